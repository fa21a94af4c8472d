// CiA 402 (IEC 61800-7-201) drive profile: object indexes, modes of operation, and the power
// state machine driven by the controlword (0x6040) and shown in the statusword (0x6041).
//
// States and their statusword coding (bits 6, 5, 3, 2, 1, 0 with the masks of the profile):
//   Not ready to switch on   x0xx 0000      Switch on disabled   x1xx 0000
//   Ready to switch on       x01x 0001      Switched on          x01x 0011
//   Operation enabled        x01x 0111      Quick stop active    x00x 0111
//   Fault reaction active    x0xx 1111      Fault                x0xx 1000
// Commands (controlword bits 7, 3, 2, 1, 0):
//   Shutdown 0xxx x110 (transitions 2, 6, 8)       Switch on 0xxx 0111 (3)
//   Disable voltage 0xxx xx0x (7, 9, 10, 12)       Quick stop 0xxx x01x (7, 10, 11)
//   Disable operation 0xxx 0111 (5)                Enable operation 0xxx 1111 (4, 16)
//   Fault reset: rising edge of bit 7 (15); while bit 7 stays set no command is decoded.
// Transitions 0 and 1 (power-up), 12 (quick stop finished, option codes 0-4), 13 (fault) and
// 14 (fault reaction finished) are the drive's own; nextState() covers the commanded ones.
// "Enable operation" in Ready to switch on goes through Switched on to Operation enabled
// (transitions 3 and 4 in one step), as drives accept the usual 0x06 -> 0x0F sequence.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace ecsim::slavesim::devices::cia402 {

// ---- objects ----------------------------------------------------------------------------------
namespace obj {
inline constexpr std::uint16_t kErrorCode = 0x603F;
inline constexpr std::uint16_t kControlword = 0x6040;
inline constexpr std::uint16_t kStatusword = 0x6041;
inline constexpr std::uint16_t kQuickStopOptionCode = 0x605A;
inline constexpr std::uint16_t kModesOfOperation = 0x6060;
inline constexpr std::uint16_t kModesOfOperationDisplay = 0x6061;
inline constexpr std::uint16_t kPositionDemandValue = 0x6062;
inline constexpr std::uint16_t kPositionActualValue = 0x6064;
inline constexpr std::uint16_t kFollowingErrorWindow = 0x6065;
inline constexpr std::uint16_t kFollowingErrorTimeout = 0x6066;
inline constexpr std::uint16_t kVelocityDemandValue = 0x606B;
inline constexpr std::uint16_t kVelocityActualValue = 0x606C;
inline constexpr std::uint16_t kTargetTorque = 0x6071;
inline constexpr std::uint16_t kMaxTorque = 0x6072;
inline constexpr std::uint16_t kTorqueActualValue = 0x6077;
inline constexpr std::uint16_t kTargetPosition = 0x607A;
inline constexpr std::uint16_t kSoftwarePositionLimit = 0x607D;  // :01 min, :02 max
inline constexpr std::uint16_t kMaxMotorSpeed = 0x6080;          // rpm
// Factor group (:01 numerator, :02 denominator each): position encoder resolution (encoder
// increments : motor revolutions), gear ratio (motor revolutions : driving shaft revolutions),
// feed constant (feed : driving shaft revolutions), and the older position factor.
inline constexpr std::uint16_t kPositionEncoderResolution = 0x608F;
inline constexpr std::uint16_t kGearRatio = 0x6091;
inline constexpr std::uint16_t kFeedConstant = 0x6092;
inline constexpr std::uint16_t kPositionFactor = 0x6093;
inline constexpr std::uint16_t kProfileVelocity = 0x6081;
inline constexpr std::uint16_t kProfileAcceleration = 0x6083;
inline constexpr std::uint16_t kProfileDeceleration = 0x6084;
inline constexpr std::uint16_t kHomingMethod = 0x6098;
inline constexpr std::uint16_t kHomingSpeeds = 0x6099;  // :01 switch search, :02 zero search
inline constexpr std::uint16_t kHomingAcceleration = 0x609A;
inline constexpr std::uint16_t kInterpolationTimePeriod = 0x60C2;  // :01 value, :02 index
inline constexpr std::uint16_t kFollowingErrorActualValue = 0x60F4;
inline constexpr std::uint16_t kDigitalInputs = 0x60FD;
inline constexpr std::uint16_t kTargetVelocity = 0x60FF;
inline constexpr std::uint16_t kSupportedDriveModes = 0x6502;
}  // namespace obj

// Error codes (0x603F, CiA 402 / CiA 301 emergency codes).
inline constexpr std::uint16_t kErrorFollowing = 0x8611;      // position following error
inline constexpr std::uint16_t kErrorCommunication = 0x8100;  // communication, generic
inline constexpr std::uint16_t kErrorOvercurrent = 0x2310;    // continuous over current
inline constexpr std::uint16_t kErrorEncoder = 0x7305;        // incremental sensor 1 fault
inline constexpr std::uint16_t kErrorReset = 0x0000;          // emergency: error reset

// The CiA 301 error register (0x1001) a fault with this code sets: bit 0 generic always, then
// by the code's group: 0x2xxx current (bit 1), 0x3xxx voltage (bit 2), 0x4xxx temperature
// (bit 3), 0x81xx communication (bit 4), other 0x6xxx-0x8xxx device profile (bit 5). 0 for
// kErrorReset.
std::uint8_t errorRegisterFor(std::uint16_t code);

// Digital inputs 0x60FD (bits 3-15 reserved, 16-31 manufacturer-specific).
namespace di {
inline constexpr std::uint32_t kNegativeLimitSwitch = 1u << 0;
inline constexpr std::uint32_t kPositiveLimitSwitch = 1u << 1;
inline constexpr std::uint32_t kHomeSwitch = 1u << 2;
}  // namespace di

// ---- controlword and statusword bits ------------------------------------------------------------
namespace cw {
inline constexpr std::uint16_t kSwitchOn = 1u << 0;
inline constexpr std::uint16_t kEnableVoltage = 1u << 1;
inline constexpr std::uint16_t kQuickStop = 1u << 2;  // active low
inline constexpr std::uint16_t kEnableOperation = 1u << 3;
inline constexpr std::uint16_t kNewSetPoint = 1u << 4;        // PP; HM: homing operation start
inline constexpr std::uint16_t kChangeImmediately = 1u << 5;  // PP
inline constexpr std::uint16_t kRelative = 1u << 6;           // PP
inline constexpr std::uint16_t kFaultReset = 1u << 7;
inline constexpr std::uint16_t kHalt = 1u << 8;
}  // namespace cw

namespace sw {
inline constexpr std::uint16_t kReadyToSwitchOn = 1u << 0;
inline constexpr std::uint16_t kSwitchedOn = 1u << 1;
inline constexpr std::uint16_t kOperationEnabled = 1u << 2;
inline constexpr std::uint16_t kFault = 1u << 3;
inline constexpr std::uint16_t kVoltageEnabled = 1u << 4;
inline constexpr std::uint16_t kQuickStop = 1u << 5;  // 0: quick stop active
inline constexpr std::uint16_t kSwitchOnDisabled = 1u << 6;
inline constexpr std::uint16_t kWarning = 1u << 7;
inline constexpr std::uint16_t kRemote = 1u << 9;
inline constexpr std::uint16_t kTargetReached = 1u << 10;
inline constexpr std::uint16_t kInternalLimitActive = 1u << 11;
inline constexpr std::uint16_t kModeSpecific12 = 1u << 12;  // PP set-point ack, PV speed 0,
                                                            // HM attained, CSx follows command
inline constexpr std::uint16_t kModeSpecific13 = 1u << 13;  // PP/CSP following error, HM error
inline constexpr std::uint16_t kStateMask = 0x006F;
}  // namespace sw

// ---- modes ------------------------------------------------------------------------------------
enum class Mode : std::int8_t {
  kNone = 0,
  kProfilePosition = 1,
  kProfileVelocity = 3,
  kHoming = 6,
  kCyclicSyncPosition = 8,
  kCyclicSyncVelocity = 9,
  kCyclicSyncTorque = 10,
};
// The 0x6502 bit of a mode of operation (0 for modes with no bit, e.g. manufacturer modes).
std::uint32_t supportedModeBit(std::int8_t mode);
std::string_view toString(Mode mode);
// The modes of operation ecsim's drive models, as 0x6502 bits: PP, PV, HM, CSP, CSV, CST (not
// VL 2, TQ 4, IP 7, nor the manufacturer-specific negative modes).
inline constexpr std::uint32_t kModelledModes = 0x3A5;
// The modes a drive runs, as 0x6502 bits: those its 0x6502 (`supported`) lists that ecsim
// models. A 0x6502 of 0 (a placeholder of SOES-generated ESIs) or none counts as "all".
std::uint32_t runnableModes(std::optional<std::uint64_t> supported);
// Whether the mode can be set at power-up on a drive that runs `runnable` (0x6502 bits): one
// of them, or 0 (no mode: the drive holds still until a master chooses one).
bool startsIn(std::int8_t mode, std::uint32_t runnable);
// "0 (no mode), 1 (PP), 8 (CSP)": mode 0 and the modes of `modes` (0x6502 bits), for messages.
std::string describeModes(std::uint32_t modes);

// ---- state machine ----------------------------------------------------------------------------
enum class State : std::uint8_t {
  kNotReadyToSwitchOn,
  kSwitchOnDisabled,
  kReadyToSwitchOn,
  kSwitchedOn,
  kOperationEnabled,
  kQuickStopActive,
  kFaultReactionActive,
  kFault,
};
std::string_view toString(State state);

enum class Command : std::uint8_t {
  kNone,  // bit 7 held high: nothing decoded
  kShutdown,
  kSwitchOn,  // also "disable operation" (same coding)
  kEnableOperation,
  kDisableVoltage,
  kQuickStop,
  kFaultReset,
};
std::string_view toString(Command command);

// Decodes a controlword; `previous` is the controlword of the previous cycle (for the edge of
// the fault-reset bit).
Command decodeControlword(std::uint16_t controlword, std::uint16_t previous);

// The state a command leads to from `state` (the same state when the command does not apply
// there). `quickStopOption` is 0x605A: with 5-8 "enable operation" leaves quick stop active.
State nextState(State state, Command command, int quickStopOption);

// Statusword bits 0-6 and 9 (remote) for a state; bit 4 (voltage enabled) in every state but
// "not ready to switch on".
std::uint16_t statusBits(State state);
// The state a statusword shows (by the masks above); nullopt for a coding no state has.
std::optional<State> stateFromStatusword(std::uint16_t statusword);

// True in the states where the power stage drives the motor.
constexpr bool powered(State s) {
  return s == State::kOperationEnabled || s == State::kQuickStopActive ||
         s == State::kFaultReactionActive;
}

}  // namespace ecsim::slavesim::devices::cia402
