// The CiA 402 drive's modes of operation: what the servo axis is asked to do in each substep
// of Operation enabled, of Quick stop active and of the fault reaction, and the mode-specific
// statusword bits.
#include <algorithm>
#include <cmath>
#include <limits>

#include "slavesim/devices/cia402_drive.hpp"

namespace ecsim::slavesim::devices {

using cia402::Mode;
using cia402::State;

namespace {

bool isMode(std::int8_t mode, Mode m) {
  return mode == static_cast<std::int8_t>(m);
}

// Share of the torque limit a "stop at the current limit" ramp uses (the rest is for the loops).
constexpr double kTorqueLimitRampShare = 0.9;
// Stopping ramps end with an exponential approach (seconds) plus a small constant share of the
// deceleration, so they finish in finite time.
constexpr double kStopLanding = 1e-3;
constexpr double kStopLandingFloor = 0.02;

double seconds(SimTime ns) {
  return static_cast<double>(ns) / static_cast<double>(kNsPerSecond);
}

}  // namespace

void Cia402Drive::startMode() {
  demand_ = measured_;
  profile_.reset(measured_, state_ == State::kOperationEnabled ? velocity() : 0.0);
  cspStart_ = cspEnd_ = measured_;
  cspPeriod_ = interpolationPeriod();
  cspElapsed_ = cspPeriod_;
  cspLastRaw_ = static_cast<std::int32_t>(obj_.positionActual.get());
  velocityTarget_ = 0.0;
  torqueTarget_ = 0.0;
  ppMoving_ = false;
  ppBuffered_.reset();
  ppAck_ = false;
  ppTarget_ = measured_;
  homing_ = HomingPhase::kIdle;
  feSince_.reset();
}

void Cia402Drive::latchModeInputs(std::uint16_t controlword, std::uint16_t previous) {
  namespace cw = cia402::cw;
  halt_ = (controlword & cw::kHalt) != 0;
  const bool newSetPoint = (controlword & cw::kNewSetPoint) != 0;
  const bool rising = newSetPoint && (previous & cw::kNewSetPoint) == 0;
  const bool enabled = state_ == State::kOperationEnabled;
  if (isMode(mode_, Mode::kCyclicSyncPosition)) {
    const auto raw = static_cast<std::int32_t>(obj_.targetPosition.get());
    if (enabled && raw != cspLastRaw_) {
      // A new target: interpolate from where the reference is now to it over one period.
      const double fraction =
          std::min(1.0, static_cast<double>(cspElapsed_) / static_cast<double>(cspPeriod_));
      cspStart_ = cspStart_ + (cspEnd_ - cspStart_) * fraction;
      // The 32-bit difference, so a target that wraps around moves the short way.
      const auto delta = static_cast<std::int32_t>(static_cast<std::uint32_t>(raw) -
                                                   static_cast<std::uint32_t>(cspLastRaw_));
      cspEnd_ += static_cast<double>(delta) * countsPerUnit_;
      cspPeriod_ = interpolationPeriod();
      cspElapsed_ = 0;
      cspLastRaw_ = raw;
    }
  } else if (isMode(mode_, Mode::kCyclicSyncVelocity) || isMode(mode_, Mode::kProfileVelocity)) {
    velocityTarget_ = static_cast<double>(obj_.targetVelocity.get()) * countsPerUnit_;
  } else if (isMode(mode_, Mode::kCyclicSyncTorque)) {
    torqueTarget_ =
        static_cast<double>(obj_.targetTorque.get()) / 1000.0 * params_.motor.ratedTorque;
  } else if (isMode(mode_, Mode::kProfilePosition)) {
    if (!newSetPoint) ppAck_ = false;
    if (enabled && rising) startPpSetPoint(controlword);
  } else if (isMode(mode_, Mode::kHoming)) {
    if (enabled && rising) startHoming();
    if (!newSetPoint && homing_ != HomingPhase::kDone && homing_ != HomingPhase::kError) {
      homing_ = HomingPhase::kIdle;  // bit 4 cleared: homing interrupted
    }
  }
}

bool Cia402Drive::softwareLimits(double& min, double& max) const {
  constexpr std::int64_t kLowest = std::numeric_limits<std::int32_t>::min();
  constexpr std::int64_t kHighest = std::numeric_limits<std::int32_t>::max();
  const std::int64_t lo = obj_.limitMin.get(kLowest);
  const std::int64_t hi = obj_.limitMax.get(kHighest);
  min = static_cast<double>(lo) * countsPerUnit_;
  max = static_cast<double>(hi) * countsPerUnit_;
  // The whole DINT range (the default) and an empty range mean no limits.
  return lo < hi && (lo != kLowest || hi != kHighest);
}

double Cia402Drive::clampToLimits(double position) {
  double min = 0.0, max = 0.0;
  if (!softwareLimits(min, max)) return position;
  if (position < min || position > max) {
    internalLimit_ = true;
    return std::clamp(position, min, max);
  }
  return position;
}

double Cia402Drive::feedForwardTorque(double acceleration) const {
  return axis_.gains().accelerationFeedForward * params_.motor.inertia * acceleration *
         countsToRad_;
}

ServoCommand Cia402Drive::positionCommand(double position, double velocity, double acceleration) {
  ServoCommand c;
  c.mode = ControlMode::kPosition;
  c.position = encoder_.angleOf(position - static_cast<double>(offset_));
  c.velocity = velocity * countsToRad_;
  c.torque = feedForwardTorque(acceleration);
  c.torqueLimit = torqueLimitNm();
  c.velocityLimit = velocityLimitCounts() * countsToRad_;
  return c;
}

int Cia402Drive::limitSide() const {
  double min = 0.0, max = 0.0;
  if (!softwareLimits(min, max)) return 0;
  if (measured_ >= max) return 1;
  if (measured_ <= min) return -1;
  return 0;
}

ServoCommand Cia402Drive::velocityCommand(double velocity, double acceleration) {
  // Software limits: no speed further outwards once at a limit.
  const int side = limitSide();
  if ((side > 0 && velocity > 0.0) || (side < 0 && velocity < 0.0)) {
    velocity = 0.0;
    acceleration = 0.0;
    internalLimit_ = true;
  }
  ServoCommand c;
  c.mode = ControlMode::kVelocity;
  c.velocity = velocity * countsToRad_;
  c.torque = feedForwardTorque(acceleration);
  c.torqueLimit = torqueLimitNm();
  c.velocityLimit = velocityLimitCounts() * countsToRad_;
  return c;
}

ServoCommand Cia402Drive::operate() {
  const double h = seconds(axis_.substepNs());
  const double vmax = velocityLimitCounts();
  const double acc =
      static_cast<double>(obj_.profileAcceleration.getUnsigned(6553600)) * countsPerUnit_;
  const double dec =
      static_cast<double>(obj_.profileDeceleration.getUnsigned(6553600)) * countsPerUnit_;
  switch (static_cast<Mode>(mode_)) {
    case Mode::kCyclicSyncPosition: {
      const double fraction =
          std::min(1.0, static_cast<double>(cspElapsed_) / static_cast<double>(cspPeriod_));
      const bool moving = cspElapsed_ < cspPeriod_;
      cspElapsed_ = std::min(cspElapsed_ + axis_.substepNs(), cspPeriod_);
      const double reference = cspStart_ + (cspEnd_ - cspStart_) * fraction;
      demand_ = clampToLimits(reference);
      const double feedForward =
          moving && !internalLimit_ ? (cspEnd_ - cspStart_) / seconds(cspPeriod_) : 0.0;
      return positionCommand(demand_, feedForward);
    }
    case Mode::kCyclicSyncVelocity:
      return velocityCommand(std::clamp(velocityTarget_, -vmax, vmax));
    case Mode::kCyclicSyncTorque: {
      ServoCommand c;
      c.mode = ControlMode::kTorque;
      c.torque = torqueTarget_;
      c.torqueLimit = torqueLimitNm();
      const int side = limitSide();
      if ((side > 0 && c.torque > 0.0) || (side < 0 && c.torque < 0.0)) {
        c.torque = 0.0;  // at a software limit: no torque outwards
        internalLimit_ = true;
      }
      return c;
    }
    case Mode::kProfileVelocity: {
      const double target = halt_ ? 0.0 : std::clamp(velocityTarget_, -vmax, vmax);
      profile_.toVelocity(target, acc, dec, h);
      return velocityCommand(profile_.velocity(), profile_.acceleration());
    }
    case Mode::kProfilePosition: {
      if (halt_) {
        profile_.toVelocity(0.0, acc, dec, h);
      } else if (ppMoving_) {
        const double speed =
            static_cast<double>(obj_.profileVelocity.getUnsigned(655360)) * countsPerUnit_;
        if (profile_.toPosition(ppTarget_, std::min(speed, vmax), acc, dec, h)) {
          ppMoving_ = false;
          if (ppBuffered_) {
            ppTarget_ = *ppBuffered_;
            ppBuffered_.reset();
            ppMoving_ = true;
          }
        }
      }
      demand_ = profile_.position();
      return positionCommand(demand_, profile_.velocity(), profile_.acceleration());
    }
    case Mode::kHoming:
      homingSubstep(h);
      demand_ = profile_.position();
      return positionCommand(demand_, profile_.velocity(), profile_.acceleration());
    default:
      return positionCommand(demand_, 0.0);  // no mode yet: hold
  }
}

ServoCommand Cia402Drive::stopping(bool faultReaction) {
  const double h = seconds(axis_.substepNs());
  if (faultReaction && clock_ - faultReactionStart_ >= params_.faultReactionTimeout) {
    enterState(State::kFault);  // transition 14 (the stop took too long)
    return {};
  }
  const int option = faultReaction ? 2 : static_cast<int>(obj_.quickStopOption.get(2));
  if (holding_) return positionCommand(demand_, 0.0);
  double deceleration = params_.quickStopDeceleration;
  if (option == 1 || option == 5) {
    deceleration =
        static_cast<double>(obj_.profileDeceleration.getUnsigned(6553600)) * countsPerUnit_;
  } else if (option == 3 || option == 4 || option == 7 || option == 8) {
    // "At the current limit": the ramp the torque limit allows, with a margin for the loops.
    deceleration = kTorqueLimitRampShare * torqueLimitNm() / params_.motor.inertia / countsToRad_;
  }
  // The last part of the ramp eases off (deceleration proportional to the remaining speed,
  // time constant kStopLanding), so the torque falls smoothly and the current loop can follow
  // without the axis reversing.
  const double landing =
      std::abs(profile_.velocity()) / kStopLanding + kStopLandingFloor * deceleration;
  deceleration = std::min(deceleration, landing);
  profile_.toVelocity(0.0, deceleration, deceleration, h);
  ServoCommand c = velocityCommand(profile_.velocity(), profile_.acceleration());
  const bool stopped =
      profile_.velocity() == 0.0 && std::abs(velocity()) <= params_.velocityThreshold;
  if (!stopped) return c;
  if (faultReaction) {
    enterState(State::kFault);  // transition 14
    return {};
  }
  if (option >= 1 && option <= 4) {
    enterState(State::kSwitchOnDisabled);  // transition 12
    return {};
  }
  holding_ = true;  // options 5-8: stay in Quick stop active, holding the position
  demand_ = measured_;
  return positionCommand(demand_, 0.0);
}

void Cia402Drive::startPpSetPoint(std::uint16_t controlword) {
  namespace cw = cia402::cw;
  const auto raw = static_cast<std::int32_t>(obj_.targetPosition.get());
  double target = 0.0;
  if ((controlword & cw::kRelative) != 0) {
    target = (ppMoving_ ? ppTarget_ : demand_) + raw * countsPerUnit_;
  } else {
    // The absolute target nearest the present position in 32-bit arithmetic (user units).
    const double hereUnits = std::round(measured_ / countsPerUnit_);
    const auto here = static_cast<std::int32_t>(
        static_cast<std::uint32_t>(static_cast<std::uint64_t>(std::llround(hereUnits))));
    const auto delta = static_cast<std::int32_t>(static_cast<std::uint32_t>(raw) -
                                                 static_cast<std::uint32_t>(here));
    target = (hereUnits + delta) * countsPerUnit_;
  }
  target = clampToLimits(target);
  internalLimit_ = false;
  if (!ppMoving_ || (controlword & cw::kChangeImmediately) != 0) {
    ppTarget_ = target;
    ppMoving_ = true;
    ppBuffered_.reset();
    ppAck_ = true;
  } else if (!ppBuffered_) {
    ppBuffered_ = target;
    ppAck_ = true;
  }
  // Else the buffer is full: no acknowledge, the master retries.
}

void Cia402Drive::startHoming() {
  homingMethod_ = static_cast<int>(obj_.homingMethod.get(37));
  homingAttained_ = false;
  const bool switchKnown = params_.homeSwitchCounts.has_value();
  switch (homingMethod_) {
    case 35:
    case 37:
      setHome();
      homing_ = HomingPhase::kDone;
      break;
    case 19:
      homing_ = !switchKnown   ? HomingPhase::kError
                : homeSwitch() ? HomingPhase::kSearchEdge
                               : HomingPhase::kSearchSwitch;
      break;
    case 20:
      homing_ = !switchKnown   ? HomingPhase::kError
                : homeSwitch() ? HomingPhase::kLeaveSwitch
                               : HomingPhase::kSearchEdge;
      break;
    default:
      homing_ = HomingPhase::kError;  // method not supported
      break;
  }
}

void Cia402Drive::setHome() {
  const std::int64_t offset = params_.homeOffset - reading_.counts;
  const auto delta = static_cast<double>(offset - offset_);
  offset_ = offset;
  measured_ += delta;
  demand_ += delta;
  profile_.shift(delta);
  cspStart_ += delta;
  cspEnd_ += delta;
  ppTarget_ += delta;
  homingAttained_ = true;
}

void Cia402Drive::homingSubstep(double h) {
  const double fast =
      static_cast<double>(obj_.homingSpeedSwitch.getUnsigned(655360)) * countsPerUnit_;
  const double slow =
      static_cast<double>(obj_.homingSpeedZero.getUnsigned(65536)) * countsPerUnit_;
  const double acc =
      static_cast<double>(obj_.homingAcceleration.getUnsigned(6553600)) * countsPerUnit_;
  const bool on = homeSwitch();
  if (halt_ && homing_ != HomingPhase::kDone && homing_ != HomingPhase::kError) {
    homing_ = HomingPhase::kIdle;  // halt interrupts homing
  }
  const bool positive19 = homingMethod_ == 19;
  switch (homing_) {
    case HomingPhase::kSearchSwitch:  // method 19: towards the switch
      profile_.toVelocity(fast, acc, acc, h);
      if (on) homing_ = HomingPhase::kSearchEdge;
      break;
    case HomingPhase::kLeaveSwitch:  // method 20: out of the switch
      profile_.toVelocity(-fast, acc, acc, h);
      if (!on) homing_ = HomingPhase::kSearchEdge;
      break;
    case HomingPhase::kSearchEdge:
      // 19: home where the switch goes off moving negative; 20: where it comes on moving
      // positive.
      profile_.toVelocity(positive19 ? -slow : slow, acc, acc, h);
      if (positive19 ? !on : on) {
        setHome();
        homing_ = HomingPhase::kStopping;
      }
      break;
    case HomingPhase::kStopping:
      if (profile_.toVelocity(0.0, acc, acc, h)) homing_ = HomingPhase::kDone;
      break;
    case HomingPhase::kIdle:
    case HomingPhase::kDone:
    case HomingPhase::kError:
      profile_.toVelocity(0.0, acc, acc, h);
      break;
  }
}

std::uint16_t Cia402Drive::modeStatusBits() const {
  namespace sw = cia402::sw;
  if (state_ != State::kOperationEnabled) return 0;
  const double v = velocity();
  const bool still = std::abs(v) <= params_.velocityThreshold;
  std::uint16_t bits = 0;
  switch (static_cast<Mode>(mode_)) {
    case Mode::kProfilePosition: {
      const bool reached =
          halt_ ? (profile_.velocity() == 0.0 && still)
                : (!ppMoving_ && std::abs(ppTarget_ - measured_) <= params_.positionWindow);
      if (reached) bits |= sw::kTargetReached;
      if (ppAck_) bits |= sw::kModeSpecific12;
      if (followingError_) bits |= sw::kModeSpecific13;
      break;
    }
    case Mode::kProfileVelocity: {
      const double target = halt_ ? 0.0 : velocityTarget_;
      if (std::abs(v - target) <= params_.velocityWindow) bits |= sw::kTargetReached;
      if (still) bits |= sw::kModeSpecific12;
      break;
    }
    case Mode::kHoming:
      switch (homing_) {
        case HomingPhase::kIdle:
          bits |= sw::kTargetReached;  // not started or interrupted
          break;
        case HomingPhase::kStopping:
          bits |= sw::kModeSpecific12;  // attained, still moving
          break;
        case HomingPhase::kDone:
          bits |= sw::kModeSpecific12 | sw::kTargetReached;
          break;
        case HomingPhase::kError:
          bits |= sw::kModeSpecific13;
          if (still) bits |= sw::kTargetReached;
          break;
        default:
          break;  // in progress
      }
      break;
    case Mode::kCyclicSyncPosition:
      bits |= sw::kModeSpecific12;  // the target position is used
      if (followingError_) bits |= sw::kModeSpecific13;
      break;
    case Mode::kCyclicSyncVelocity:
    case Mode::kCyclicSyncTorque:
      bits |= sw::kModeSpecific12;
      break;
    default:
      break;
  }
  return bits;
}

}  // namespace ecsim::slavesim::devices
