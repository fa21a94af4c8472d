// Encoders: resolution, single-turn and multi-turn wrap-around, incremental zero at switch-on,
// quantisation, seeded noise; the device state file; and a drive whose absolute position
// survives being destroyed and re-created from its state file while an incremental one
// restarts from zero.
#include "slavesim/devices/encoder.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <vector>

#include "slavesim/devices/device_state.hpp"
#include "tests/slavesim/drive_test_support.hpp"
#include "tests/slavesim/temp_dir.hpp"

namespace ecsim::testing {
namespace {

constexpr double kTurn = 2.0 * std::numbers::pi;

dev::EncoderParams params(dev::EncoderKind kind, std::uint32_t cpr = 1000, unsigned turnBits = 4) {
  dev::EncoderParams p;
  p.kind = kind;
  p.countsPerRevolution = cpr;
  p.multiTurnBits = turnBits;
  return p;
}

TEST(Encoder, ResolutionAndFloorQuantisation) {
  dev::Encoder e(params(dev::EncoderKind::kAbsoluteMultiTurn, 131072, 15));
  e.powerOn(0.0);
  EXPECT_EQ(e.read(kTurn).counts, 131072);
  EXPECT_EQ(e.read(0.5 * kTurn).counts, 65536);
  EXPECT_EQ(e.read(kTurn * 10.0 / 131072.0 + 1e-12).counts, 10);
  EXPECT_EQ(e.read(kTurn * 9.999 / 131072.0).counts, 9) << "a count is reached, not rounded to";
  EXPECT_EQ(e.read(-kTurn * 0.5 / 131072.0).counts, -1) << "floor below zero too";
  EXPECT_NEAR(e.angleOf(65536.0), 0.5 * kTurn, 1e-12);
}

TEST(Encoder, SingleTurnWrapsEveryRevolution) {
  dev::Encoder e(params(dev::EncoderKind::kAbsoluteSingleTurn));
  e.powerOn(0.0);
  const std::pair<double, std::int64_t> cases[] = {{0.25, 250},  {1.0, 0},  {2.25, 250},
                                                   {-0.25, 750}, {-1.0, 0}, {-3.9, 100}};
  for (const auto& [turns, reported] : cases) {
    const auto r = e.read(turns * kTurn + 1e-9);
    EXPECT_EQ(r.reported, reported) << turns << " turns";
    EXPECT_EQ(r.singleTurn, static_cast<std::uint32_t>(reported)) << turns << " turns";
  }
}

TEST(Encoder, MultiTurnCountsTurnsInASignedRangeAndWraps) {
  dev::Encoder e(params(dev::EncoderKind::kAbsoluteMultiTurn, 1000, 4));  // turns -8 ... 7
  e.powerOn(0.0);
  const std::tuple<double, std::int64_t, std::int64_t> cases[] = {
      {7.5, 7500, 7},     // top of the range
      {8.0, -8000, -8},   // one more turn wraps to the bottom
      {8.5, -7500, -8},   //
      {-8.0, -8000, -8},  // bottom
      {-8.5, 7500, 7},    // one turn below wraps to the top
      {16.25, 250, 0},    // a whole range further: back where it was
      {-2.75, -2750, -3},
  };
  for (const auto& [turns, reported, turnCount] : cases) {
    const auto r = e.read(turns * kTurn + 1e-9);
    EXPECT_EQ(r.reported, reported) << turns << " turns";
    EXPECT_EQ(r.turns, turnCount) << turns << " turns";
    EXPECT_EQ(r.counts, static_cast<std::int64_t>(std::floor(turns * 1000 + 1e-6)))
        << "the continuous count does not wrap";
  }
}

TEST(Encoder, DefaultMultiTurnFillsTheWhole32BitRange) {
  dev::Encoder e(dev::EncoderParams{});  // 17 + 15 bits
  e.powerOn(0.0);
  const double top = 16384.0 * kTurn;  // 2^14 turns = 2^31 counts
  EXPECT_EQ(e.read(top - 1.5 * kTurn / 131072).reported, 2147483646);
  EXPECT_EQ(e.read(top + 0.5 * kTurn / 131072).reported, -2147483648LL);
}

TEST(Encoder, IncrementalStartsFromZeroAtEachSwitchOn) {
  dev::Encoder e(params(dev::EncoderKind::kIncremental));
  e.powerOn(3.3 * kTurn);
  EXPECT_EQ(e.read(3.3 * kTurn).counts, 0);
  EXPECT_EQ(e.read(4.3 * kTurn + 1e-9).reported, 1000);
  EXPECT_EQ(e.read(1.3 * kTurn + 1e-9).reported, -2000) << "no wrap of its own";
  e.powerOn(4.3 * kTurn);
  EXPECT_EQ(e.read(4.3 * kTurn + 1e-9).reported, 0) << "the position is lost at switch-off";
  EXPECT_FALSE(e.absolute());
}

TEST(Encoder, QuantisationStep) {
  dev::EncoderParams p = params(dev::EncoderKind::kAbsoluteMultiTurn, 4096, 8);
  p.quantisationStep = 16;  // a 256-line disc reported in 4096 counts
  dev::Encoder e(p);
  e.powerOn(0.0);
  for (int c = -100; c < 100; ++c) {
    const auto r = e.read((c + 0.5) / 4096.0 * kTurn);
    EXPECT_EQ(r.counts % 16, 0);
    EXPECT_EQ(r.counts, static_cast<std::int64_t>(std::floor((c + 0.5) / 16.0)) * 16) << c;
  }
}

TEST(Encoder, FaultFreezesTheReadingUntilCleared) {
  dev::Encoder e(params(dev::EncoderKind::kAbsoluteMultiTurn, 1000, 4));
  e.powerOn(0.0);
  EXPECT_EQ(e.read(2.5005 * kTurn).counts, 2500);
  e.setFault(true);
  EXPECT_TRUE(e.faulted());
  const auto frozen = e.read(3.7505 * kTurn);
  EXPECT_EQ(frozen.counts, 2500) << "the last good reading";
  EXPECT_EQ(frozen.reported, 2500);
  e.setFault(false);
  EXPECT_EQ(e.read(3.7505 * kTurn).counts, 3750);
}

TEST(Encoder, SeededNoiseIsReproducibleAndHasItsStandardDeviation) {
  dev::EncoderParams p = params(dev::EncoderKind::kAbsoluteMultiTurn, 131072, 15);
  p.noiseCounts = 4.0;
  p.seed = 42;
  dev::Encoder a(p), b(p);
  p.seed = 43;
  dev::Encoder c(p);
  const double angle = 1000.5 / 131072.0 * kTurn;
  double sum = 0.0, squares = 0.0;
  int differ = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const auto ra = a.read(angle);
    ASSERT_EQ(ra.counts, b.read(angle).counts) << "same seed, same sequence";
    differ += ra.counts != c.read(angle).counts ? 1 : 0;
    const double x = static_cast<double>(ra.counts) + 0.5 - 1000.5;  // floor takes 0.5 on average
    sum += x;
    squares += x * x;
  }
  EXPECT_GT(differ, n / 2) << "another seed, another sequence";
  const double mean = sum / n;
  const double sigma = std::sqrt(squares / n - mean * mean);
  EXPECT_NEAR(mean, 0.0, 0.1);
  // Quantisation adds 1/12 count^2 of variance to the noise's 16.
  EXPECT_NEAR(sigma, std::sqrt(16.0 + 1.0 / 12.0), 0.1);
}

// ---- state file ---------------------------------------------------------------------------------

using DeviceStateFile = TempDir;

TEST_F(DeviceStateFile, RoundTripsTheAngleBitForBit) {
  const auto path = dir_ / "axis.state";
  for (double angle : {0.0, 123.45678901234567, -98765.4321, 1e-300, 6.02e23}) {
    ASSERT_TRUE(dev::saveDeviceState(path, {angle}).ok());
    auto loaded = dev::loadDeviceState(path);
    ASSERT_TRUE(loaded.ok()) << loaded.error().message();
    EXPECT_EQ(loaded->shaftAngle, angle);
  }
  EXPECT_FALSE(std::filesystem::exists(dir_ / "axis.state.tmp")) << "renamed into place";
}

TEST_F(DeviceStateFile, ErrorsNameTheFileAndLine) {
  auto missing = dev::loadDeviceState(dir_ / "none.state");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().code, ErrorCode::kNotFound);
  const auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return dev::loadDeviceState(dir_ / name);
  };
  auto wrongFile = write("a.state", "# hello\nsomething else\n");
  ASSERT_FALSE(wrongFile.ok());
  EXPECT_EQ(wrongFile.error().code, ErrorCode::kParse);
  EXPECT_NE(wrongFile.error().context.find("a.state:2"), std::string::npos)
      << wrongFile.error().context;
  auto version = write("b.state", "ecsim-device-state 7\nshaft-angle-rad 1\n");
  ASSERT_FALSE(version.ok());
  EXPECT_NE(version.error().context.find("version"), std::string::npos);
  auto badNumber = write("c.state", "ecsim-device-state 1\nshaft-angle-rad 1.5x\n");
  ASSERT_FALSE(badNumber.ok());
  EXPECT_NE(badNumber.error().context.find("c.state:2"), std::string::npos);
  auto noAngle = write("d.state", "ecsim-device-state 1\nfuture-key 3\n");
  ASSERT_FALSE(noAngle.ok());
  auto fine = write("e.state", "ecsim-device-state 1\r\nfuture-key 3\r\nshaft-angle-rad -2.5\r\n");
  ASSERT_TRUE(fine.ok()) << fine.error().message();
  EXPECT_EQ(fine->shaftAngle, -2.5);
}

// ---- a drive across re-creation ---------------------------------------------------------------

using DrivePersistence = TempDir;

// Moves the bench's drive by `turns` in CSV and stops it.
void moveTurns(DriveBench& b, double turns) {
  b.mode(9);
  b.tick();
  b.enable();
  b.set<std::int32_t>(c402::obj::kTargetVelocity, 0, turns > 0 ? 524288 : -524288);  // 4 rev/s
  b.run(static_cast<SimTime>(std::abs(turns) / 4.0 * kNsPerSecond));
  b.set<std::int32_t>(c402::obj::kTargetVelocity, 0, 0);
  b.run(100 * kNsPerMs);
  b.controlword(0x0000);  // disable voltage: the power stage goes off
  b.run(10 * kNsPerMs);
}

TEST_F(DrivePersistence, AbsolutePositionSurvivesRecreationFromTheStateFile) {
  dev::DriveParams p = benchParams();
  p.stateFile = dir_ / "drive.state";
  std::int32_t before = 0;
  {
    DriveBench b(p);
    moveTurns(b, 5.3);
    before = b.position();
    EXPECT_NEAR(before, 5.3 * 131072, 0.2 * 131072);
  }  // the drive is destroyed: it writes the state file
  ASSERT_TRUE(std::filesystem::exists(p.stateFile));
  DriveBench again(p);
  EXPECT_EQ(again.position(), before) << "same count before any step";
  again.run(5 * kNsPerMs);
  EXPECT_EQ(again.position(), before);
}

TEST_F(DrivePersistence, IncrementalEncoderRestartsFromZero) {
  dev::DriveParams p = benchParams();
  p.stateFile = dir_ / "drive.state";
  p.encoder.kind = dev::EncoderKind::kIncremental;
  {
    DriveBench b(p);
    moveTurns(b, -2.0);
    EXPECT_NEAR(b.position(), -2.0 * 131072, 0.2 * 131072);
  }
  DriveBench again(p);
  EXPECT_EQ(again.position(), 0) << "the shaft is where it was, the count is not";
  auto state = dev::loadDeviceState(p.stateFile);
  ASSERT_TRUE(state.ok());
  EXPECT_NEAR(state->shaftAngle, -2.0 * kTurn, 0.2 * kTurn) << "the mechanics were kept";
}

TEST_F(DrivePersistence, UnreadableStateFileRefusesTheDrive) {
  dev::DriveParams p = benchParams();
  p.stateFile = dir_ / "broken.state";
  std::ofstream(p.stateFile) << "not a state file\n";
  slavesim::EsiSlaveOptions options;
  options.deviceModels = false;
  auto slave = makeExampleSlave(kEcs7201, options);
  ASSERT_NE(slave, nullptr);
  auto drive = dev::Cia402Drive::create(*slavesim::objectDictionaryOf(*slave), p);
  ASSERT_FALSE(drive.ok());
  EXPECT_NE(drive.error().context.find("broken.state:1"), std::string::npos)
      << drive.error().context;
}

}  // namespace
}  // namespace ecsim::testing
