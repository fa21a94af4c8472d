// The CiA 402 factor group (IEC 61800-7-201 / CiA 402-2, objects 0x608F position encoder
// resolution, 0x6091 gear ratio, 0x6092 feed constant; the position factor of the older
// 0x6093 is "position encoder resolution * gear ratio / feed constant"):
//   position [increments] = position [user units] * (0x608F:01 / 0x608F:02)
//                           * (0x6091:01 / 0x6091:02) / (0x6092:01 / 0x6092:02)
// A drive whose ESI has these objects takes its target 0x607A and reports 0x6064 in user units;
// SDO writes of them take effect; with the defaults 1:1 a unit is one encoder increment.
// Our master (in process) brings an ECS7201 whose ESI has the factor group (a test variant of
// examples/esi/ecsim_devices.xml) to OP, enables it and moves it in CSP by user units.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "embed/testing/network_fixture.hpp"
#include "slavesim/devices/device_models.hpp"
#include "tests/slavesim/esi_variant.hpp"

namespace ecsim::testing {
namespace {

struct UnitsCase {
  const char* name;
  std::uint32_t encoder[2];  // 0x608F in the ESI: increments, motor revolutions
  std::uint32_t gear[2];     // 0x6091: motor revolutions, shaft revolutions
  std::uint32_t feed[2];     // 0x6092: feed, shaft revolutions
  bool bySdo;                // the ESI has 1:1 everywhere; the master writes the values in PREOP
  std::int32_t move;         // user units
  double motorTurns;         // the motor turns that move is
};
void PrintTo(const UnitsCase& c, std::ostream* os) { *os << c.name; }

const UnitsCase kCases[] = {
    // 360000 user units (e.g. 1/1000 degree) per turn of a 2^17-count encoder, no gear.
    {"FeedPerTurn", {131072, 1}, {1, 1}, {360000, 1}, false, 360000, 1.0},
    // The same written by SDO in PREOP over an ESI of 1:1 defaults.
    {"FeedPerTurnBySdo", {131072, 1}, {1, 1}, {360000, 1}, true, 360000, 1.0},
    // A 3:1 gear: 3 motor turns per turn of the driving shaft; 10 mm feed per shaft turn in um.
    {"GearAndFeed", {131072, 1}, {3, 1}, {10000, 1}, false, 10000, 3.0},
    // A 2^20 encoder in the ESI (the model's encoder takes that resolution) and a feed of 2^20
    // per turn: units of one increment, 2^20 of them a turn (8 turns were the encoder 2^17).
    {"EncoderIncrements", {1048576, 1}, {1, 1}, {1048576, 1}, false, 1048576, 1.0},
    // 0x608F alone, feed 1:1: the unit is one turn of the driving shaft.
    {"TurnsAsUnits", {131072, 1}, {1, 1}, {1, 1}, false, 2, 2.0},
    // Defaults everywhere: one unit = one encoder count (2^17 per turn), as without the objects.
    {"Defaults", {1, 1}, {1, 1}, {1, 1}, false, 131072, 1.0},
};

class DriveUnits : public NetworkFixture, public ::testing::WithParamInterface<UnitsCase> {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("ecsim-drive-units-" + std::to_string(::getpid()) + "-" + GetParam().name);
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    stopNetwork();
    std::filesystem::remove_all(dir_);
  }
  std::filesystem::path topology(const UnitsCase& c) {
    const bool esi = !c.bySdo;
    EsiVariant v;
    v.dataTypes = kRatioDataType;
    v.objects = ratioObject("#x608F", "Position encoder resolution", esi ? c.encoder[0] : 1,
                            esi ? c.encoder[1] : 1) +
                ratioObject("#x6091", "Gear ratio", esi ? c.gear[0] : 1, esi ? c.gear[1] : 1) +
                ratioObject("#x6092", "Feed constant", esi ? c.feed[0] : 1, esi ? c.feed[1] : 1);
    const auto esiPath = writeEcs7201Variant(dir_ / "drives.xml", v);
    const auto path = dir_ / "net.xml";
    std::ofstream(path) << "<Topology name=\"units\">\n  <Slave name=\"Axis\" esi=\""
                        << esiPath.string() << "\" product=\"" << kEcs7201
                        << "\"/>\n</Topology>\n";
    return path;
  }
  Status writeU32(std::uint16_t index, std::uint8_t sub, std::uint32_t value) {
    const std::uint8_t bytes[] = {static_cast<std::uint8_t>(value),
                                  static_cast<std::uint8_t>(value >> 8),
                                  static_cast<std::uint8_t>(value >> 16),
                                  static_cast<std::uint8_t>(value >> 24)};
    return master().sdoDownload(0, index, sub, bytes);
  }
  Status cycle() {
    ECSIM_TRY(master().exchange());
    return advance(kNsPerMs);
  }
  std::filesystem::path dir_;
};

TEST_P(DriveUnits, CspMovesInUserUnits) {
  const UnitsCase& c = GetParam();
  auto started = startInProcess(topology(c));
  ASSERT_TRUE(started.ok()) << started.error().message();
  dev::Cia402Drive* drive = dev::driveOf(network().segment().slave(0));
  ASSERT_NE(drive, nullptr);
  ASSERT_TRUE(master().scan().ok());
  ASSERT_TRUE(master().bringTo(AlState::kPreOp).ok());
  if (c.bySdo) {
    EXPECT_DOUBLE_EQ(drive->positionFactor(), 1.0) << "1:1 in the ESI";
    ASSERT_TRUE(writeU32(0x608F, 1, c.encoder[0]).ok());
    ASSERT_TRUE(writeU32(0x608F, 2, c.encoder[1]).ok());
    ASSERT_TRUE(writeU32(0x6091, 1, c.gear[0]).ok());
    ASSERT_TRUE(writeU32(0x6091, 2, c.gear[1]).ok());
    ASSERT_TRUE(writeU32(0x6092, 1, c.feed[0]).ok());
    ASSERT_TRUE(writeU32(0x6092, 2, c.feed[1]).ok());
  }
  auto op = master().bringTo(AlState::kOp);
  ASSERT_TRUE(op.ok()) << op.error().message();
  const double factor = static_cast<double>(c.encoder[0]) / c.encoder[1] * c.gear[0] / c.gear[1] /
                        (static_cast<double>(c.feed[0]) / c.feed[1]);
  EXPECT_DOUBLE_EQ(drive->positionFactor(), factor);

  auto controlword = master().variable("0.0x6040:00");
  auto statusword = master().variable("0.0x6041:00");
  auto target = master().variable("0.0x607A:00");
  auto actual = master().variable("0.0x6064:00");
  auto mode = master().variable("0.0x6060:00");
  ASSERT_TRUE(controlword.ok() && statusword.ok() && target.ok() && actual.ok() && mode.ok());
  mode->set<std::int8_t>(8);  // CSP
  for (int cw : {0x0006, 0x0007, 0x000F}) {
    controlword->set<std::uint16_t>(static_cast<std::uint16_t>(cw));
    for (int i = 0; i < 20; ++i) {
      target->set<std::int32_t>(actual->get<std::int32_t>());
      ASSERT_TRUE(cycle().ok());
    }
  }
  ASSERT_EQ(statusword->get<std::uint16_t>() & 0x6F, 0x27) << "Operation enabled";

  const std::int32_t start = actual->get<std::int32_t>();
  const double startAngle = drive->axis().motor().angle();
  constexpr int kRamp = 1000;
  for (int i = 1; i <= kRamp + 300; ++i) {
    const double s = std::min(1.0, static_cast<double>(i) / kRamp);
    target->set<std::int32_t>(start +
                              static_cast<std::int32_t>(std::lround(c.move * s * s * (3 - 2 * s))));
    ASSERT_TRUE(cycle().ok());
  }
  const double turns = (drive->axis().motor().angle() - startAngle) / (2.0 * std::numbers::pi);
  // Within a thousandth of a turn (the tuned loop settles well inside it at any resolution).
  constexpr double kTurnTolerance = 1e-3;
  EXPECT_NEAR(turns, c.motorTurns, kTurnTolerance) << c.name;
  EXPECT_NEAR(actual->get<std::int32_t>() - start, c.move, kTurnTolerance * c.move / c.motorTurns)
      << c.name;
  EXPECT_EQ(drive->errorCode(), 0);
}

INSTANTIATE_TEST_SUITE_P(FactorGroup, DriveUnits, ::testing::ValuesIn(kCases),
                         [](const auto& param) { return std::string(param.param.name); });

}  // namespace
}  // namespace ecsim::testing
