// Application-layer state (AL Control 0x0120 / AL Status 0x0130, bits 0-3; bit 4 = error
// indication / error acknowledge) and AL status codes (register 0x0134), ETG.1000.6 §5.3 and
// the ESC datasheet section I §10. The code list follows ../shared/notes/ethercat-facts.md §C.8.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

namespace ecsim {

enum class AlState : std::uint8_t {
  kInit = 1,
  kPreOp = 2,
  kBootstrap = 3,
  kSafeOp = 4,
  kOp = 8,
};

constexpr std::uint16_t kAlStateMask = 0x000F;  // AL control / AL status bits 0-3
constexpr std::uint16_t kAlErrorFlag = 0x0010;  // AL status: error indication; control: ack

// "INIT", "PREOP", "BOOT", "SAFEOP", "OP"; "unknown" for any other value.
std::string_view toString(AlState state);
// The state in the low nibble of an AL control/status value, if it names one of the five.
std::optional<AlState> alStateFromRaw(std::uint16_t raw);

// AL status codes (0x0134). Values outside this list are legal on the wire (vendor codes):
// code that reads the register keeps the raw std::uint16_t and uses alStatusCodeText().
enum class AlStatusCode : std::uint16_t {
  kNoError = 0x0000,
  kUnspecifiedError = 0x0001,
  kNoMemory = 0x0002,
  kInvalidDeviceSetup = 0x0003,
  kInvalidRevision = 0x0004,
  kSiiMismatchesFirmware = 0x0006,
  kFirmwareUpdateFailed = 0x0007,
  kLicenseError = 0x000E,
  kInvalidRequestedStateChange = 0x0011,
  kUnknownRequestedState = 0x0012,
  kBootstrapNotSupported = 0x0013,
  kNoValidFirmware = 0x0014,
  kInvalidMailboxConfigurationBoot = 0x0015,
  kInvalidMailboxConfigurationPreOp = 0x0016,
  kInvalidSyncManagerConfiguration = 0x0017,
  kNoValidInputs = 0x0018,
  kNoValidOutputs = 0x0019,
  kSynchronizationError = 0x001A,
  kSyncManagerWatchdog = 0x001B,
  kInvalidSyncManagerTypes = 0x001C,
  kInvalidOutputConfiguration = 0x001D,
  kInvalidInputConfiguration = 0x001E,
  kInvalidWatchdogConfiguration = 0x001F,
  kNeedsColdStart = 0x0020,
  kNeedsInit = 0x0021,
  kNeedsPreOp = 0x0022,
  kNeedsSafeOp = 0x0023,
  kInvalidInputMapping = 0x0024,
  kInvalidOutputMapping = 0x0025,
  kInconsistentSettings = 0x0026,
  kFreeRunNotSupported = 0x0027,
  kSyncModeNotSupported = 0x0028,
  kFreeRunNeeds3Buffer = 0x0029,
  kBackgroundWatchdog = 0x002A,
  kNoValidInputsAndOutputs = 0x002B,
  kFatalSyncError = 0x002C,
  kNoSyncError = 0x002D,
  kInvalidInputFmmuConfiguration = 0x002E,
  kInvalidDcSyncConfiguration = 0x0030,
  kInvalidDcLatchConfiguration = 0x0031,
  kPllError = 0x0032,
  kDcSyncIoError = 0x0033,
  kDcSyncTimeout = 0x0034,
  kDcInvalidSyncCycleTime = 0x0035,
  kDcInvalidSync0CycleTime = 0x0036,
  kDcInvalidSync1CycleTime = 0x0037,
  kMailboxAoe = 0x0041,
  kMailboxEoe = 0x0042,
  kMailboxCoe = 0x0043,
  kMailboxFoe = 0x0044,
  kMailboxSoe = 0x0045,
  kMailboxVoe = 0x004F,
  kEepromNoAccess = 0x0050,
  kEepromError = 0x0051,
  kExternalHardwareNotReady = 0x0052,
  kSlaveRestartedLocally = 0x0060,
  kDeviceIdentificationUpdated = 0x0061,
  kModuleIdentListMismatch = 0x0070,
  kSupplyVoltageTooLow = 0x0080,
  kSupplyVoltageTooHigh = 0x0081,
};

// A short English description of an AL status code; "unknown AL status code" if not listed.
std::string_view alStatusCodeText(std::uint16_t code);
inline std::string_view alStatusCodeText(AlStatusCode code) {
  return alStatusCodeText(static_cast<std::uint16_t>(code));
}
// True when the code is one of the AlStatusCode values above.
bool isKnownAlStatusCode(std::uint16_t code);

}  // namespace ecsim
