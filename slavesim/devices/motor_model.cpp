#include "slavesim/devices/motor_model.hpp"

#include <algorithm>
#include <Eigen/Dense>
#include <cmath>
#include <unsupported/Eigen/MatrixFunctions>

namespace ecsim::slavesim::devices {
namespace {

// The header's arrays seen as the matrices they hold.
template <int R, int C, std::size_t N>
Eigen::Map<Eigen::Matrix<double, R, C>, Eigen::Aligned16> asMatrix(std::array<double, N>& a) {
  static_assert(N == R * C);
  return Eigen::Map<Eigen::Matrix<double, R, C>, Eigen::Aligned16>(a.data());
}
template <int R, int C, std::size_t N>
Eigen::Map<const Eigen::Matrix<double, R, C>, Eigen::Aligned16> asMatrix(
    const std::array<double, N>& a) {
  static_assert(N == R * C);
  return Eigen::Map<const Eigen::Matrix<double, R, C>, Eigen::Aligned16>(a.data());
}

// Zero-order-hold discretisation of x' = A x + B u over h: the exponential of the augmented
// matrix [[A, B], [0, 0]] h is [[Ad, Bd], [0, I]].
template <int N, int M>
void discretize(const Eigen::Matrix<double, N, N>& a, const Eigen::Matrix<double, N, M>& b,
                double h, Eigen::Matrix<double, N, N>& ad, Eigen::Matrix<double, N, M>& bd) {
  Eigen::Matrix<double, N + M, N + M> m = Eigen::Matrix<double, N + M, N + M>::Zero();
  m.template topLeftCorner<N, N>() = a * h;
  m.template topRightCorner<N, M>() = b * h;
  const Eigen::Matrix<double, N + M, N + M> e = m.exp();
  ad = e.template topLeftCorner<N, N>();
  bd = e.template topRightCorner<N, M>();
}

double sign(double v) {
  return v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0);
}

}  // namespace

MotorModel::MotorModel(const MotorParams& params, double substepSeconds, bool electrical)
    : params_(params), h_(substepSeconds), electrical_(electrical) {
  const double j = params_.inertia;
  const double b = params_.viscousFriction;
  Eigen::Matrix2d a2;
  a2 << 0.0, 1.0, 0.0, -b / j;
  Eigen::Vector2d b2(0.0, 1.0 / j);
  Eigen::Matrix2d ad2;
  Eigen::Matrix<double, 2, 1> bd2;
  discretize<2, 1>(a2, b2, h_, ad2, bd2);
  asMatrix<2, 2>(ad2_) = ad2;
  asMatrix<2, 1>(bd2_) = bd2;
  if (electrical_) {
    const double l = params_.inductance;
    Eigen::Matrix3d a3;
    a3 << 0.0, 1.0, 0.0,                          //
        0.0, -b / j, params_.torqueConstant / j,  //
        0.0, -params_.backEmfConstant / l, -params_.resistance / l;
    Eigen::Matrix<double, 3, 2> b3;
    b3 << 0.0, 0.0,  //
        0.0, -1.0 / j, 1.0 / l, 0.0;
    Eigen::Matrix3d ad3;
    Eigen::Matrix<double, 3, 2> bd3;
    discretize<3, 2>(a3, b3, h_, ad3, bd3);
    asMatrix<3, 3>(ad3_) = ad3;
    asMatrix<3, 2>(bd3_) = bd3;
  }
}

double MotorModel::loadTorque() const {
  const double gravity = params_.gravityPendulum
                             ? params_.gravityTorque * std::sin(x_[0] + params_.gravityAngle)
                             : params_.gravityTorque;
  return gravity + externalTorque_;
}

double MotorModel::disturbance(double drive, bool& stuck) const {
  const double load = loadTorque();
  const double tc = params_.coulombFriction;
  const double w = x_[1];
  stuck = false;
  if (w != 0.0) return tc * sign(w) + load;
  const double net = drive - load;
  if (tc > 0.0 && std::abs(net) <= tc) {
    stuck = true;
    return drive;  // static friction balances the motor: no acceleration
  }
  return tc * sign(net) + load;
}

void MotorModel::finish(double previousVelocity, double previousAngle, bool stuck) {
  if (stuck) {
    x_[0] = previousAngle;
    x_[1] = 0.0;
    return;
  }
  // Coulomb friction stops a shaft whose speed crosses zero within the substep; it breaks
  // away again in a later substep if the torque exceeds the friction.
  if (params_.coulombFriction > 0.0 && previousVelocity != 0.0 &&
      sign(x_[1]) != sign(previousVelocity)) {
    x_[1] = 0.0;
  }
}

void MotorModel::stepVoltage(double u) {
  if (!electrical_) {
    stepTorque(0.0);
    return;
  }
  u = std::clamp(u, -params_.voltageLimit, params_.voltageLimit);
  const double w0 = x_[1];
  const double theta0 = x_[0];
  bool stuck = false;
  const double td = disturbance(motorTorque(), stuck);
  const Eigen::Vector3d next =
      asMatrix<3, 3>(ad3_) * asMatrix<3, 1>(x_) + asMatrix<3, 2>(bd3_) * Eigen::Vector2d(u, td);
  asMatrix<3, 1>(x_) = next;
  finish(w0, theta0, stuck);
}

void MotorModel::stepTorque(double torque) {
  const double w0 = x_[1];
  const double theta0 = x_[0];
  bool stuck = false;
  const double td = disturbance(torque, stuck);
  const Eigen::Vector2d mech =
      asMatrix<2, 2>(ad2_) * asMatrix<3, 1>(x_).head<2>() + asMatrix<2, 1>(bd2_) * (torque - td);
  asMatrix<3, 1>(x_).head<2>() = mech;
  x_[2] = torque / params_.torqueConstant;
  finish(w0, theta0, stuck);
}

void MotorModel::stepOff() {
  stepTorque(0.0);
}

}  // namespace ecsim::slavesim::devices
