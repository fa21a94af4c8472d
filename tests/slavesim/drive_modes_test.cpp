// The drive's modes of operation through its dictionary (0x6060/0x6061 with 0x6502), each
// checked against what the profile and the model predict: CSP lag, CSV speed, CST torque and
// acceleration, PP trapezoid and set-point handshake, PV ramps, homing methods 37/35/19/20,
// software limits, speed and torque limits, the following-error fault and quick-stop ramps.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "tests/slavesim/drive_test_support.hpp"

namespace ecsim::testing {
namespace {

constexpr std::int8_t kPp = 1;
constexpr std::int8_t kPv = 3;
constexpr std::int8_t kHm = 6;
constexpr std::int8_t kCsp = 8;
constexpr std::int8_t kCsv = 9;
constexpr std::int8_t kCst = 10;
constexpr double kCpr = 131072.0;  // counts per revolution (0x2011 of the ECS7211)

using namespace c402::obj;
namespace sw = c402::sw;

// ---- CSP ----------------------------------------------------------------------------------------

struct CspCase {
  double feedForward;
  SimTime cycle;  // master cycle = interpolation period 0x60C2
};

class CspRamp : public ::testing::TestWithParam<CspCase> {};

TEST_P(CspRamp, FollowsWithThePredictedLag) {
  const CspCase c = GetParam();
  dev::DriveParams params = benchParams();
  params.gains = dev::ServoGains::tuned(params.motor);
  params.gains->velocityFeedForward = c.feedForward;
  DriveBench b(params);
  b.set<std::uint8_t>(kInterpolationTimePeriod, 1, static_cast<std::uint8_t>(c.cycle / kNsPerMs));
  b.set<std::int8_t>(kInterpolationTimePeriod, 2, -3);
  b.mode(kCsp);
  b.tick();
  b.enable();
  ASSERT_EQ(b.get<std::int8_t>(kModesOfOperationDisplay), kCsp);
  EXPECT_NE(b.statusword() & sw::kModeSpecific12, 0) << "drive follows the command value";
  const double v = kCpr;  // one revolution per second
  double target = b.position();
  const double start = target;
  for (int k = 0; k < static_cast<int>(500 * kNsPerMs / c.cycle); ++k) {
    target += v * static_cast<double>(c.cycle) / kNsPerSecond;
    b.set<std::int32_t>(kTargetPosition, 0, static_cast<std::int32_t>(std::lround(target)));
    b.run(c.cycle, c.cycle);
  }
  // Linear interpolation over one period delays the reference by that period; without speed
  // feed-forward the P position loop adds v / Kp (the PI speed loop leaves no speed error).
  const double kp = params.gains->positionKp;
  const double lag =
      v * static_cast<double>(c.cycle) / kNsPerSecond + (1.0 - c.feedForward) * v / kp;
  EXPECT_NEAR(target - b.position(), lag, 0.01 * lag + 2.0)
      << "travelled " << b.position() - start << " counts";
  EXPECT_NEAR(b.velocity(), v, 0.002 * v);
  EXPECT_NEAR(static_cast<double>(b.get<std::int32_t>(kFollowingErrorActualValue)),
              (1.0 - c.feedForward) * v / kp, 0.01 * lag + 2.0)
      << "0x60F4 is demand - actual";
}

INSTANTIATE_TEST_SUITE_P(FeedForwardAndPeriod, CspRamp,
                         ::testing::Values(CspCase{1.0, kNsPerMs}, CspCase{0.0, kNsPerMs},
                                           CspCase{1.0, 2 * kNsPerMs}, CspCase{0.5, 4 * kNsPerMs}),
                         [](const ::testing::TestParamInfo<CspCase>& param) {
                           return "ff" +
                                  std::to_string(static_cast<int>(param.param.feedForward * 100)) +
                                  "_" + std::to_string(param.param.cycle / kNsPerMs) + "ms";
                         });

TEST(DriveModes, CspTargetWrapsAroundThe32BitRange) {
  dev::DriveParams params = benchParams();
  // Start just below the top of the 32-bit range (multi-turn count 2^31 - 1000).
  params.initialShaftAngle = (2147483647.0 - 1000.0) / kCpr * 2.0 * std::numbers::pi;
  DriveBench b(params);
  b.mode(kCsp);
  b.tick();
  b.enable();
  std::int32_t target = b.position();
  for (int k = 0; k < 300; ++k) {
    target = static_cast<std::int32_t>(static_cast<std::uint32_t>(target) + 20u);  // wraps
    b.set<std::int32_t>(kTargetPosition, 0, target);
    b.tick();
  }
  b.run(100 * kNsPerMs);
  EXPECT_EQ(b.state(), State::kOperationEnabled) << "no following error across the wrap";
  EXPECT_LT(b.position(), -2147483647 + 5000 + 100) << "0x6064 wrapped to the bottom";
  EXPECT_NEAR(static_cast<double>(b.position()), static_cast<double>(target), 3.0);
}

// ---- CSV, CST ----------------------------------------------------------------------------------

TEST(DriveModes, CsvReachesTheTargetVelocityUnderTheSpeedLimit) {
  DriveBench b;
  b.mode(kCsv);
  b.tick();
  b.enable();
  b.set<std::int32_t>(kTargetVelocity, 0, -300000);
  b.run(200 * kNsPerMs);
  EXPECT_NEAR(b.velocity(), -300000, 300);
  EXPECT_NE(b.statusword() & sw::kModeSpecific12, 0);
  // 0x6080 = 100 rpm caps the speed at 100/60 rev/s.
  b.set<std::uint32_t>(kMaxMotorSpeed, 0, 100);
  b.set<std::int32_t>(kTargetVelocity, 0, 1'000'000);
  b.run(300 * kNsPerMs);
  EXPECT_NEAR(b.velocity(), 100.0 / 60.0 * kCpr, 300);
}

TEST(DriveModes, CstTorqueGivesTheModelsAccelerationAndObeysMaxTorque) {
  dev::DriveParams params = benchParams();
  params.motor.viscousFriction = 0.0;
  DriveBench b(params);
  b.mode(kCst);
  b.tick();
  b.enable();
  b.set<std::int16_t>(kTargetTorque, 0, 500);  // 50 % of rated torque
  b.tick();
  const double v0 = b.velocity();
  b.run(50 * kNsPerMs);
  EXPECT_NEAR(b.torque(), 500, 5);
  // J dw/dt = T: 50 ms at 0.5 * 1.27 N m over 2e-4 kg m^2, in counts/s.
  const double torque = 0.5 * params.motor.ratedTorque;
  const double expected = torque / params.motor.inertia * 0.05 / (2.0 * std::numbers::pi) * kCpr;
  EXPECT_NEAR(b.velocity() - v0, expected, 0.01 * expected);
  b.set<std::uint16_t>(kMaxTorque, 0, 200);
  b.run(5 * kNsPerMs);
  EXPECT_NEAR(b.torque(), 200, 3) << "0x6072 limits the torque";
}

// ---- PP -----------------------------------------------------------------------------------------

TEST(DriveModes, PpMovesOnTheTrapezoidWithTheSetPointHandshake) {
  DriveBench b;
  b.mode(kPp);
  b.tick();
  b.enable();
  EXPECT_NE(b.statusword() & sw::kTargetReached, 0) << "at rest: target reached";
  const double v = 655360, a = 6553600, distance = 1'000'000;  // 0x6081/0x6083/0x6084 defaults
  b.set<std::int32_t>(kTargetPosition, 0, static_cast<std::int32_t>(distance));
  b.controlword(0x001F);  // new set-point
  b.tick();
  EXPECT_NE(b.statusword() & sw::kModeSpecific12, 0) << "set-point acknowledged";
  EXPECT_EQ(b.statusword() & sw::kTargetReached, 0);
  b.controlword(0x000F);
  b.tick();
  EXPECT_EQ(b.statusword() & sw::kModeSpecific12, 0) << "ack follows bit 4 down";
  // Trapezoid: accelerate v/a, cruise, decelerate v/a: d/v + v/a in all.
  const double duration = distance / v + v / a;
  double peak = 0.0;
  SimTime reachedAt = 0;
  for (int k = 0; k < 2500 && reachedAt == 0; ++k) {
    b.tick();
    peak = std::max(peak, static_cast<double>(b.velocity()));
    if ((b.statusword() & sw::kTargetReached) != 0) reachedAt = b.now;
  }
  ASSERT_NE(reachedAt, 0);
  EXPECT_NEAR(static_cast<double>(reachedAt) / kNsPerSecond, duration + 0.002, 0.02);
  EXPECT_NEAR(peak, v, 0.02 * v) << "the actual speed overshoots the profile a little";
  b.run(50 * kNsPerMs);
  EXPECT_NEAR(b.position(), distance, 20);
  // Relative move of -250000 from the previous target.
  b.set<std::int32_t>(kTargetPosition, 0, -250000);
  b.controlword(0x005F);
  b.tick();
  b.controlword(0x004F);
  b.run(2 * kNsPerSecond);
  EXPECT_NEAR(b.position(), distance - 250000, 20);
}

TEST(DriveModes, PpBuffersOneSetPointOrChangesImmediately) {
  DriveBench b;
  b.mode(kPp);
  b.tick();
  b.enable();
  b.set<std::int32_t>(kTargetPosition, 0, 400000);
  b.controlword(0x001F);
  b.tick();
  b.controlword(0x000F);
  b.run(100 * kNsPerMs);
  // Second set-point while moving, not immediate: buffered, run after the first.
  b.set<std::int32_t>(kTargetPosition, 0, 100000);
  b.controlword(0x001F);
  b.tick();
  EXPECT_NE(b.statusword() & sw::kModeSpecific12, 0) << "buffer free: acknowledged";
  b.controlword(0x000F);
  double highest = 0.0;
  for (int k = 0; k < 2000; ++k) {
    b.tick();
    highest = std::max(highest, static_cast<double>(b.position()));
  }
  EXPECT_NEAR(highest, 400000, 200) << "the first target was reached before the buffered one";
  EXPECT_NEAR(b.position(), 100000, 20);
  // Change immediately (bit 5): the new target replaces the running one at once.
  b.set<std::int32_t>(kTargetPosition, 0, 900000);
  b.controlword(0x001F);
  b.tick();
  b.controlword(0x000F);
  b.run(100 * kNsPerMs);
  b.set<std::int32_t>(kTargetPosition, 0, 300000);
  b.controlword(0x003F);
  b.tick();
  b.controlword(0x000F);
  highest = 0.0;
  for (int k = 0; k < 2000; ++k) {
    b.tick();
    highest = std::max(highest, static_cast<double>(b.position()));
  }
  EXPECT_LT(highest, 500000) << "turned back before the replaced target";
  EXPECT_NEAR(b.position(), 300000, 20);
}

TEST(DriveModes, PpHaltStopsAndHolds) {
  DriveBench b;
  b.mode(kPp);
  b.tick();
  b.enable();
  b.set<std::int32_t>(kTargetPosition, 0, 2'000'000);
  b.controlword(0x001F);
  b.tick();
  b.controlword(0x010F);  // halt
  b.run(300 * kNsPerMs);
  EXPECT_LT(std::abs(b.velocity()), 500);
  EXPECT_NE(b.statusword() & sw::kTargetReached, 0) << "halted: target reached";
  const std::int32_t held = b.position();
  EXPECT_LT(held, 200000);
  b.run(100 * kNsPerMs);
  EXPECT_NEAR(b.position(), held, 5);
}

// ---- PV -----------------------------------------------------------------------------------------

TEST(DriveModes, PvRampsWithTheProfileAcceleration) {
  DriveBench b;
  b.mode(kPv);
  b.tick();
  b.enable();
  b.set<std::uint32_t>(kProfileAcceleration, 0, 1'000'000);
  b.set<std::uint32_t>(kProfileDeceleration, 0, 2'000'000);
  b.set<std::int32_t>(kTargetVelocity, 0, 200000);
  b.run(100 * kNsPerMs);
  EXPECT_NEAR(b.velocity(), 100000, 2000) << "half way up after 0.1 s at 1e6 counts/s^2";
  EXPECT_EQ(b.statusword() & sw::kTargetReached, 0);
  b.run(150 * kNsPerMs);
  EXPECT_NEAR(b.velocity(), 200000, 500);
  EXPECT_NE(b.statusword() & sw::kTargetReached, 0);
  EXPECT_EQ(b.statusword() & sw::kModeSpecific12, 0) << "not at speed zero";
  b.controlword(0x010F);  // halt: down at the deceleration
  b.run(50 * kNsPerMs);
  EXPECT_NEAR(b.velocity(), 100000, 2000);
  b.run(100 * kNsPerMs);
  EXPECT_NE(b.statusword() & sw::kModeSpecific12, 0) << "speed zero";
}

// ---- HM -----------------------------------------------------------------------------------------

class CurrentPositionHoming : public ::testing::TestWithParam<int> {};

TEST_P(CurrentPositionHoming, MakesThePresentPositionHome) {
  dev::DriveParams params = benchParams();
  params.initialShaftAngle = 3.25 * 2.0 * std::numbers::pi;
  DriveBench b(params);
  EXPECT_NEAR(b.position(), 3.25 * kCpr, 1);
  b.mode(kHm);
  b.set<std::int8_t>(kHomingMethod, 0, static_cast<std::int8_t>(GetParam()));
  b.tick();
  b.enable();
  EXPECT_EQ(b.statusword() & (sw::kTargetReached | sw::kModeSpecific12 | sw::kModeSpecific13),
            sw::kTargetReached)
      << "not started";
  b.controlword(0x001F);
  b.tick();
  EXPECT_NEAR(b.position(), 0, 1);
  EXPECT_EQ(b.statusword() & (sw::kTargetReached | sw::kModeSpecific12 | sw::kModeSpecific13),
            sw::kTargetReached | sw::kModeSpecific12)
      << "homing attained and target reached";
  b.run(50 * kNsPerMs);
  EXPECT_NEAR(b.position(), 0, 1) << "no motion";
}

INSTANTIATE_TEST_SUITE_P(Methods, CurrentPositionHoming, ::testing::Values(35, 37));

struct SwitchCase {
  int method;
  double startCounts;
};

class SwitchHoming : public ::testing::TestWithParam<SwitchCase> {};

TEST_P(SwitchHoming, FindsTheSwitchEdge) {
  const SwitchCase c = GetParam();
  dev::DriveParams params = benchParams();
  params.homeSwitchCounts = 50000.0;  // on above 50000 encoder counts
  params.initialShaftAngle = c.startCounts / kCpr * 2.0 * std::numbers::pi;
  DriveBench b(params);
  b.mode(kHm);
  b.set<std::int8_t>(kHomingMethod, 0, static_cast<std::int8_t>(c.method));
  b.set<std::uint32_t>(kHomingSpeeds, 1, 200000);
  b.set<std::uint32_t>(kHomingSpeeds, 2, 20000);
  b.tick();
  b.enable();
  b.controlword(0x001F);
  bool sawInProgress = false;
  SimTime doneAt = 0;
  for (int k = 0; k < 5000 && doneAt == 0; ++k) {
    b.tick();
    const std::uint16_t bits =
        b.statusword() & (sw::kTargetReached | sw::kModeSpecific12 | sw::kModeSpecific13);
    if (bits == 0) sawInProgress = true;
    if (bits == (sw::kTargetReached | sw::kModeSpecific12)) doneAt = b.now;
    ASSERT_EQ(bits & sw::kModeSpecific13, 0) << "homing error";
  }
  ASSERT_NE(doneAt, 0) << "homing did not complete";
  EXPECT_TRUE(sawInProgress);
  EXPECT_TRUE(b.drive->homingAttained());
  // Home is the switch edge: position 0 there, so position = encoder count - 50000 (within
  // what the slow speed covers in one 62.5 us substep).
  const double counts = b.drive->encoder().exactCounts(b.drive->axis().motor().angle());
  EXPECT_NEAR(counts - b.position(), 50000.0, 20000.0 * 62.5e-6 + 2.0);
}

INSTANTIATE_TEST_SUITE_P(Methods, SwitchHoming,
                         ::testing::Values(SwitchCase{19, 0.0}, SwitchCase{19, 90000.0},
                                           SwitchCase{20, 0.0}, SwitchCase{20, 90000.0}),
                         [](const ::testing::TestParamInfo<SwitchCase>& param) {
                           return "method" + std::to_string(param.param.method) + "_from" +
                                  std::to_string(static_cast<int>(param.param.startCounts));
                         });

TEST(DriveModes, UnsupportedHomingMethodReportsHomingError) {
  DriveBench b;
  b.mode(kHm);
  b.set<std::int8_t>(kHomingMethod, 0, 1);  // index pulse methods are not modelled
  b.tick();
  b.enable();
  b.controlword(0x001F);
  b.tick();
  EXPECT_NE(b.statusword() & sw::kModeSpecific13, 0);
  EXPECT_NE(b.statusword() & sw::kTargetReached, 0) << "error with speed zero";
  EXPECT_FALSE(b.drive->homingAttained());
}

// ---- modes, limits, monitoring --------------------------------------------------------------

TEST(DriveModes, OnlySupportedModesAreTaken) {
  DriveBench b;
  b.tick();
  EXPECT_EQ(b.get<std::int8_t>(kModesOfOperationDisplay), kCsp) << "0x6060 default 8";
  b.mode(kPv);
  b.tick();
  EXPECT_EQ(b.get<std::int8_t>(kModesOfOperationDisplay), kPv);
  for (int m : {2, 4, 7, -1, 0}) {  // VL, TQ, IP, manufacturer, none: not in 0x6502
    b.mode(static_cast<std::int8_t>(m));
    b.tick();
    EXPECT_EQ(b.get<std::int8_t>(kModesOfOperationDisplay), kPv) << int(m);
  }
}

TEST(DriveModes, SoftwareLimitsClampPositionAndStopVelocity) {
  DriveBench b;
  b.set<std::int32_t>(kSoftwarePositionLimit, 1, -100000);
  b.set<std::int32_t>(kSoftwarePositionLimit, 2, 200000);
  b.mode(kCsp);
  b.tick();
  b.enable();
  std::int32_t target = b.position();
  for (int k = 0; k < 600; ++k) {
    target += 1000;
    b.set<std::int32_t>(kTargetPosition, 0, target);
    b.tick();
  }
  b.run(100 * kNsPerMs);
  EXPECT_NEAR(b.position(), 200000, 5);
  EXPECT_NE(b.statusword() & sw::kInternalLimitActive, 0);
  EXPECT_EQ(b.state(), State::kOperationEnabled);
  // Velocity mode at the lower limit: inward is allowed, outward is not.
  b.mode(kCsv);
  b.set<std::int32_t>(kTargetVelocity, 0, -400000);
  b.run(1500 * kNsPerMs);
  EXPECT_LT(b.position(), -100000 + 1);
  EXPECT_GT(b.position(), -100000 - 5000) << "stopped near the limit";
  EXPECT_NE(b.statusword() & sw::kInternalLimitActive, 0);
  b.set<std::int32_t>(kTargetVelocity, 0, 100000);
  b.run(100 * kNsPerMs);
  EXPECT_NEAR(b.velocity(), 100000, 500);
  EXPECT_EQ(b.statusword() & sw::kInternalLimitActive, 0);
}

class FollowingError : public ::testing::TestWithParam<std::uint32_t> {};

TEST_P(FollowingError, FaultsWhenTheWindowIsExceededLongerThanTheTimeout) {
  const std::uint32_t window = GetParam();
  DriveBench b;
  b.set<std::uint32_t>(kFollowingErrorWindow, 0, window);
  b.set<std::uint16_t>(kFollowingErrorTimeout, 0, 10);  // ms
  b.mode(kCsp);
  b.tick();
  b.enable();
  b.set<std::uint16_t>(kMaxTorque, 0, 0);  // the motor cannot follow at all
  std::int32_t target = b.position();
  const SimTime enabledAt = b.now;
  SimTime beyondAt = 0;
  SimTime faultAt = 0;
  for (int k = 0; k < 1000 && faultAt == 0; ++k) {
    target += 100;  // 100 counts per ms
    b.set<std::int32_t>(kTargetPosition, 0, target);
    b.tick();
    const auto fe = b.get<std::int32_t>(kFollowingErrorActualValue);
    if (beyondAt == 0 && std::abs(fe) > static_cast<std::int64_t>(window)) beyondAt = b.now;
    if (beyondAt == 0) {
      EXPECT_EQ(b.statusword() & sw::kWarning, 0) << "within the window";
      EXPECT_EQ(b.state(), State::kOperationEnabled);
    }
    if (b.errorCode() != 0) faultAt = b.now;
  }
  ASSERT_NE(beyondAt, 0);
  ASSERT_NE(faultAt, 0);
  EXPECT_EQ(b.errorCode(), c402::kErrorFollowing);
  EXPECT_NEAR(static_cast<double>(faultAt - beyondAt), 10.0 * kNsPerMs, 1.0 * kNsPerMs);
  EXPECT_NEAR(static_cast<double>(beyondAt - enabledAt) / kNsPerMs, window / 100.0 + 1.0, 1.0)
      << "the error grows 100 counts per ms, one interpolation period after the first target";
  b.run(10 * kNsPerMs);
  EXPECT_EQ(b.state(), State::kFault);
}

INSTANTIATE_TEST_SUITE_P(Windows, FollowingError, ::testing::Values(500u, 2000u, 10000u));

TEST(DriveModes, FollowingErrorMonitoringOffWithAllOnes) {
  DriveBench b;
  b.set<std::uint32_t>(kFollowingErrorWindow, 0, 0xFFFFFFFFu);
  b.mode(kCsp);
  b.tick();
  b.enable();
  b.set<std::uint16_t>(kMaxTorque, 0, 0);
  b.set<std::int32_t>(kTargetPosition, 0, b.position() + 50000);
  b.run(200 * kNsPerMs);
  EXPECT_EQ(b.state(), State::kOperationEnabled);
  EXPECT_EQ(b.errorCode(), 0);
}

struct QuickStopCase {
  std::int16_t option;
  double deceleration;  // counts/s^2 the stop should show; 0: at the torque limit
  State after;
};

class QuickStop : public ::testing::TestWithParam<QuickStopCase> {};

TEST_P(QuickStop, StopsOnTheRampTheOptionCodeNames) {
  const QuickStopCase c = GetParam();
  dev::DriveParams params = benchParams();
  params.quickStopDeceleration = 8.0e6;
  DriveBench b(params);
  b.set<std::int16_t>(kQuickStopOptionCode, 0, c.option);
  b.set<std::uint32_t>(kProfileDeceleration, 0, 4'000'000);
  b.mode(kCsv);
  b.tick();
  b.enable();
  const double v = 800000;
  b.set<std::int32_t>(kTargetVelocity, 0, static_cast<std::int32_t>(v));
  b.run(200 * kNsPerMs);
  b.controlword(0x0002);
  SimTime stoppedAt = 0;
  const SimTime start = b.now;
  double lowest = v;
  for (int k = 0; k < 4000 && stoppedAt == 0; ++k) {
    b.run(kNsPerMs / 4, kNsPerMs / 4);
    lowest = std::min(lowest, static_cast<double>(b.velocity()));
    if (std::abs(b.velocity()) < 2000) stoppedAt = b.now;
  }
  ASSERT_NE(stoppedAt, 0);
  const double seconds = static_cast<double>(stoppedAt - start) / kNsPerSecond;
  // Options 3/7 ramp at 90 % of what the torque limit (300 % of 1.27 N m) gives 2e-4 kg m^2.
  const double deceleration =
      c.deceleration > 0.0 ? c.deceleration : 0.9 * 3.81 / 2e-4 / (2.0 * std::numbers::pi) * kCpr;
  // The ramp eases off over its last milliseconds (a 1 ms exponential landing).
  EXPECT_NEAR(seconds, v / deceleration + 0.001, 0.1 * v / deceleration + 0.001);
  b.run(20 * kNsPerMs);
  EXPECT_EQ(b.state(), c.after);
  EXPECT_GT(lowest, -0.02 * v) << "stops without reversing";
}

INSTANTIATE_TEST_SUITE_P(Options, QuickStop,
                         ::testing::Values(QuickStopCase{1, 4.0e6, State::kSwitchOnDisabled},
                                           QuickStopCase{2, 8.0e6, State::kSwitchOnDisabled},
                                           QuickStopCase{3, 0.0, State::kSwitchOnDisabled},
                                           QuickStopCase{5, 4.0e6, State::kQuickStopActive},
                                           QuickStopCase{6, 8.0e6, State::kQuickStopActive},
                                           QuickStopCase{7, 0.0, State::kQuickStopActive}),
                         [](const ::testing::TestParamInfo<QuickStopCase>& param) {
                           return "option" + std::to_string(param.param.option);
                         });

}  // namespace
}  // namespace ecsim::testing
