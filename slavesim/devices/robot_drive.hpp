// The ECS7211 "LinuxCNC-style" robot drive: the CiA 402 drive plus robot I/O and an absolute
// position latch (examples/README.md, ECS7211):
//
//   0x6000:01 Alarm            1 while the drive is in Fault or Fault reaction active
//   0x6000:02 Limit            1 while a software position limit acts (statusword bit 11)
//   0x6000:03 Input            the home switch (DriveParams::homeSwitchCounts)
//   0x6000:04 Absolute ready   1 once 0x2010 holds the latched multi-turn encoder position
//   0x7000:01 Servo on         enables the drive for a master that sends no controlword: while
//                              the master's controlword is 0, Servo on = 1 steps the state
//                              machine to Operation enabled (shutdown, then enable operation)
//                              and Servo on = 0 disables the voltage. A nonzero controlword
//                              takes precedence.
//   0x7000:02 Clear            rising edge: fault reset (alarm clear)
//   0x7000:03 Output           a digital output of the drive: output()
//   0x7000:04 Absolute request rising edge: 0x2010 is latched again (Absolute ready drops for
//                              RobotDriveOptions::latchTime, then the new value is there)
//   0x2010    Absolute position   DINT, the encoder's multi-turn count (without home offset),
//                                 latched at creation, so an SDO upload in PREOP reads it
//   0x2011    Encoder resolution  counts per revolution
// All USINT; every object is optional (absent objects are skipped).
#pragma once

#include <cstdint>
#include <memory>

#include "slavesim/devices/cia402_drive.hpp"

namespace ecsim::slavesim::devices {

struct RobotDriveOptions {
  SimTime latchTime{2 * kNsPerMs};
};

class RobotDrive final : public Cia402Drive {
 public:
  static Result<std::unique_ptr<RobotDrive>> create(coe::ObjectDictionary& od,
                                                    const DriveParams& params = {},
                                                    const RobotDriveOptions& options = {});

  bool output() const { return output_; }
  bool absoluteReady() const { return absoluteReady_; }
  std::int32_t absolutePosition() const { return absolutePosition_; }

 protected:
  std::uint16_t effectiveControlword(std::uint16_t fromMaster) override;
  void publishExtra(SimTime now) override;

 private:
  RobotDrive(coe::ObjectDictionary& od, const DriveParams& params,
             const RobotDriveOptions& options);
  void latchAbsolute();

  RobotDriveOptions options_;
  ObjectRef alarm_, limit_, input_, ready_;
  ObjectRef servoOn_, clear_, outputRef_, request_;
  ObjectRef absolute_, resolution_;
  bool output_{false};
  bool absoluteReady_{false};
  std::int32_t absolutePosition_{0};
  bool previousClear_{false};
  bool previousRequest_{false};
  bool latching_{false};
  SimTime latchDue_{0};
};

}  // namespace ecsim::slavesim::devices
