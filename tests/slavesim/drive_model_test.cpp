// The motor/load model and the servo loops against closed-form solutions:
//  - a DC motor's speed after a voltage step is second order (J L s^2 + (J R + L b) s +
//    R b + Kt Ke), integrated exactly by the zero-order-hold discretisation;
//  - a position step under a P position loop and a P velocity loop is the textbook second-order
//    system J theta'' + (Kv + b) theta' + Kv Kp theta = Kv Kp theta*, with an ideal and with the
//    modelled current loop;
//  - Coulomb breakaway, viscous run-up, constant gravity, a pendulum's period, the torque limit.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "slavesim/devices/motor_model.hpp"
#include "slavesim/devices/servo_axis.hpp"

namespace ecsim::testing {
namespace {

namespace dev = slavesim::devices;

constexpr double kH = 1.0 / 16000.0;

// Unit step response of w_n^2 / (s^2 + 2 zeta w_n s + w_n^2).
double secondOrderStep(double zeta, double wn, double t) {
  if (zeta < 1.0) {
    const double wd = wn * std::sqrt(1.0 - zeta * zeta);
    return 1.0 - std::exp(-zeta * wn * t) *
                     (std::cos(wd * t) + zeta / std::sqrt(1.0 - zeta * zeta) * std::sin(wd * t));
  }
  if (zeta == 1.0) return 1.0 - std::exp(-wn * t) * (1.0 + wn * t);
  const double r = std::sqrt(zeta * zeta - 1.0);
  const double p1 = -wn * (zeta - r);
  const double p2 = -wn * (zeta + r);
  return 1.0 + (p2 * std::exp(p1 * t) - p1 * std::exp(p2 * t)) / (p1 - p2);
}

dev::MotorParams linearMotor() {
  dev::MotorParams m;
  m.coulombFriction = 0.0;
  return m;
}

TEST(MotorModel, VoltageStepIsTheElectromechanicalSecondOrderResponse) {
  const dev::MotorParams m = linearMotor();
  dev::MotorModel motor(m, kH, true);
  const double u = 24.0;
  // Characteristic polynomial J L s^2 + (J R + L b) s + (R b + Kt Ke).
  const double a2 = m.inertia * m.inductance;
  const double a1 = m.inertia * m.resistance + m.inductance * m.viscousFriction;
  const double a0 = m.resistance * m.viscousFriction + m.torqueConstant * m.backEmfConstant;
  const double wn = std::sqrt(a0 / a2);
  const double zeta = a1 / (2.0 * a2 * wn);
  const double wFinal = m.torqueConstant * u / a0;
  ASSERT_LT(zeta, 1.0) << "the default motor is underdamped: a real test of the oscillation";
  double worst = 0.0;
  for (int k = 1; k <= 1600; ++k) {  // 100 ms
    motor.stepVoltage(u);
    const double expected = wFinal * secondOrderStep(zeta, wn, k * kH);
    worst = std::max(worst, std::abs(motor.velocity() - expected));
  }
  EXPECT_LT(worst, 1e-6 * wFinal) << "exact discretisation: only rounding";
  EXPECT_NEAR(motor.velocity(), wFinal, 1e-3 * wFinal);
  EXPECT_NEAR(motor.current(), m.viscousFriction * wFinal / m.torqueConstant, 1e-3);
}

struct LoopCase {
  double zeta;
  double wn;  // rad/s
  bool idealCurrentLoop;
};

class PositionStep : public ::testing::TestWithParam<LoopCase> {};

TEST_P(PositionStep, MatchesTheAnalyticSecondOrderResponseWithinOnePercent) {
  const LoopCase c = GetParam();
  const dev::MotorParams m = linearMotor();
  // Kv Kp / J = wn^2 and (Kv + b) / J = 2 zeta wn.
  dev::ServoGains g;
  g.velocityKp = 2.0 * c.zeta * c.wn * m.inertia - m.viscousFriction;
  g.positionKp = c.wn * c.wn * m.inertia / g.velocityKp;
  g.velocityTi = 0.0;
  g.currentKp = m.inductance * 2.0 * std::numbers::pi * 1000.0;
  g.currentTi = m.inductance / m.resistance;
  g.velocityFeedForward = 0.0;
  dev::AxisOptions options;
  options.idealCurrentLoop = c.idealCurrentLoop;
  dev::ServoAxis axis(m, g, options);
  const double step = 2.0;  // rad
  dev::ServoCommand command;
  command.mode = dev::ControlMode::kPosition;
  command.position = step;
  double worst = 0.0;
  // Ten time constants of the slowest pole.
  const double slowest =
      c.zeta <= 1.0 ? c.zeta * c.wn : c.wn * (c.zeta - std::sqrt(c.zeta * c.zeta - 1.0));
  const int n = static_cast<int>(10.0 / slowest / kH);
  for (int k = 0; k < n; ++k) {
    const double expected = step * secondOrderStep(c.zeta, c.wn, k * kH);
    worst = std::max(worst, std::abs(axis.motor().angle() - expected));
    axis.substep(command, axis.motor().angle());
  }
  EXPECT_LT(worst, 0.01 * step) << "largest deviation " << worst / step * 100 << " % of the step";
  EXPECT_NEAR(axis.motor().angle(), step, 0.001 * step);
}

INSTANTIATE_TEST_SUITE_P(DampingAndCurrentLoop, PositionStep,
                         ::testing::Values(LoopCase{0.3, 80.0, true}, LoopCase{0.5, 80.0, true},
                                           LoopCase{0.707, 80.0, true}, LoopCase{1.0, 80.0, true},
                                           LoopCase{2.0, 80.0, true}, LoopCase{0.5, 50.0, false},
                                           LoopCase{0.707, 50.0, false},
                                           LoopCase{1.0, 50.0, false}),
                         [](const ::testing::TestParamInfo<LoopCase>& param) {
                           return "zeta" +
                                  std::to_string(static_cast<int>(param.param.zeta * 1000)) +
                                  "_wn" + std::to_string(static_cast<int>(param.param.wn)) +
                                  (param.param.idealCurrentLoop ? "_ideal" : "_currentLoop");
                         });

TEST(MotorModel, CoulombFrictionHoldsBelowBreakawayAndBrakesAbove) {
  dev::MotorParams m = linearMotor();
  m.coulombFriction = 0.1;
  dev::MotorModel motor(m, kH, false);
  for (int k = 0; k < 1600; ++k) motor.stepTorque(0.09);
  EXPECT_EQ(motor.velocity(), 0.0) << "below breakaway";
  EXPECT_EQ(motor.angle(), 0.0);
  // Above it: J w' = T - Tc - b w, so w(t) = (T - Tc)/b (1 - e^(-b t / J)).
  const double t = 0.3;
  for (int k = 1; k <= 16000; ++k) {
    motor.stepTorque(t);
    const double expected = (t - m.coulombFriction) / m.viscousFriction *
                            (1.0 - std::exp(-m.viscousFriction / m.inertia * k * kH));
    ASSERT_NEAR(motor.velocity(), expected, 1e-6 * std::abs(expected) + 1e-9) << k;
  }
  // Torque removed: friction brings it to rest and it stays there.
  for (int k = 0; k < 16000 * 20; ++k) motor.stepTorque(0.0);
  EXPECT_EQ(motor.velocity(), 0.0);
}

TEST(MotorModel, ConstantGravityAcceleratesAnUnpoweredAxis) {
  dev::MotorParams m = linearMotor();
  m.viscousFriction = 0.0;
  m.gravityTorque = 0.5;
  dev::MotorModel motor(m, kH, true);
  for (int k = 0; k < 1600; ++k) motor.stepOff();
  const double t = 0.1;
  EXPECT_NEAR(motor.angle(), -0.5 * m.gravityTorque / m.inertia * t * t, 1e-9);
  EXPECT_NEAR(motor.velocity(), -m.gravityTorque / m.inertia * t, 1e-9);
}

TEST(MotorModel, PendulumSwingsWithItsSmallAnglePeriod) {
  dev::MotorParams m = linearMotor();
  m.viscousFriction = 0.0;
  m.inertia = 0.01;
  m.gravityTorque = 1.0;
  m.gravityPendulum = true;
  dev::MotorModel motor(m, kH, false);
  motor.setAngle(0.01);
  // Small oscillations: period 2 pi sqrt(J / Tg0).
  const double period = 2.0 * std::numbers::pi * std::sqrt(m.inertia / m.gravityTorque);
  double previous = motor.velocity();
  std::vector<double> crossings;  // times the speed goes from + to -
  double amplitude = 0.0;
  for (int k = 1; k < 16000 * 3; ++k) {
    motor.stepOff();
    if (previous > 0.0 && motor.velocity() <= 0.0) crossings.push_back(k * kH);
    previous = motor.velocity();
    amplitude = std::max(amplitude, std::abs(motor.angle()));
  }
  ASSERT_GE(crossings.size(), 3u);
  EXPECT_NEAR(crossings[2] - crossings[1], period, 2 * kH);
  EXPECT_NEAR(amplitude, 0.01, 1e-4) << "no friction: the swing neither grows nor dies";
}

TEST(ServoAxis, TorqueLimitCapsTheDemandAndTheMotorTorque) {
  const dev::MotorParams m = linearMotor();
  dev::ServoAxis axis(m, dev::ServoGains::tuned(m));
  dev::ServoCommand command;
  command.mode = dev::ControlMode::kVelocity;
  command.velocity = 300.0;  // rad/s, far away: the loop asks for all it can get
  command.torqueLimit = 1.0;
  double peak = 0.0;
  for (int k = 0; k < 800; ++k) {  // 50 ms
    axis.substep(command, axis.motor().angle());
    peak = std::max(peak, std::abs(axis.torque()));
    ASSERT_LE(std::abs(axis.torqueDemand()), 1.0 + 1e-12);
  }
  EXPECT_TRUE(axis.torqueLimited());
  EXPECT_NEAR(peak, 1.0, 0.05) << "the current loop follows the limited demand";
  // Accelerating at the limit: w ~ (T/J) t for b t / J << 1.
  EXPECT_NEAR(axis.motor().velocity(), 1.0 / m.inertia * 0.05, 0.05 * 1.0 / m.inertia * 0.05);
}

TEST(ServoAxis, VelocityLoopIntegralRemovesTheFrictionError) {
  dev::MotorParams m = linearMotor();
  m.coulombFriction = 0.05;
  m.gravityTorque = 0.3;
  dev::ServoAxis axis(m, dev::ServoGains::tuned(m));
  dev::ServoCommand command;
  command.mode = dev::ControlMode::kVelocity;
  command.velocity = 50.0;
  for (int k = 0; k < 16000; ++k) axis.substep(command, axis.motor().angle());
  EXPECT_NEAR(axis.motor().velocity(), 50.0, 0.01);
  // Steady state: Kt i = b w + Tc + Tg.
  EXPECT_NEAR(axis.torque(), m.viscousFriction * 50.0 + 0.05 + 0.3, 1e-3);
}

}  // namespace
}  // namespace ecsim::testing
