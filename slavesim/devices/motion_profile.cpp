#include "slavesim/devices/motion_profile.hpp"

#include <algorithm>
#include <cmath>

namespace ecsim::slavesim::devices {
namespace {

double sign(double v) {
  return v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0);
}

}  // namespace

bool MotionProfile::toPosition(double target, double maxVelocity, double acceleration,
                               double deceleration, double dt) {
  acceleration = std::max(acceleration, 1e-9);
  deceleration = std::max(deceleration, 1e-9);
  maxVelocity = std::max(maxVelocity, 0.0);
  const double distance = target - position_;
  const double direction = sign(distance);
  acceleration_ = 0.0;
  if (direction == 0.0 && velocity_ == 0.0) return true;
  const double v0 = velocity_;
  double v1 = 0.0;
  if (direction == 0.0 || v0 * direction < 0.0) {
    // At the target while moving, or moving away from it: brake first.
    v1 = v0 - sign(v0) * std::min(std::abs(v0), deceleration * dt);
  } else {
    const double speed = std::abs(v0);
    const double up = speed + acceleration * dt;
    const double cap =
        speed > maxVelocity ? std::max(maxVelocity, speed - deceleration * dt) : maxVelocity;
    const double stopping = std::sqrt(2.0 * deceleration * std::abs(distance));
    v1 = direction * std::min({up, cap, stopping});
  }
  const double next = position_ + 0.5 * (v0 + v1) * dt;
  // Landing on (or passing) the target at a speed one step of deceleration can absorb: done.
  if (direction != 0.0 && sign(target - next) != direction &&
      std::abs(v1) <= deceleration * dt * 2.0 + 1e-9) {
    position_ = target;
    velocity_ = 0.0;
    return true;
  }
  position_ = next;
  velocity_ = v1;
  acceleration_ = dt > 0.0 ? (v1 - v0) / dt : 0.0;
  return false;
}

bool MotionProfile::toVelocity(double target, double acceleration, double deceleration, double dt) {
  const double v0 = velocity_;
  // Speeding up (same direction, larger magnitude) uses the acceleration, anything else the
  // deceleration until the sign changes.
  const bool speedingUp =
      v0 == 0.0 || (sign(target) == sign(v0) && std::abs(target) > std::abs(v0));
  const double rate = std::max(speedingUp ? acceleration : deceleration, 1e-9) * dt;
  double v1 = target;
  if (std::abs(target - v0) > rate) v1 = v0 + sign(target - v0) * rate;
  // Crossing zero: stop there, the next step speeds up in the other direction.
  if (v0 != 0.0 && sign(v1) != sign(v0) && sign(v1) != 0.0) v1 = 0.0;
  position_ += 0.5 * (v0 + v1) * dt;
  velocity_ = v1;
  acceleration_ = dt > 0.0 ? (v1 - v0) / dt : 0.0;
  return v1 == target;
}

}  // namespace ecsim::slavesim::devices
