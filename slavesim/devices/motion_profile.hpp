// An online trapezoidal motion generator (acceleration-limited, no jerk limit), stepped at the
// drive's substep rate. Used for profile position and velocity, homing moves and stopping
// ramps. Positions and velocities in counts and counts/s. The target, limits and ramps may
// change between steps (a new set-point "immediately", a halt, a quick stop): the generator
// continues from where it is.
//
// Towards a position it runs at min(vmax, sqrt(2 dec |distance|)) reached with `acc`, which in
// continuous time is the trapezoid (or triangle) of the profile; positions integrate the mean
// velocity of each step, and the final step lands exactly on the target.
#pragma once

namespace ecsim::slavesim::devices {

class MotionProfile {
 public:
  void reset(double position, double velocity) {
    position_ = position;
    velocity_ = velocity;
    acceleration_ = 0.0;
  }
  // Shifts the position (a new home offset) without changing the motion.
  void shift(double delta) { position_ += delta; }

  // One step of `dt` seconds towards `target`; returns true once there at rest.
  bool toPosition(double target, double maxVelocity, double acceleration, double deceleration,
                  double dt);
  // One step of the velocity towards `target` (acceleration while the speed grows,
  // deceleration while it falls); returns true once the velocity equals the target.
  bool toVelocity(double target, double acceleration, double deceleration, double dt);

  double position() const { return position_; }
  double velocity() const { return velocity_; }
  // Mean acceleration of the last step (counts/s^2), for torque feed-forward.
  double acceleration() const { return acceleration_; }

 private:
  double position_{0.0};
  double velocity_{0.0};
  double acceleration_{0.0};
};

}  // namespace ecsim::slavesim::devices
