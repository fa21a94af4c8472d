// A servo axis: the motor model under the cascaded loops of a servo drive, all run once per
// substep (16 kHz by default):
//
//   position  w* = Kvff w_ff + Kp (theta* - theta_m)                    (P, theta_m measured)
//   velocity  T* = Kv (e_w + (1/Tn) integral e_w) + T_ff,  e_w = w* - w  (PI, anti-windup)
//   current   u  = Kc (e_i + (1/Tc) integral e_i) + Ke w,  e_i = T*/Kt - i  (PI + EMF decoupling)
//
// with w* limited to the speed limit and T* to the torque limit. Velocity mode enters at the
// velocity loop, torque mode at the current loop. With the ideal-current option the motor
// torque equals T* (no winding model). Units are SI (rad, rad/s, N m, A, V); the drive converts
// from encoder counts.
#pragma once

#include <cstdint>
#include <limits>

#include "protocol/time.hpp"
#include "slavesim/devices/motor_model.hpp"

namespace ecsim::slavesim::devices {

struct ServoGains {
  double positionKp{0.0};               // (rad/s)/rad
  double velocityKp{0.0};               // N m/(rad/s)
  double velocityTi{0.0};               // s; 0: no integral action
  double currentKp{0.0};                // V/A
  double currentTi{0.0};                // s; 0: no integral action
  double velocityFeedForward{1.0};      // share of the demand speed added to w*
  double accelerationFeedForward{1.0};  // share of J a (profile acceleration) added to T*
  // Loops tuned by the usual rules: current loop crossover at currentHz with its zero on the
  // winding pole (Kc = L wc, Tc = L/R), velocity loop crossover at velocityHz (Kv = J wv,
  // Tn = 4/wv), position gain wv/6.
  static ServoGains tuned(const MotorParams& motor, double velocityHz = 100.0,
                          double currentHz = 1000.0);
};

enum class ControlMode : std::uint8_t { kOff, kPosition, kVelocity, kTorque };

struct ServoCommand {
  ControlMode mode{ControlMode::kOff};
  double position{0.0};  // rad: reference (position mode)
  double velocity{0.0};  // rad/s: feed-forward (position) or reference (velocity)
  double torque{0.0};    // N m: feed-forward (position, velocity) or reference (torque)
  double torqueLimit{std::numeric_limits<double>::infinity()};    // N m
  double velocityLimit{std::numeric_limits<double>::infinity()};  // rad/s
};

struct AxisOptions {
  double substepHz{16000.0};
  bool idealCurrentLoop{false};
};

class ServoAxis {
 public:
  ServoAxis(const MotorParams& motor, const ServoGains& gains, const AxisOptions& options = {});

  // Substep length in ns (62500 at 16 kHz).
  SimTime substepNs() const { return substepNs_; }
  // One control period and one plant step. `measuredPosition` is the position feedback (rad)
  // as the drive's encoder reports it.
  void substep(const ServoCommand& command, double measuredPosition);
  // Clears the integrators (on enabling, or on a mode change).
  void resetControllers();

  MotorModel& motor() { return motor_; }
  const MotorModel& motor() const { return motor_; }
  const ServoGains& gains() const { return gains_; }
  void setGains(const ServoGains& gains) { gains_ = gains; }
  // Torque the loops asked for in the last substep (after limiting), and whether the limit cut it.
  double torqueDemand() const { return torqueDemand_; }
  bool torqueLimited() const { return torqueLimited_; }
  // Motor torque: Kt i (or the demand, with an ideal current loop; 0 while off).
  double torque() const;

 private:
  double velocityLoop(double reference, const ServoCommand& command);

  MotorModel motor_;
  ServoGains gains_;
  SimTime substepNs_;
  double h_;
  double velocityIntegral_{0.0};  // integral of e_w, rad
  double currentIntegral_{0.0};   // integral of e_i, A s
  double torqueDemand_{0.0};
  bool torqueLimited_{false};
  bool off_{true};
};

}  // namespace ecsim::slavesim::devices
