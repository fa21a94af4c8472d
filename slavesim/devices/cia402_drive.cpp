// The CiA 402 drive: construction, time keeping, power state machine, monitoring and the
// objects it publishes. The modes of operation are in cia402_modes.cpp.
#include "slavesim/devices/cia402_drive.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

#include "slavesim/coe/standard_objects.hpp"
#include "slavesim/devices/device_state.hpp"
#include "slavesim/devices/error_register.hpp"

namespace ecsim::slavesim::devices {

using cia402::State;

namespace {

// At most this much motor time is simulated in one step (a stalled clock, a debugger): the
// rest is dropped rather than stalling the firmware.
constexpr SimTime kMaxCatchUp = 10 * kNsPerSecond;
constexpr std::uint64_t kFollowingErrorOff = 0xFFFFFFFFu;
constexpr std::int64_t kDefaultMaxTorquePerMille = 3000;
// The following error window of ecsim's own drives (examples/esi/ecsim_devices.xml 0x6065).
constexpr std::int64_t kDefaultFollowingErrorWindow = 10000;
constexpr std::uint64_t kMaxEncoderResolution = 1u << 30;  // as encoder.resolution

// ETG.6010 multi-axis layout: each further axis has its profile objects 0x800 higher.
constexpr std::uint16_t kAxisIndexStep = 0x800;
constexpr std::uint16_t kFirstProfileIndex = 0x6000;
constexpr std::uint16_t kRxPdoFirst = 0x1600;
constexpr std::uint16_t kRxPdoLast = 0x17FF;

// Whether any RxPDO mapping object of the dictionary maps `index`.
bool rxPdoMaps(const coe::ObjectDictionary& od, std::uint16_t index) {
  for (std::uint32_t pdo = kRxPdoFirst; pdo <= kRxPdoLast; ++pdo) {
    if (od.findEntry(static_cast<std::uint16_t>(pdo), 0) == nullptr) continue;
    for (const auto& m : coe::mappedObjects(od, static_cast<std::uint16_t>(pdo))) {
      if (m.index == index) return true;
    }
  }
  return false;
}

std::int32_t wrap32(std::int64_t v) {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(static_cast<std::uint64_t>(v)));
}

}  // namespace

Cia402Drive::Cia402Drive(coe::ObjectDictionary& od, const DriveParams& params)
    : od_(od),
      params_(params),
      axis_(params.motor, params.gains.value_or(ServoGains::tuned(params.motor)), params.axis),
      encoder_(params.encoder) {}

Result<std::unique_ptr<Cia402Drive>> Cia402Drive::create(coe::ObjectDictionary& od,
                                                         const DriveParams& params) {
  std::unique_ptr<Cia402Drive> drive(new Cia402Drive(od, params));
  ECSIM_TRY(drive->init());
  return drive;
}

Status Cia402Drive::init() {
  using namespace cia402::obj;
  const auto shift = static_cast<std::uint16_t>(params_.axisNumber * kAxisIndexStep);
  auto at = [shift](std::uint16_t index) {
    return index >= kFirstProfileIndex ? static_cast<std::uint16_t>(index + shift) : index;
  };
  for (std::uint16_t index : {kControlword, kStatusword, kModesOfOperation,
                              kModesOfOperationDisplay, kPositionActualValue}) {
    if (od_.findEntry(at(index), 0) == nullptr) {
      char text[80];
      std::snprintf(text, sizeof text, "CiA 402 drive (axis %u): dictionary has no object 0x%04X",
                    params_.axisNumber, static_cast<unsigned>(at(index)));
      return makeError(ErrorCode::kNotFound, text);
    }
  }
  auto ref = [&](std::uint16_t index, std::uint8_t sub = 0) {
    return ObjectRef(od_, at(index), sub);
  };
  // The target the vendor's PDOs carry: 0x607A / 0x60FF, or the demand values 0x6062 / 0x606B
  // where only those are mapped.
  auto target = [&](std::uint16_t standard, std::uint16_t demand) {
    return !rxPdoMaps(od_, at(standard)) && rxPdoMaps(od_, at(demand)) ? ref(demand)
                                                                       : ref(standard);
  };
  obj_.errorCode = ref(kErrorCode);
  obj_.controlword = ref(kControlword);
  obj_.statusword = ref(kStatusword);
  obj_.quickStopOption = ref(kQuickStopOptionCode);
  obj_.mode = ref(kModesOfOperation);
  obj_.modeDisplay = ref(kModesOfOperationDisplay);
  obj_.positionActual = ref(kPositionActualValue);
  obj_.feWindow = ref(kFollowingErrorWindow);
  obj_.feTimeout = ref(kFollowingErrorTimeout);
  obj_.velocityActual = ref(kVelocityActualValue);
  obj_.targetTorque = ref(kTargetTorque);
  obj_.maxTorque = ref(kMaxTorque);
  obj_.torqueActual = ref(kTorqueActualValue);
  obj_.targetPosition = target(kTargetPosition, kPositionDemandValue);
  obj_.limitMin = ref(kSoftwarePositionLimit, 1);
  obj_.limitMax = ref(kSoftwarePositionLimit, 2);
  obj_.maxMotorSpeed = ref(kMaxMotorSpeed);
  obj_.profileVelocity = ref(kProfileVelocity);
  obj_.profileAcceleration = ref(kProfileAcceleration);
  obj_.profileDeceleration = ref(kProfileDeceleration);
  obj_.homingMethod = ref(kHomingMethod);
  obj_.homingSpeedSwitch = ref(kHomingSpeeds, 1);
  obj_.homingSpeedZero = ref(kHomingSpeeds, 2);
  obj_.homingAcceleration = ref(kHomingAcceleration);
  obj_.ipValue = ref(kInterpolationTimePeriod, 1);
  obj_.ipIndex = ref(kInterpolationTimePeriod, 2);
  obj_.feActual = ref(kFollowingErrorActualValue);
  obj_.targetVelocity = target(kTargetVelocity, kVelocityDemandValue);
  obj_.supportedModes = ref(kSupportedDriveModes);
  obj_.errorRegister = ref(error_register::kIndex);
  obj_.encoderIncrements = ref(kPositionEncoderResolution, 1);
  obj_.encoderRevolutions = ref(kPositionEncoderResolution, 2);
  obj_.gearMotor = ref(kGearRatio, 1);
  obj_.gearShaft = ref(kGearRatio, 2);
  obj_.feed = ref(kFeedConstant, 1);
  obj_.feedRevolutions = ref(kFeedConstant, 2);
  obj_.factorNumerator = ref(kPositionFactor, 1);
  obj_.factorDenominator = ref(kPositionFactor, 2);
  obj_.digitalInputs = ref(kDigitalInputs);
  touchProbe_.bind(od_, at);
  if (params_.resolutionFromDictionary) {
    const std::uint64_t increments = obj_.encoderIncrements.getUnsigned(0);
    const std::uint64_t revolutions = obj_.encoderRevolutions.getUnsigned(0);
    if (increments > 0 && revolutions > 0 && increments != revolutions &&
        increments % revolutions == 0 && increments / revolutions <= kMaxEncoderResolution) {
      params_.encoder.countsPerRevolution = static_cast<std::uint32_t>(increments / revolutions);
      encoder_ = Encoder(params_.encoder);
    }
  }
  countsPerUnit_ = readPositionFactor();
  std::optional<std::int8_t> initialMode = params_.initialMode;
  if (!initialMode && obj_.supportedModes && obj_.supportedModes.getUnsigned() == 0 &&
      !rxPdoMaps(od_, at(kModesOfOperation)) && rxPdoMaps(od_, at(kTargetPosition))) {
    initialMode = static_cast<std::int8_t>(cia402::Mode::kCyclicSyncPosition);
  }
  if (initialMode) obj_.mode.set(*initialMode);
  if (params_.followingErrorWindow) {
    obj_.feWindow.set(*params_.followingErrorWindow);
  } else if (obj_.feWindow && obj_.feWindow.get() == 0) {
    // A power-up window of 0 (an object the ESI gives no default: Copley's XE2) would make
    // every count of deviation a following error; a drive ships with a window, so it is taken
    // as unset (0xFFFFFFFF still switches the check off, CiA 402).
    obj_.feWindow.set(kDefaultFollowingErrorWindow);
  }
  if (params_.followingErrorTimeoutMs) obj_.feTimeout.set(*params_.followingErrorTimeoutMs);
  if (params_.maxTorquePerMille) {
    obj_.maxTorque.set(*params_.maxTorquePerMille);
  } else if (obj_.maxTorque && obj_.maxTorque.get() == 0) {
    // A power-up value of 0 (an object the ESI gives no default, or one made up for a PDO
    // entry the dictionary lacks, as the AX2000's 0x6072) would leave the motor without
    // torque: take it as unset.
    obj_.maxTorque.set(kDefaultMaxTorquePerMille);
  }

  double angle = params_.initialShaftAngle;
  if (!params_.stateFile.empty()) {
    ECSIM_ASSIGN_OR_RETURN(auto file, DeviceStateFile::open(params_.stateFile));
    if (file.loaded()) angle = file.loaded()->shaftAngle;
    stateSaver_.emplace(std::move(file), params_.stateSaveInterval);
  }
  axis_.motor().setAngle(angle);
  encoder_.powerOn(angle);
  countsToRad_ = 2.0 * std::numbers::pi / encoder_.params().countsPerRevolution;
  measure();
  demand_ = measured_;
  profile_.reset(measured_, 0.0);
  cspStart_ = cspEnd_ = measured_;
  publish(0);
  return okStatus();
}

Cia402Drive::~Cia402Drive() {
  (void)saveState();
}

Status Cia402Drive::saveState() const {
  if (!stateSaver_) return okStatus();
  return stateSaver_->save(DeviceState{axis_.motor().angle()});
}

double Cia402Drive::velocity() const {
  return axis_.motor().velocity() / countsToRad_;
}

bool Cia402Drive::homeSwitch() const {
  return params_.homeSwitchCounts &&
         static_cast<double>(reading_.counts) >= *params_.homeSwitchCounts;
}

std::uint32_t Cia402Drive::digitalInputs() const {
  const auto count = static_cast<double>(reading_.counts);
  std::uint32_t bits = homeSwitch() ? cia402::di::kHomeSwitch : 0u;
  if (params_.negativeLimitSwitchCounts && count <= *params_.negativeLimitSwitchCounts) {
    bits |= cia402::di::kNegativeLimitSwitch;
  }
  if (params_.positiveLimitSwitchCounts && count >= *params_.positiveLimitSwitchCounts) {
    bits |= cia402::di::kPositiveLimitSwitch;
  }
  return bits;
}

double Cia402Drive::torqueLimitNm() const {
  const auto perMille = static_cast<double>(obj_.maxTorque.get(kDefaultMaxTorquePerMille));
  return std::max(0.0, perMille) / 1000.0 * params_.motor.ratedTorque;
}

double Cia402Drive::velocityLimitCounts() const {
  const auto rpm = static_cast<double>(obj_.maxMotorSpeed.getUnsigned(0));
  if (rpm <= 0.0) return std::numeric_limits<double>::infinity();
  return rpm / 60.0 * encoder_.params().countsPerRevolution;
}

double Cia402Drive::readPositionFactor() const {
  auto ratio = [](const ObjectRef& numerator, const ObjectRef& denominator) {
    const std::uint64_t n = numerator.getUnsigned(0);
    const std::uint64_t d = denominator.getUnsigned(0);
    return n > 0 && d > 0 ? static_cast<double>(n) / static_cast<double>(d) : 1.0;
  };
  if (!obj_.encoderIncrements && !obj_.gearMotor && !obj_.feed) {
    return ratio(obj_.factorNumerator, obj_.factorDenominator);
  }
  return ratio(obj_.encoderIncrements, obj_.encoderRevolutions) *
         ratio(obj_.gearMotor, obj_.gearShaft) / ratio(obj_.feed, obj_.feedRevolutions);
}

void Cia402Drive::updatePositionFactor() {
  const double factor = readPositionFactor();
  if (factor == countsPerUnit_) return;
  countsPerUnit_ = factor;
  // The targets the master sent are in the old unit: start over from the actual position.
  if (cia402::powered(state_)) startMode();
}

SimTime Cia402Drive::interpolationPeriod() const {
  const auto value = static_cast<double>(obj_.ipValue.getUnsigned(1));
  const auto index = static_cast<double>(obj_.ipIndex.get(-3));
  if (value <= 0.0 || index < -9.0 || index > 0.0) return kNsPerMs;
  const auto ns = static_cast<SimTime>(std::llround(value * std::pow(10.0, index + 9.0)));
  return std::clamp<SimTime>(ns, axis_.substepNs(), kNsPerSecond);
}

void Cia402Drive::measure() {
  reading_ = encoder_.read(axis_.motor().angle());
  measured_ = static_cast<double>(reading_.counts + offset_);
}

void Cia402Drive::step(coe::ObjectDictionary& /*od*/, AlState al, SimTime now) {
  if (!syncActive()) pulsed_ = false;
  if (syncActive() && started_) {
    // The SYNC0 pulses run the drive. Before the first one the motor still moves on: frozen
    // from the activation to the start time (100 ms for our master, docs/master.md), six
    // drives then integrated those 100 ms at the first pulse in one poll, 7 ms of CPU during
    // which the served network answered no frame.
    if (!pulsed_) advanceTo(now);
    return;
  }
  cycle(al, now);
}

void Cia402Drive::sync(coe::ObjectDictionary& /*od*/, unsigned signal, AlState al, SimTime now) {
  if (signal != 0 || !syncActive()) return;
  pulsed_ = true;
  cycle(al, now);
}

void Cia402Drive::advanceTo(SimTime now) {
  const SimTime dt = now > lastNow_ ? now - lastNow_ : 0;
  lastNow_ = std::max(lastNow_, now);
  advance(dt);
}

void Cia402Drive::cycle(AlState al, SimTime now) {
  if (!started_) {
    started_ = true;
    lastNow_ = now;
    readyAt_ = now + params_.initTime;
  }
  advanceTo(now);
  if (stateSaver_) (void)stateSaver_->tick(lastNow_, DeviceState{axis_.motor().angle()});
  takeCommands(al);
  publish(now);
}

void Cia402Drive::advance(SimTime dt) {
  pendingNs_ = std::min(pendingNs_ + dt, kMaxCatchUp);
  const SimTime h = axis_.substepNs();
  while (pendingNs_ >= h) {
    substep();
    pendingNs_ -= h;
    clock_ += h;
  }
}

void Cia402Drive::substep() {
  // reading_ was taken at the end of the previous substep (or at creation): now.
  internalLimit_ = false;
  ServoCommand command;
  switch (state_) {
    case State::kOperationEnabled:
      command = operate();
      break;
    case State::kQuickStopActive:
      command = stopping(false);
      break;
    case State::kFaultReactionActive:
      command = stopping(true);
      break;
    default:
      break;  // power stage off
  }
  positionDemand_ = command.mode == ControlMode::kPosition;
  followingErrorValue_ = positionDemand_ ? demand_ - measured_ : 0.0;  // both at this instant
  checkFollowingError(positionDemand_ && state_ == State::kOperationEnabled);
  if (encoder_.faulted()) raiseFault(cia402::kErrorEncoder);
  axis_.substep(command, encoder_.angleOf(static_cast<double>(reading_.counts)));
  const bool switchBefore = homeSwitch();
  const std::int64_t countsBefore = reading_.counts;
  measure();
  touchProbe_.sense(switchBefore, homeSwitch(), params_.homeSwitchCounts.value_or(0.0),
                    countsBefore, reading_.counts, encoder_.params().countsPerRevolution);
}

void Cia402Drive::checkFollowingError(bool active) {
  const std::uint64_t window = obj_.feWindow.getUnsigned(kFollowingErrorOff);
  if (!active || window == kFollowingErrorOff) {
    feSince_.reset();
    warning_ = false;
    return;
  }
  const double error = std::abs(followingErrorValue_);
  if (error <= static_cast<double>(window) * countsPerUnit_) {
    feSince_.reset();
    warning_ = false;
    return;
  }
  warning_ = true;
  if (!feSince_) feSince_ = clock_;
  const SimTime timeout = static_cast<SimTime>(obj_.feTimeout.getUnsigned(0)) * kNsPerMs;
  if (clock_ - *feSince_ >= timeout) {
    followingError_ = true;
    raiseFault(cia402::kErrorFollowing);
  }
}

void Cia402Drive::takeCommands(AlState al) {
  if (al != lastAl_) {
    lastAl_ = al;
    (void)saveState();
  }
  if (state_ == State::kNotReadyToSwitchOn && lastNow_ >= readyAt_) {
    enterState(State::kSwitchOnDisabled);  // transition 1
  }
  updatePositionFactor();
  touchProbe_.takeFunction();
  // The mode is a setting: it may be chosen by SDO before OP.
  const auto requested = static_cast<std::int8_t>(obj_.mode.get(mode_));
  if (requested != mode_) switchMode(requested);
  if (al != AlState::kOp) {
    // No valid outputs: commands are not taken; a running power stage is a fault.
    if (cia402::powered(state_) && state_ != State::kFaultReactionActive) {
      raiseFault(cia402::kErrorCommunication);
    }
    return;
  }
  const std::uint16_t previous = previousControlword_;
  const std::uint16_t controlword =
      effectiveControlword(static_cast<std::uint16_t>(obj_.controlword.getUnsigned()));
  previousControlword_ = controlword;
  const cia402::Command command = cia402::decodeControlword(controlword, previous);
  const int option = static_cast<int>(obj_.quickStopOption.get(2));
  const State next = cia402::nextState(state_, command, option);
  if (next != state_) enterState(next);
  latchModeInputs(controlword, previous);
}

void Cia402Drive::enterState(State next) {
  const State previous = state_;
  state_ = next;
  switch (next) {
    case State::kOperationEnabled:
      if (previous != State::kQuickStopActive) axis_.resetControllers();
      holding_ = false;
      startMode();
      break;
    case State::kQuickStopActive: {
      const int option = static_cast<int>(obj_.quickStopOption.get(2));
      if (option == 0) {
        state_ = State::kSwitchOnDisabled;  // disable drive function, then transition 12
        break;
      }
      profile_.reset(measured_, velocity());
      demand_ = measured_;
      holding_ = false;
      break;
    }
    case State::kFaultReactionActive:
      faultReactionStart_ = clock_;
      profile_.reset(measured_, velocity());
      holding_ = false;
      break;
    case State::kSwitchOnDisabled:
      if (previous == State::kFault) {
        errorCode_ = 0;  // transition 15: fault reset
        followingError_ = false;
        emitEmergency(cia402::kErrorReset);
      }
      break;
    default:
      break;
  }
  if (cia402::powered(previous) && !cia402::powered(state_)) (void)saveState();
}

void Cia402Drive::raiseFault(std::uint16_t code) {
  if (state_ == State::kFault || state_ == State::kFaultReactionActive) return;
  errorCode_ = code;
  enterState(cia402::powered(state_) ? State::kFaultReactionActive : State::kFault);
  emitEmergency(code);
}

void Cia402Drive::emitEmergency(std::uint16_t code) {
  const std::uint8_t reg = cia402::errorRegisterFor(code);
  obj_.errorRegister.set(reg);
  if (!emergencySink_) return;
  Emergency e;
  e.errorCode = code;
  e.errorRegister = reg;
  ++emergenciesSent_;
  emergencySink_(e);
}

void Cia402Drive::injectFault(std::uint16_t code) {
  raiseFault(code);
}

void Cia402Drive::switchMode(std::int8_t requested) {
  const std::uint32_t runnable = cia402::runnableModes(
      obj_.supportedModes ? std::optional(obj_.supportedModes.getUnsigned()) : std::nullopt);
  if ((cia402::supportedModeBit(requested) & runnable) == 0) return;  // refused: keep the mode
  mode_ = requested;
  startMode();
}

void Cia402Drive::publish(SimTime now) {
  std::uint16_t status = cia402::statusBits(state_);
  if (warning_) status |= cia402::sw::kWarning;
  if (internalLimit_) status |= cia402::sw::kInternalLimitActive;
  status |= modeStatusBits();
  statusword_ = status;
  obj_.statusword.set(status);
  obj_.modeDisplay.set(mode_);
  obj_.positionActual.set(
      wrap32(std::llround(static_cast<double>(reading_.reported + offset_) / countsPerUnit_)));
  obj_.velocityActual.set(std::llround(velocity() / countsPerUnit_));
  obj_.torqueActual.set(std::llround(axis_.torque() / params_.motor.ratedTorque * 1000.0));
  obj_.feActual.set(std::llround(followingErrorValue_ / countsPerUnit_));
  obj_.errorCode.set(errorCode_);
  obj_.digitalInputs.set(digitalInputs());
  touchProbe_.publish(static_cast<double>(offset_), countsPerUnit_);
  publishExtra(now);
}

}  // namespace ecsim::slavesim::devices
