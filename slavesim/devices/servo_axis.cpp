#include "slavesim/devices/servo_axis.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace ecsim::slavesim::devices {

ServoGains ServoGains::tuned(const MotorParams& motor, double velocityHz, double currentHz) {
  const double wv = 2.0 * std::numbers::pi * velocityHz;
  const double wc = 2.0 * std::numbers::pi * currentHz;
  ServoGains g;
  g.currentKp = motor.inductance * wc;
  g.currentTi = motor.resistance > 0.0 ? motor.inductance / motor.resistance : 0.0;
  g.velocityKp = motor.inertia * wv;
  g.velocityTi = 4.0 / wv;
  g.positionKp = wv / 6.0;
  g.velocityFeedForward = 1.0;
  return g;
}

ServoAxis::ServoAxis(const MotorParams& motor, const ServoGains& gains, const AxisOptions& options)
    : motor_(motor, 1.0 / options.substepHz, !options.idealCurrentLoop),
      gains_(gains),
      substepNs_(static_cast<SimTime>(std::llround(1e9 / options.substepHz))),
      h_(1.0 / options.substepHz) {}

void ServoAxis::resetControllers() {
  velocityIntegral_ = 0.0;
  currentIntegral_ = 0.0;
}

double ServoAxis::torque() const {
  if (off_) return 0.0;
  return motor_.electrical() ? motor_.motorTorque() : torqueDemand_;
}

double ServoAxis::velocityLoop(double reference, const ServoCommand& command) {
  const double limit = std::max(0.0, command.torqueLimit);
  const double w = std::clamp(reference, -command.velocityLimit, command.velocityLimit);
  const double error = w - motor_.velocity();
  const double kv = gains_.velocityKp;
  const double integralGain = gains_.velocityTi > 0.0 ? 1.0 / gains_.velocityTi : 0.0;
  double t = kv * (error + integralGain * velocityIntegral_) + command.torque;
  const double limited = std::clamp(t, -limit, limit);
  // Conditional integration: stop integrating while the output is saturated in the direction
  // the error pushes it (anti-windup).
  if (integralGain > 0.0 && (t == limited || (t > limited) != (error > 0.0))) {
    velocityIntegral_ += error * h_;
    t = kv * (error + integralGain * velocityIntegral_) + command.torque;
  }
  return t;
}

void ServoAxis::substep(const ServoCommand& command, double measuredPosition) {
  if (command.mode == ControlMode::kOff) {
    if (!off_) resetControllers();
    off_ = true;
    torqueDemand_ = 0.0;
    torqueLimited_ = false;
    motor_.stepOff();
    return;
  }
  off_ = false;
  double t = 0.0;
  switch (command.mode) {
    case ControlMode::kPosition: {
      const double w = gains_.velocityFeedForward * command.velocity +
                       gains_.positionKp * (command.position - measuredPosition);
      t = velocityLoop(w, command);
      break;
    }
    case ControlMode::kVelocity:
      t = velocityLoop(command.velocity, command);
      break;
    case ControlMode::kTorque:
      t = command.torque;
      break;
    case ControlMode::kOff:
      break;
  }
  const double limit = std::max(0.0, command.torqueLimit);
  torqueLimited_ = std::abs(t) > limit;
  torqueDemand_ = std::clamp(t, -limit, limit);
  if (!motor_.electrical()) {
    motor_.stepTorque(torqueDemand_);
    return;
  }
  const MotorParams& p = motor_.params();
  const double error = torqueDemand_ / p.torqueConstant - motor_.current();
  const double integralGain = gains_.currentTi > 0.0 ? 1.0 / gains_.currentTi : 0.0;
  const double emf = p.backEmfConstant * motor_.velocity();
  double u = gains_.currentKp * (error + integralGain * currentIntegral_) + emf;
  const double limited = std::clamp(u, -p.voltageLimit, p.voltageLimit);
  if (integralGain > 0.0 && (u == limited || (u > limited) != (error > 0.0))) {
    currentIntegral_ += error * h_;
    u = gains_.currentKp * (error + integralGain * currentIntegral_) + emf;
  }
  motor_.stepVoltage(u);
}

}  // namespace ecsim::slavesim::devices
