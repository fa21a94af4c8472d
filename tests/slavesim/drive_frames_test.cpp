// The drives end to end through frames, as a master meets them: slaves built by
// makeSlaveFromEsi from examples/esi/ecsim_devices.xml (which attaches the drive model),
// brought to OP with frames, then the CiA 402 enable sequence and a CSP ramp over LRW cycles;
// the ECS7211 with the LinuxCNC-style PDO selection, robot I/O and the absolute position read
// by SDO at start-up; and a simulated power cycle and restart with a state file.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <optional>

#include "slavesim/devices/device_models.hpp"
#include "slavesim/devices/device_state.hpp"
#include "tests/slavesim/drive_test_support.hpp"

namespace ecsim::testing {
namespace {

constexpr double kCpr = 131072.0;

// ECS7201 default images (examples/README.md): SM2 13 bytes, SM3 15 bytes.
namespace pd7201 {
constexpr std::size_t kControlword = 0, kTargetPosition = 2, kTargetVelocity = 6, kMode = 12;
constexpr std::size_t kStatusword = 0, kPosition = 2, kVelocity = 6, kModeDisplay = 12,
                      kErrorCode = 13;
}  // namespace pd7201

std::optional<State> stateOf(std::uint16_t statusword) {
  return c402::stateFromStatusword(statusword);
}

// Sends `controlword` until the statusword shows `expected` (at most `cycles` cycles).
bool commandUntil(CyclicExchange& x, std::size_t cwOffset, std::uint16_t controlword,
                  std::size_t swOffset, State expected, int cycles = 5) {
  x.put16(cwOffset, controlword);
  for (int i = 0; i < cycles; ++i) {
    x.cycle();
    if (stateOf(x.in16(swOffset)) == expected) return true;
  }
  return false;
}

TEST(DriveFrames, Ecs7201EnablesAndFollowsACspRampWithThePredictedLag) {
  topology::Segment seg;
  seg.addSlave(makeExampleSlave(kEcs7201));
  ASSERT_NE(dev::driveOf(seg.slave(0)), nullptr) << "makeSlaveFromEsi attached the drive";
  OpSlave op = bringToOp(seg, {{2, true, 13}, {3, false, 15}});
  ASSERT_EQ(op.outBytes, 13);
  ASSERT_EQ(op.inBytes, 15);
  CyclicExchange x{seg, op.outBytes, op.inBytes};
  x.put8(pd7201::kMode, 8);  // CSP
  x.cycle();
  x.cycle();
  EXPECT_EQ(x.wkc, 3);
  EXPECT_EQ(stateOf(x.in16(pd7201::kStatusword)), State::kSwitchOnDisabled);
  EXPECT_EQ(static_cast<std::int8_t>(x.in8(pd7201::kModeDisplay)), 8);
  EXPECT_EQ(x.in16(pd7201::kErrorCode), 0);
  // The enable sequence, target position held at the actual position.
  const std::int32_t start = x.in32(pd7201::kPosition);
  x.put32(pd7201::kTargetPosition, start);
  ASSERT_TRUE(
      commandUntil(x, pd7201::kControlword, 0x0006, pd7201::kStatusword, State::kReadyToSwitchOn));
  ASSERT_TRUE(
      commandUntil(x, pd7201::kControlword, 0x0007, pd7201::kStatusword, State::kSwitchedOn));
  ASSERT_TRUE(
      commandUntil(x, pd7201::kControlword, 0x000F, pd7201::kStatusword, State::kOperationEnabled));
  EXPECT_NE(x.in16(pd7201::kStatusword) & c402::sw::kModeSpecific12, 0);
  // A ramp at one revolution per second, one target per 1 ms cycle.
  const double v = kCpr;
  double target = start;
  for (int k = 0; k < 600; ++k) {
    target += v * 1e-3;
    x.put32(pd7201::kTargetPosition, static_cast<std::int32_t>(std::lround(target)));
    x.cycle();
    ASSERT_EQ(x.wkc, 3);
    ASSERT_EQ(stateOf(x.in16(pd7201::kStatusword)), State::kOperationEnabled) << k;
  }
  // What the frame of cycle k shows was sampled at its start, when the drive's reference had
  // reached the target of cycle k-1: the interpolation over 0x60C2 (1 ms) delays it by one
  // period, and with speed feed-forward the loops add no steady lag. So the master sees
  // target - actual = v * 1 ms.
  const dev::Cia402Drive* drive = dev::driveOf(seg.slave(0));
  const double kp = drive->axis().gains().positionKp;
  const double ff = drive->axis().gains().velocityFeedForward;
  const double predicted = v * 1e-3 + (1.0 - ff) * v / kp;
  const double lag = target - x.in32(pd7201::kPosition);
  EXPECT_NEAR(lag, predicted, 0.01 * predicted + 2.0);
  EXPECT_NEAR(x.in32(pd7201::kVelocity), v, 0.002 * v);
  EXPECT_NEAR(x.in32(pd7201::kPosition) - start, 0.599 * v, 0.01 * v) << "travelled";
}

TEST(DriveFrames, Ecs7211LinuxCncStyleWithRobotIoAndAbsolutePosition) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("ecsim-drive-frames-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto stateFile = dir / "axis.state";
  ASSERT_TRUE(dev::saveDeviceState(stateFile, {2.5 * 2.0 * std::numbers::pi}).ok());
  slavesim::EsiSlaveOptions options;
  options.stateFile = stateFile;
  topology::Segment seg;
  seg.addSlave(makeExampleSlave(kEcs7211, options));
  dev::RobotDrive* robot = dev::robotDriveOf(seg.slave(0));
  ASSERT_NE(robot, nullptr);
  std::int32_t absoluteAtStart = 0;
  std::uint32_t resolution = 0;
  // LinuxCNC-style: read the absolute position at start-up, choose the CSP PDOs, mode 8.
  auto configure = [&](MailboxMaster& m) {
    absoluteAtStart = m.uploadValue<std::int32_t>(0x2010, 0);
    resolution = m.uploadValue<std::uint32_t>(0x2011, 0);
    EXPECT_EQ(m.download(0x1C12, 0, {0}), 0u);
    EXPECT_EQ(m.download(0x1C12, 1, le16(0x1602)), 0u);
    EXPECT_EQ(m.download(0x1C12, 2, le16(0x1604)), 0u);
    EXPECT_EQ(m.download(0x1C12, 0, {2}), 0u);
    EXPECT_EQ(m.download(0x1C13, 0, {0}), 0u);
    EXPECT_EQ(m.download(0x1C13, 1, le16(0x1A02)), 0u);
    EXPECT_EQ(m.download(0x1C13, 2, le16(0x1A04)), 0u);
    EXPECT_EQ(m.download(0x1C13, 3, le16(0x1A05)), 0u);
    EXPECT_EQ(m.download(0x1C13, 0, {3}), 0u);
    EXPECT_EQ(m.download(0x6060, 0, {8}), 0u);
  };
  OpSlave op = bringToOp(seg, {{2, true, 10}, {3, false, 18}}, 0, configure);
  EXPECT_EQ(absoluteAtStart, static_cast<std::int32_t>(2.5 * kCpr)) << "0x2010 from the encoder";
  EXPECT_EQ(resolution, 131072u);
  // SM2: 0 controlword, 2 target position, 6..9 servo on, clear, output, absolute request.
  // SM3: 0 statusword, 2 position, 6..9 alarm, limit, input, absolute ready, 10 following
  // error, 14 absolute position.
  CyclicExchange x{seg, op.outBytes, op.inBytes};
  x.put32(2, absoluteAtStart);
  x.cycle();
  x.cycle();
  ASSERT_EQ(x.wkc, 3);
  EXPECT_EQ(x.in32(2), absoluteAtStart);
  EXPECT_EQ(x.in8(9), 1) << "absolute ready";
  EXPECT_EQ(x.in32(14), absoluteAtStart);
  EXPECT_EQ(x.in8(6), 0) << "no alarm";
  // Servo on with controlword 0: the drive enables itself.
  x.put8(6, 1);
  x.put8(8, 1);  // output on
  for (int i = 0; i < 5; ++i) x.cycle();
  EXPECT_EQ(stateOf(x.in16(0)), State::kOperationEnabled);
  EXPECT_TRUE(robot->output());
  // A short CSP move, -0.2 revolutions over 200 ms.
  double target = absoluteAtStart;
  for (int k = 0; k < 200; ++k) {
    target -= 0.001 * kCpr;
    x.put32(2, static_cast<std::int32_t>(std::lround(target)));
    x.cycle();
  }
  for (int k = 0; k < 50; ++k) x.cycle();
  // Within a few counts: the default motor has Coulomb friction, so the last counts are
  // stick-slip under the PI speed loop.
  EXPECT_NEAR(x.in32(2), target, 10.0);
  EXPECT_NEAR(static_cast<double>(static_cast<std::int32_t>(readLe32(x.in, 10))), 0.0, 10.0)
      << "0x60F4 at rest";
  EXPECT_EQ(x.in32(14), absoluteAtStart) << "0x2010 is a latch";
  // Absolute request: the drive sees it after the frame that brings it, so the next frame
  // shows ready down; 2 ms later the new value is there.
  x.put8(9, 1);
  x.cycle();
  x.cycle();
  EXPECT_EQ(x.in8(9), 0);
  int cycles = 0;
  while (x.in8(9) == 0 && cycles < 10) {
    x.cycle();
    ++cycles;
  }
  EXPECT_EQ(x.in8(9), 1);
  EXPECT_LE(cycles, 3);
  EXPECT_NEAR(x.in32(14), x.in32(2), 2.0) << "0x2010 latched again (no home offset)";
  // A fault shows as Alarm; Clear resets it and Servo on enables again.
  robot->injectFault(0x7500);
  x.cycle();
  x.cycle();
  EXPECT_EQ(x.in8(6), 1) << "alarm";
  EXPECT_EQ(stateOf(x.in16(0)), State::kFault);
  x.put8(7, 1);  // clear
  for (int i = 0; i < 5; ++i) x.cycle();
  EXPECT_EQ(x.in8(6), 0);
  EXPECT_EQ(stateOf(x.in16(0)), State::kOperationEnabled);
  x.put8(6, 0);  // servo off
  for (int i = 0; i < 3; ++i) x.cycle();
  EXPECT_EQ(stateOf(x.in16(0)), State::kSwitchOnDisabled);
  std::filesystem::remove_all(dir);
}

// ECS7211 default images: SM2 = 0x1600 + 0x1604 (17 bytes), SM3 = 0x1A00 + 0x1A04 (19 bytes).
std::int32_t moveAndStop(topology::Segment& seg, SimTime& now, double turns) {
  OpSlave op = bringToOp(seg, {{2, true, 17}, {3, false, 19}}, now);
  CyclicExchange x{seg, op.outBytes, op.inBytes, now};
  x.put8(12, 9);  // CSV
  x.cycle();
  x.put32(2, x.in32(2));
  EXPECT_TRUE(commandUntil(x, 0, 0x0006, 0, State::kReadyToSwitchOn));
  EXPECT_TRUE(commandUntil(x, 0, 0x000F, 0, State::kOperationEnabled));
  const double speed = 4.0 * kCpr;
  x.put32(6, static_cast<std::int32_t>(turns > 0 ? speed : -speed));
  for (int k = 0; k < static_cast<int>(std::abs(turns) / 4.0 * 1000); ++k) x.cycle();
  x.put32(6, 0);
  for (int k = 0; k < 100; ++k) x.cycle();
  EXPECT_TRUE(commandUntil(x, 0, 0x0000, 0, State::kSwitchOnDisabled));
  x.cycle();
  now = x.now;
  return x.in32(2);
}

TEST(DriveFrames, AbsolutePositionIsTheSameAfterAPowerCycleAndARestart) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("ecsim-power-cycle-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  slavesim::EsiSlaveOptions options;
  options.stateFile = dir / "axis.state";
  std::int32_t before = 0;
  SimTime now = 0;
  {
    topology::Segment seg;
    seg.addSlave(makeExampleSlave(kEcs7211, options));
    before = moveAndStop(seg, now, 7.3);
    EXPECT_NEAR(before, 7.3 * kCpr, 0.05 * kCpr);

    // Power cycle: the ESC back to its reset values, the dictionary to its defaults, the
    // device model re-created (it reads the state file the old one wrote).
    slavesim::Slave& slave = seg.slave(0);
    slave.esc().powerOnReset();
    auto* pd = slavesim::processDataDeviceOf(slave);
    ASSERT_NE(pd, nullptr);
    pd->dictionary().resetToDefaults();
    dev::DeviceModelOptions modelOptions;
    modelOptions.stateFile = options.stateFile;
    ASSERT_TRUE(dev::attachDeviceModel(*pd, dev::DeviceModelKind::kRobotDrive, modelOptions).ok());
    EXPECT_EQ(slave.state(), AlState::kInit);
    std::int32_t absolute = 0;
    bringToOp(seg, {{2, true, 17}, {3, false, 19}}, now,
              [&](MailboxMaster& m) { absolute = m.uploadValue<std::int32_t>(0x2010, 0); });
    EXPECT_EQ(absolute, before) << "0x2010 after the power cycle";
    // And it keeps working: a move back.
    const std::int32_t after = moveAndStop(seg, now, -3.0);
    EXPECT_NEAR(after - before, -3.0 * kCpr, 0.05 * kCpr);
    before = after;
  }  // the simulator "exits": the drive writes its state file
  // A new process: a new slave from the ESI with the same state file.
  topology::Segment seg;
  seg.addSlave(makeExampleSlave(kEcs7211, options));
  std::int32_t absolute = 0;
  std::int32_t position = 0;
  bringToOp(seg, {{2, true, 17}, {3, false, 19}}, 0, [&](MailboxMaster& m) {
    absolute = m.uploadValue<std::int32_t>(0x2010, 0);
    position = m.uploadValue<std::int32_t>(0x6064, 0);
  });
  EXPECT_EQ(absolute, before) << "0x2010 after a restart";
  EXPECT_EQ(position, before) << "0x6064 (no home offset)";
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace ecsim::testing
