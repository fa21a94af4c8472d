// Networks of drives with our master, in-process on virtual time and through frames only:
// the 6-axis robot of examples/topologies/robot6.xml reaches OP and reports its absolute
// positions over SDO; the drives of the demo network are enabled by the CiA 402 sequence,
// follow a CSP ramp with the tracking error the drive model itself predicts, and report a
// following error over 0x603F and an emergency the master receives.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "slavesim/devices/device_models.hpp"
#include "tests/slavesim/drive_master_support.hpp"
#include "tests/slavesim/drive_test_support.hpp"

namespace ecsim::testing {
namespace {

std::filesystem::path topologyPath(const char* name) {
  return std::filesystem::path(ECSIM_SOURCE_DIR) / "examples" / "topologies" / name;
}

constexpr std::size_t kDrive1 = 4;  // bus positions in the demo network
constexpr std::size_t kDrive2 = 5;

TEST(DriveNetwork, Robot6ReachesOpAndReportsAbsolutePositions) {
  TopologyMaster net(topologyPath("robot6.xml"));
  ASSERT_TRUE(net.ready());
  dev::Cia402Drive* j3 = dev::driveOf(net.segment().slave(3));
  ASSERT_NE(j3, nullptr);
  ASSERT_NE(dev::robotDriveOf(net.segment().slave(3)), nullptr);
  EXPECT_DOUBLE_EQ(j3->params().motor.inertia, 6.0e-4) << "<Param> of robot6.xml";
  // Joint 4 (no gravity on it) is turned by hand while the network starts.
  dev::Cia402Drive* j4 = dev::driveOf(net.segment().slave(4));
  ASSERT_NE(j4, nullptr);
  j4->axis().motor().setAngle(-2.25 * 2.0 * std::numbers::pi);
  master::Master& m = net.master();
  ASSERT_TRUE(m.start().ok());
  ASSERT_EQ(m.slaves().size(), 7u);
  for (const auto& s : m.slaves()) {
    ASSERT_TRUE(s.state().has_value());
    EXPECT_EQ(*s.state(), AlState::kOp) << s.position;
  }
  for (int c = 0; c < 100; ++c) EXPECT_TRUE(net.cycle().ok()) << c;
  EXPECT_EQ(m.statistics().wkcErrors, 0u);
  // LinuxCNC-style start-up: the absolute position of every joint by SDO (0x2010, latched
  // when the drive powered up) and the present one (0x6064).
  for (std::size_t j = 1; j <= 6; ++j) {
    auto raw = m.sdoUpload(j, 0x2010, 0);
    ASSERT_TRUE(raw.ok()) << j << ": " << raw.error().message();
    ASSERT_EQ(raw->size(), 4u);
    EXPECT_EQ(static_cast<std::int32_t>(readLe32(*raw, 0)), 0) << "joint " << j;
  }
  auto moved = m.sdoUpload(4, c402::obj::kPositionActualValue, 0);
  ASSERT_TRUE(moved.ok());
  EXPECT_NEAR(static_cast<std::int32_t>(readLe32(*moved, 0)), -2 * 131072 - 131072 / 4, 1);
  auto cpr = m.sdoUpload(6, 0x2011, 0);
  ASSERT_TRUE(cpr.ok());
  EXPECT_EQ(readLe32(*cpr, 0), 1048576u) << "J6's encoder.resolution";
}

// The CSP ramp a master sends: `rate` counts per cycle for `cycles` cycles from `from`.
std::int32_t rampTarget(std::int32_t from, double rate, int cycle) {
  return from + static_cast<std::int32_t>(std::llround(rate * cycle));
}

// The tracking error of the same ramp on the drive model alone (no frames, no bus): the
// drive stepped once per millisecond with the target of each cycle. Returns the largest
// |target - actual| over the last half of the ramp.
double predictedTrackingError(double rate, int cycles) {
  DriveBench b{dev::DriveParams{}};  // the demo drives: default parameters
  b.tick();
  b.enable();
  b.mode(8);
  b.tick();
  const std::int32_t from = b.position();
  double worst = 0.0;
  for (int c = 1; c <= cycles; ++c) {
    const std::int32_t target = rampTarget(from, rate, c);
    b.set<std::int32_t>(c402::obj::kTargetPosition, 0, target);
    b.tick();
    if (c > cycles / 2) worst = std::max(worst, std::abs(double(target) - b.position()));
  }
  return worst;
}

TEST(DriveNetwork, DemoDrivesEnableByCia402AndFollowACspRampAsTheModelPredicts) {
  TopologyMaster net(topologyPath("demo.xml"));
  ASSERT_TRUE(net.ready());
  master::Master& m = net.master();
  ASSERT_TRUE(m.start().ok());
  Cia402Axis axes[] = {Cia402Axis(m, kDrive1), Cia402Axis(m, kDrive2)};
  for (auto& a : axes) {
    ASSERT_TRUE(a.ok());
    a.setMode(8);  // CSP
  }
  int cycles = 0;
  while (!(axes[0].operationEnabled() && axes[1].operationEnabled()) && cycles < 50) {
    for (auto& a : axes) a.stepEnable();
    ASSERT_TRUE(net.cycle().ok());
    ++cycles;
  }
  for (auto& a : axes) {
    EXPECT_EQ(a.statusword() & 0x6F, 0x27) << std::hex << a.statusword();
    EXPECT_EQ(a.statusword() & 0xFF, 0x37) << "0x..37 operation enabled, voltage enabled";
  }
  EXPECT_LE(cycles, 6) << "shutdown, switch on, enable operation";
  const double rate = 131.072 * 2;  // 2 rev/s at 1 ms
  const int rampCycles = 1000;
  const double predicted = predictedTrackingError(rate, rampCycles);
  const std::int32_t from[] = {axes[0].actual(), axes[1].actual()};
  double worst[] = {0.0, 0.0};
  for (int c = 1; c <= rampCycles; ++c) {
    for (int a = 0; a < 2; ++a) axes[a].setTarget(rampTarget(from[a], rate, c));
    ASSERT_TRUE(net.cycle().ok()) << c;
    // The inputs of this cycle show the drive as the target of this cycle reached it.
    if (c > rampCycles / 2) {
      for (int a = 0; a < 2; ++a) {
        worst[a] =
            std::max(worst[a], std::abs(double(rampTarget(from[a], rate, c)) - axes[a].actual()));
      }
    }
  }
  EXPECT_EQ(m.statistics().wkcErrors, 0u);
  for (int a = 0; a < 2; ++a) {
    EXPECT_NEAR(axes[a].actual() - from[a], rate * rampCycles, 3 * rate) << a;
    // Over frames the inputs that come back with target c were latched before that target
    // arrived (outputs and inputs share the LRW): one cycle of motion more than the model's
    // own error, which is measured after the step that took the target.
    const double expected = predicted + rate;
    EXPECT_GT(predicted, 0.0);
    EXPECT_NEAR(worst[a], expected, 0.02 * expected)
        << "axis " << a << ", model predicts " << predicted << " + one cycle " << rate;
    std::printf("axis %d: worst tracking error %.1f counts, model + one cycle %.1f\n", a, worst[a],
                expected);
    EXPECT_FALSE(axes[a].fault());
  }
}

TEST(DriveNetwork, FollowingErrorIsReportedIn603FAndAsAnEmergency) {
  TopologyMaster net(topologyPath("demo.xml"));
  ASSERT_TRUE(net.ready());
  master::Master& m = net.master();
  ASSERT_TRUE(m.start().ok());
  // A following error window of 50 counts, 1 ms: a fast ramp leaves it.
  std::array<std::uint8_t, 4> window{};
  writeLe32(window, 0, 50);
  ASSERT_TRUE(m.sdoDownload(kDrive1, c402::obj::kFollowingErrorWindow, 0, window).ok());
  std::array<std::uint8_t, 2> timeout{};
  writeLe16(timeout, 0, 1);
  ASSERT_TRUE(m.sdoDownload(kDrive1, c402::obj::kFollowingErrorTimeout, 0, timeout).ok());
  Cia402Axis axis(m, kDrive1);
  ASSERT_TRUE(axis.ok());
  axis.setMode(8);
  for (int c = 0; c < 10 && !axis.operationEnabled(); ++c) {
    axis.stepEnable();
    ASSERT_TRUE(net.cycle().ok());
  }
  ASSERT_TRUE(axis.operationEnabled()) << std::hex << axis.statusword();
  const std::int32_t from = axis.actual();
  int c = 1;
  for (; c <= 200 && !axis.fault(); ++c) {
    axis.setTarget(rampTarget(from, 131.072 * 20, c));  // 20 rev/s out of nothing
    ASSERT_TRUE(net.cycle().ok());
  }
  ASSERT_TRUE(axis.fault()) << "no fault after " << c << " cycles";
  auto code = m.sdoUpload(kDrive1, c402::obj::kErrorCode, 0);
  ASSERT_TRUE(code.ok()) << code.error().message();
  EXPECT_EQ(readLe16(*code, 0), 0x8611);
  bool found = false;
  for (const auto& e : m.emergencies()) {
    if (e.position == kDrive1 && e.emergency.errorCode == 0x8611) {
      found = true;
      EXPECT_EQ(e.emergency.errorRegister, 0x21);
    }
  }
  EXPECT_TRUE(found) << m.emergencies().size() << " emergencies received";
}

}  // namespace
}  // namespace ecsim::testing
