// A CiA 402 servo drive (the ECS7201 of examples/esi/ecsim_devices.xml, and the base of the
// ECS7211): an Application of the slave's ProcessDataDevice that works on the CiA 402 objects
// of its dictionary, so a master reaches it through PDOs and SDOs exactly as a real drive.
//
// Each step(now) first advances the motor by the time elapsed since the previous step (in
// substeps of the servo axis, 62.5 us at 16 kHz) under the commands taken at the previous
// step, then takes the new outputs (controlword, mode, targets), runs the power state machine
// and writes the inputs (statusword, actual values). So outputs a frame brings at time t act
// from t on, and the inputs show the drive at `now`. While the ESC generates SYNC0
// (Application::syncActive(), DC synchronous mode) that cycle runs on each SYNC0 pulse instead
// (sync()), so outputs act and inputs are latched at the pulses, and step() leaves the model
// alone, except that until the first pulse (0x0990 is typically 100 ms after the activation)
// step() moves the motor on without taking or publishing anything; without SYNC0 the drive
// free-runs on step() as described.
//
// The objects are found by index in whatever dictionary the device has (ecsim's own ESI or a
// vendor's), moved by DriveParams::axis * 0x800 for the further axes of a multi-axis device.
// A vendor whose RxPDOs map the demand values 0x6062 / 0x606B rather than 0x607A / 0x60FF
// (the Beckhoff AX2000's synchronous PDOs 0x1701-0x1708) gets those as its targets.
//
// Behaviour, in the terms of cia402.hpp:
//  - the controlword is obeyed in OP only. Leaving OP while the power stage is on is a
//    communication fault (0x8100): fault reaction, then Fault. Not ready to switch on lasts
//    DriveParams::initTime after the first step.
//  - modes (0x6060, shown in 0x6061 once active; a mode 0x6502 does not list is refused and
//    the previous one stays; a 0x6502 of 0 lists nothing and counts as "all implemented"): CSP
//    (target position interpolated linearly over the 0x60C2 period, its slope as velocity
//    feed-forward), CSV, CST (0x6071 per mille of rated torque), PP (bit 4 new set-point with
//    acknowledge in bit 12, bit 5 change immediately, bit 6 relative, one buffered set-point,
//    0x6081/0x6083/0x6084), PV (0x60FF ramped with 0x6083/0x6084), HM (bit 4 starts; methods 37 and
//    35: the present position is home; 19 and 20: home switch, see DriveParams::homeSwitchCounts).
//    Bit 8 halts PP, PV and HM.
//  - limits: 0x6072 max torque (per mille), 0x6080 max motor speed (rpm, 0: none), 0x607D
//    software position limits on the unwrapped position (position modes clamp their demand;
//    velocity and torque modes stop pushing outwards) with bit 11 while one acts; the whole
//    DINT range (the default) or min >= max switches them off.
//  - following error (position modes): 0x60F4 = demand - actual; beyond 0x6065 the warning
//    bit 7 is set, beyond it for longer than 0x6066 ms bit 13 and fault 0x8611 in 0x603F
//    (0x6065 = 0xFFFFFFFF switches monitoring off).
//  - faults: every fault (following error, communication 0x8100, an injected one such as
//    over current 0x2310, and an encoder fault 0x7305 while Encoder::faulted()) sets 0x603F,
//    the error register 0x1001 (when present; cia402::errorRegisterFor) and sends a CoE
//    emergency (code, error register, 5 zero bytes) through the emergency sink; the fault
//    reset clears 0x603F and 0x1001 and sends the "error reset" emergency 0x0000.
//  - quick stop (0x605A): 0 coast; 1/5 profile deceleration, 2/6 quick-stop deceleration,
//    3/7 and 4/8 at the torque limit; 1-4 then Switch on disabled, 5-8 hold in Quick stop
//    active. The fault reaction stops at the quick-stop deceleration (at most
//    faultReactionTimeout), then the power stage goes off.
//  - transitions 5, 8 and 9 switch the power stage off at once (the motor coasts).
//  - units (CiA 402 factor group, IEC 61800-7-201): position [increments] = position [user
//    units] * position factor, position factor = 0x608F (increments / motor revolutions) *
//    0x6091 (motor / shaft revolutions) / 0x6092 (feed / shaft revolutions); a device with none
//    of the three and a 0x6093 position factor (numerator / denominator) takes that. Absent
//    objects and zero terms count as 1, so the default unit is one encoder increment. The
//    positions (0x607A, 0x6064, 0x60F4, 0x6065, 0x607D) are in user units, velocities (0x60FF,
//    0x606C, 0x6081, 0x6099) in user units/s and accelerations (0x6083, 0x6084, 0x609A) in user
//    units/s^2; the factor is re-read every cycle, so an SDO write takes effect at once (while
//    powered, the mode restarts from the actual position). A 0x608F whose ratio is a whole
//    number other than 1 gives the encoder's counts per revolution at creation, unless
//    DriveParams::resolutionFromDictionary is false (encoder.resolution given).
//  - digital inputs 0x60FD: bit 0 negative and bit 1 positive limit switch, bit 2 home switch,
//    from the encoder count against DriveParams' switch positions (bits 16-31 stay 0).
//  - touch probe 0x60B8-0x60BD where present (cia402_touch_probe.hpp): probe 1 latches at the
//    edges of the home switch or at the encoder's zero impulse, probe 2 at the zero impulse.
//  - position is the encoder count plus the home offset; 0x6064 wraps at 32 bits. The shaft
//    angle is kept in DriveParams::stateFile (read at creation; written when the power stage
//    goes off, on AL state changes, by saveState(), when the drive is destroyed, and every
//    stateSaveInterval of simulated time while the shaft moves, so kill -9 loses at most that).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>

#include "protocol/coe.hpp"
#include "protocol/result.hpp"
#include "slavesim/devices/cia402.hpp"
#include "slavesim/devices/cia402_touch_probe.hpp"
#include "slavesim/devices/device_state.hpp"
#include "slavesim/devices/encoder.hpp"
#include "slavesim/devices/motion_profile.hpp"
#include "slavesim/devices/object_ref.hpp"
#include "slavesim/devices/servo_axis.hpp"
#include "slavesim/process_data.hpp"

namespace ecsim::slavesim::devices {

struct DriveParams {
  MotorParams motor;
  std::optional<ServoGains> gains;  // default: ServoGains::tuned(motor)
  AxisOptions axis;
  EncoderParams encoder;
  double quickStopDeceleration{2.0e7};  // counts/s^2 (about 150 rev/s^2 at 17 bits)
  double positionWindow{100.0};         // counts: PP target reached
  double velocityWindow{2000.0};        // counts/s: PV target reached
  double velocityThreshold{500.0};      // counts/s: "speed = 0", stop detection
  std::int64_t homeOffset{0};           // counts: the position the home point gets
  // Home switch: active while the encoder count (before any home offset) is >= this.
  std::optional<double> homeSwitchCounts{0.0};
  // Hardware limit switches: the negative one active while the encoder count (before any home
  // offset) is <= its position, the positive one while it is >=; unset: none. Shown in 0x60FD
  // with the home switch; the drive itself does not react to them.
  std::optional<double> negativeLimitSwitchCounts;
  std::optional<double> positiveLimitSwitchCounts;
  SimTime initTime{0};                           // in Not ready to switch on
  SimTime faultReactionTimeout{500 * kNsPerMs};  // longest fault reaction
  double initialShaftAngle{0.0};                 // rad, when there is no state file yet
  std::filesystem::path stateFile;               // empty: nothing kept
  SimTime stateSaveInterval{100 * kNsPerMs};     // periodic saves while moving; 0: none
  // Initial values of the dictionary's 0x6065 (counts), 0x6066 (ms) and 0x6072 (per mille);
  // unset: the ESI defaults (a 0x6072 of 0 at power-up counts as unset: 300 %).
  std::optional<std::uint32_t> followingErrorWindow;
  std::optional<std::uint16_t> followingErrorTimeoutMs;
  std::optional<std::uint16_t> maxTorquePerMille;
  // Which CiA 402 axis of a multi-axis device (ETG.6010: axis n has its profile objects at
  // 0x6000-0x67FF + n * 0x800; 0x603F-0x67FF objects of axis 0 move, 0x1001 does not).
  unsigned axisNumber{0};
  // The mode of operation at power-up (0x6060), e.g. 8 (CSP) for a device whose PDOs carry no
  // 0x6060 and whose 0x6060 a master cannot write. Unset: the dictionary's value, except for
  // a fixed-mode CSP device (0x6502 lists no mode, the RxPDOs map 0x607A but not 0x6060, as
  // the SOES CiA 402 example STMBL_ECAT): CSP.
  std::optional<std::int8_t> initialMode;
  // A 0x608F position encoder resolution (increments : revolutions, a whole ratio other than
  // 1) sets encoder.countsPerRevolution at creation.
  bool resolutionFromDictionary{true};
};

// Where a drive's emergency messages go (the slave's CoE server, coe::CoeServer::pushEmergency).
using EmergencySink = std::function<void(const Emergency&)>;

class Cia402Drive : public Application {
 public:
  // Needs 0x6040, 0x6041, 0x6060, 0x6061 and 0x6064 in the dictionary; the other objects are
  // used when present. Fails when the state file exists but cannot be read.
  static Result<std::unique_ptr<Cia402Drive>> create(coe::ObjectDictionary& od,
                                                     const DriveParams& params = {});
  ~Cia402Drive() override;

  void step(coe::ObjectDictionary& od, AlState state, SimTime now) override;
  // SYNC0 (signal 0) while syncActive(): one drive cycle at the pulse. Other pulses: ignored.
  void sync(coe::ObjectDictionary& od, unsigned signal, AlState state, SimTime now) override;

  cia402::State state() const { return state_; }
  std::int8_t activeMode() const { return mode_; }
  std::uint16_t statusword() const { return statusword_; }
  std::uint16_t errorCode() const { return errorCode_; }
  // Unwrapped position (counts, with home offset) as the drive measures it, and its demand.
  double position() const { return measured_; }
  double demandPosition() const { return demand_; }
  double velocity() const;  // counts/s
  // Encoder counts per position user unit (the CiA 402 position factor; 1 by default).
  double positionFactor() const { return countsPerUnit_; }
  bool homeSwitch() const;
  // The digital inputs 0x60FD shows (cia402::di bits).
  std::uint32_t digitalInputs() const;
  bool homingAttained() const { return homingAttained_; }

  ServoAxis& axis() { return axis_; }
  const ServoAxis& axis() const { return axis_; }
  Encoder& encoder() { return encoder_; }
  const Encoder& encoder() const { return encoder_; }
  const TouchProbe& touchProbe() const { return touchProbe_; }
  const DriveParams& params() const { return params_; }
  // Raises a fault from outside (fault injection): fault reaction, then Fault with `code`
  // (e.g. cia402::kErrorOvercurrent, kErrorFollowing, kErrorEncoder), with its emergency.
  void injectFault(std::uint16_t code);
  // Encoder fault injection: while set the position freezes and the drive faults with 0x7305
  // (again after each fault reset, until cleared).
  void setEncoderFault(bool faulted) { encoder_.setFault(faulted); }
  void setEmergencySink(EmergencySink sink) { emergencySink_ = std::move(sink); }
  const EmergencySink& emergencySink() const { return emergencySink_; }
  std::uint64_t emergenciesSent() const { return emergenciesSent_; }
  // Writes the state file now (no-op without one).
  Status saveState() const;

 protected:
  Cia402Drive(coe::ObjectDictionary& od, const DriveParams& params);
  Status init();
  // Hooks for derived drives: the controlword the state machine gets (default: the master's),
  // and the inputs to publish after each step.
  virtual std::uint16_t effectiveControlword(std::uint16_t fromMaster) { return fromMaster; }
  virtual void publishExtra(SimTime /*now*/) {}
  bool internalLimit() const { return internalLimit_; }
  std::int64_t encoderReported() const { return reading_.reported; }
  AlState alState() const { return lastAl_; }

 private:
  enum class HomingPhase : std::uint8_t {
    kIdle,
    kSearchSwitch,  // fast, towards the switch
    kLeaveSwitch,   // fast, out of the switch
    kSearchEdge,    // slow, until the edge
    kStopping,      // home found, braking
    kDone,
    kError,
  };

  // ---- cia402_drive.cpp ----
  void cycle(AlState al, SimTime now);
  void emitEmergency(std::uint16_t code);
  void advance(SimTime dt);
  // The motor moved on to `now` under the commands it has, nothing taken or published.
  void advanceTo(SimTime now);
  void substep();
  void measure();
  void takeCommands(AlState al);
  void enterState(cia402::State next);
  void raiseFault(std::uint16_t code);
  void switchMode(std::int8_t requested);
  void publish(SimTime now);
  void checkFollowingError(bool positionControlled);
  double torqueLimitNm() const;
  double velocityLimitCounts() const;
  SimTime interpolationPeriod() const;
  double readPositionFactor() const;
  void updatePositionFactor();
  // ---- cia402_modes.cpp ----
  void startMode();
  void latchModeInputs(std::uint16_t controlword, std::uint16_t previous);
  // The servo command for this substep in Operation enabled.
  ServoCommand operate();
  ServoCommand stopping(bool faultReaction);
  // Commands from counts, counts/s and counts/s^2 (the acceleration is fed forward as J a).
  ServoCommand positionCommand(double position, double velocity, double acceleration = 0.0);
  ServoCommand velocityCommand(double velocity, double acceleration = 0.0);
  double feedForwardTorque(double acceleration) const;
  void startPpSetPoint(std::uint16_t controlword);
  void startHoming();
  void homingSubstep(double dt);
  void setHome();
  std::uint16_t modeStatusBits() const;
  // 0x607D as a range; false when it sets no limit (empty, or the whole DINT range).
  bool softwareLimits(double& min, double& max) const;
  double clampToLimits(double position);
  // +1 at or beyond the upper software limit, -1 at or below the lower one, else 0.
  int limitSide() const;

  coe::ObjectDictionary& od_;
  DriveParams params_;
  ServoAxis axis_;
  Encoder encoder_;
  struct Objects {
    ObjectRef errorCode, controlword, statusword, quickStopOption, mode, modeDisplay;
    ObjectRef positionActual, feWindow, feTimeout, velocityActual, targetTorque, maxTorque;
    ObjectRef torqueActual, targetPosition, limitMin, limitMax, maxMotorSpeed;
    ObjectRef profileVelocity, profileAcceleration, profileDeceleration;
    ObjectRef homingMethod, homingSpeedSwitch, homingSpeedZero, homingAcceleration;
    ObjectRef ipValue, ipIndex, feActual, targetVelocity, supportedModes, errorRegister;
    ObjectRef encoderIncrements, encoderRevolutions, gearMotor, gearShaft, feed, feedRevolutions;
    ObjectRef factorNumerator, factorDenominator, digitalInputs;
  } obj_;
  TouchProbe touchProbe_;
  EmergencySink emergencySink_;
  std::uint64_t emergenciesSent_{0};

  cia402::State state_{cia402::State::kNotReadyToSwitchOn};
  std::int8_t mode_{0};
  std::uint16_t previousControlword_{0};
  std::uint16_t statusword_{0};
  std::uint16_t errorCode_{0};
  bool started_{false};
  bool pulsed_{false};  // a SYNC0 pulse came since SYNC0 was last switched on
  SimTime lastNow_{0};
  SimTime pendingNs_{0};
  SimTime clock_{0};  // time of the motor model (the start of the next substep)
  SimTime readyAt_{0};
  AlState lastAl_{AlState::kInit};
  std::optional<PeriodicStateSaver> stateSaver_;

  EncoderReading reading_{};
  std::int64_t offset_{0};  // drive position = encoder count + offset_
  double measured_{0.0};    // drive position, counts, unwrapped
  double demand_{0.0};      // position demand, counts, unwrapped (position modes)
  bool positionDemand_{false};
  double followingErrorValue_{0.0};  // demand - actual at the last substep (0x60F4)
  bool internalLimit_{false};
  bool warning_{false};
  bool followingError_{false};
  std::optional<SimTime> feSince_;
  double countsToRad_{0.0};
  double countsPerUnit_{1.0};  // the position factor

  // mode state
  MotionProfile profile_;
  double cspStart_{0.0}, cspEnd_{0.0};
  SimTime cspElapsed_{0}, cspPeriod_{kNsPerMs};
  std::int32_t cspLastRaw_{0};
  double velocityTarget_{0.0};  // CSV/PV, counts/s
  double torqueTarget_{0.0};    // CST, N m
  bool halt_{false};
  // PP
  double ppTarget_{0.0};
  bool ppMoving_{false};
  std::optional<double> ppBuffered_;
  bool ppAck_{false};
  bool ppReached_{true};
  // HM
  HomingPhase homing_{HomingPhase::kIdle};
  bool homingAttained_{false};
  int homingMethod_{0};
  // stopping (quick stop, fault reaction)
  bool holding_{false};
  SimTime faultReactionStart_{0};
};

}  // namespace ecsim::slavesim::devices
