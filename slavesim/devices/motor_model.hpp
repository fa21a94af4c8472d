// The motor and its load: a permanent-magnet servo motor (DC-equivalent model, one winding)
// driving a rigid load.
//
//   electrical  L di/dt = u - R i - Ke w
//   mechanical  J dw/dt = Kt i - b w - Tc sgn(w) - Tg(theta) - Text,   dtheta/dt = w
//
// with theta the shaft angle (rad, unbounded), w its speed (rad/s), i the winding current (A),
// u the converter voltage (V, limited to +/-voltageLimit), J the inertia of rotor and load,
// b viscous and Tc Coulomb friction (also the breakaway torque: a shaft at rest stays at rest
// while |Kt i - Tg - Text| <= Tc), Tg the gravity load (constant, or Tg0 sin(theta + phi) for
// a pendulum) and Text an external load torque.
//
// The linear part is integrated exactly over each substep with a zero-order hold on the inputs
// (Ad = e^(A h), Bd = integral of e^(A s) B over one substep, from the matrix exponential of
// Eigen's MatrixFunctions module), with friction, gravity and the external torque held over the
// substep. With the ideal-current option the winding is left out and the motor torque is the
// input (the current loop taken as infinitely fast).
//
// The state and the discretised matrices are plain arrays here, mapped onto Eigen types in
// motor_model.cpp only: Eigen costs about 1.8 s of compiling in each of the 66 files that reach
// this header through the drives.
#pragma once

#include <array>

namespace ecsim::slavesim::devices {

struct MotorParams {
  double inertia{2.0e-4};          // J, kg m^2 (rotor and load)
  double viscousFriction{2.0e-4};  // b, N m s/rad
  double coulombFriction{0.02};    // Tc, N m
  double gravityTorque{0.0};       // Tg0, N m, pulling towards negative angles
  bool gravityPendulum{false};     // Tg = Tg0 sin(theta + gravityAngle) instead of Tg0
  double gravityAngle{0.0};        // phi, rad
  double torqueConstant{0.5};      // Kt, N m/A
  double backEmfConstant{0.5};     // Ke, V s/rad
  double resistance{2.5};          // R, ohm
  double inductance{4.0e-3};       // L, H
  double voltageLimit{180.0};      // V
  double ratedTorque{1.27};        // N m: 1000 per mille in 0x6071/0x6072/0x6077
};

class MotorModel {
 public:
  // `electrical` false: ideal current loop, stepTorque() only.
  MotorModel(const MotorParams& params, double substepSeconds, bool electrical);

  const MotorParams& params() const { return params_; }
  double substep() const { return h_; }
  bool electrical() const { return electrical_; }

  // One substep with the converter voltage u (clamped to the voltage limit).
  void stepVoltage(double u);
  // One substep with the motor torque given directly (the winding current follows it).
  void stepTorque(double torque);
  // One substep with the power stage off: no current, no motor torque.
  void stepOff();

  double angle() const { return x_[0]; }
  double velocity() const { return x_[1]; }
  double current() const { return x_[2]; }
  double motorTorque() const { return params_.torqueConstant * x_[2]; }
  // Gravity plus external torque at the present angle (positive: pulls towards negative).
  double loadTorque() const;
  void setExternalTorque(double torque) { externalTorque_ = torque; }
  double externalTorque() const { return externalTorque_; }
  // Places the shaft (e.g. restored from a state file); speed and current are kept.
  void setAngle(double angle) { x_[0] = angle; }
  void setVelocity(double velocity) { x_[1] = velocity; }

 private:
  // Friction + load torque to hold over the next substep, for a motor torque `drive`; sets
  // stuck when the shaft is at rest and stays there.
  double disturbance(double drive, bool& stuck) const;
  void finish(double previousVelocity, double previousAngle, bool stuck);

  MotorParams params_;
  double h_;
  bool electrical_;
  // Column-major, 16-byte aligned, as Eigen's own fixed-size types.
  alignas(16) std::array<double, 3> x_{};  // theta, w, i
  // Electrical model: x' = Ad3 x + Bd3 [u, Td]; mechanical only: [theta, w]' = Ad2 . + Bd2 T.
  alignas(16) std::array<double, 9> ad3_{1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
  alignas(16) std::array<double, 6> bd3_{};
  alignas(16) std::array<double, 4> ad2_{1.0, 0.0, 0.0, 1.0};
  alignas(16) std::array<double, 2> bd2_{};
  double externalTorque_{0.0};
};

}  // namespace ecsim::slavesim::devices
