// Touch probe of a CiA 402 drive (ETG.6010 / IEC 61800-7-201 objects 0x60B8 function, 0x60B9
// status, 0x60BA/0x60BB probe 1 positive/negative edge position, 0x60BC/0x60BD probe 2), where
// the device's dictionary has them (a test variant of the ECS7201's ESI adds them):
//   0x60B8 per probe (probe 2 at bit 8): bit 0 enable, bit 1 continuous, bits 2-3 source (00
//   external input: probe 1's is the home switch; 01 encoder zero impulse, once per turn),
//   bit 4 / bit 5 sample the positive / negative edge
//   0x60B9 per probe: bit 0 enabled, bit 1 positive edge stored, bit 2 negative edge stored
// Table-driven: each row writes 0x60B8, turns the shaft to a position and checks 0x60B9 and
// the latched positions.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <numbers>

#include "slavesim/devices/device_models.hpp"
#include "tests/slavesim/esi_variant.hpp"
#include "tests/slavesim/one_slave_topology.hpp"

namespace ecsim::testing {
namespace {

constexpr std::int64_t kTurn = 131072;       // the default encoder's counts per turn
constexpr std::int64_t kHomeSwitch = 65536;  // drive.homeSwitch below

struct Step {
  std::uint16_t function;  // 0x60B8
  std::int64_t counts;     // shaft position to go to
  std::uint16_t status;    // 0x60B9 expected
  std::int32_t latched[4];  // 0x60BA-0x60BD expected
};

struct ProbeCase {
  const char* name;
  std::vector<Step> steps;
};
void PrintTo(const ProbeCase& c, std::ostream* os) { *os << c.name; }

const ProbeCase kCases[] = {
    {"HomeSwitchPositiveEdge",
     {{0x0011, 0, 0x0001, {0, 0, 0, 0}},
      {0x0011, 100000, 0x0003, {kHomeSwitch, 0, 0, 0}},
      {0x0011, 0, 0x0003, {kHomeSwitch, 0, 0, 0}}}},  // negative edge not sampled
    {"HomeSwitchBothEdges",
     {{0x0031, 0, 0x0001, {0, 0, 0, 0}},
      {0x0031, 100000, 0x0003, {kHomeSwitch, 0, 0, 0}},
      {0x0031, 1000, 0x0007, {kHomeSwitch, kHomeSwitch, 0, 0}}}},
    {"Probe2ZeroImpulse",
     {{0x1500, 1000, 0x0100, {0, 0, 0, 0}},
      {0x1500, kTurn + 1000, 0x0300, {0, 0, kTurn, 0}},
      {0x1500, 50000, 0x0300, {0, 0, kTurn, 0}}}},  // negative edge not sampled
    {"Probe2HasNoExternalInput",
     {{0x1100, 0, 0x0100, {0, 0, 0, 0}}, {0x1100, 100000, 0x0100, {0, 0, 0, 0}}}},
    {"FirstEventThenRearm",
     {{0x0015, 1000, 0x0001, {0, 0, 0, 0}},
      {0x0015, kTurn + 1000, 0x0003, {kTurn, 0, 0, 0}},
      {0x0015, 2 * kTurn + 1000, 0x0003, {kTurn, 0, 0, 0}},  // first event kept
      {0x0005, 2 * kTurn + 1000, 0x0001, {kTurn, 0, 0, 0}},  // sample bit off ...
      {0x0015, 3 * kTurn + 1000, 0x0003, {3 * kTurn, 0, 0, 0}}}},  // ... and on: re-armed
    {"Continuous",
     {{0x0017, 1000, 0x0001, {0, 0, 0, 0}},
      {0x0017, kTurn + 1000, 0x0003, {kTurn, 0, 0, 0}},
      {0x0017, 2 * kTurn + 1000, 0x0003, {2 * kTurn, 0, 0, 0}}}},
    {"DisabledStoresNothing",
     {{0x0000, 0, 0x0000, {0, 0, 0, 0}}, {0x0030, 100000, 0x0000, {0, 0, 0, 0}}}},
};

class DriveTouchProbe : public OneSlaveTopology, public ::testing::WithParamInterface<ProbeCase> {
};

TEST_P(DriveTouchProbe, LatchesThePositionAtTheEdges) {
  EsiVariant v;
  v.objects = varObject("#x60B8", "Touch probe function", "UINT", 16, "rw", "R") +
              varObject("#x60B9", "Touch probe status", "UINT", 16, "ro", "T") +
              varObject("#x60BA", "Touch probe 1 positive edge", "DINT", 32, "ro", "T") +
              varObject("#x60BB", "Touch probe 1 negative edge", "DINT", 32, "ro", "T") +
              varObject("#x60BC", "Touch probe 2 positive edge", "DINT", 32, "ro", "T") +
              varObject("#x60BD", "Touch probe 2 negative edge", "DINT", 32, "ro", "T");
  const auto esi = writeEcs7201Variant(dir_ / "drives.xml", v);
  const auto path = dir_ / "net.xml";
  std::ofstream(path) << "<Topology name=\"t\">\n  <Slave name=\"Axis\" esi=\"" << esi.string()
                      << "\" product=\"" << kEcs7201 << "\">\n"
                      << "    <Param name=\"drive.homeSwitch\" value=\"" << kHomeSwitch << "\"/>\n"
                      << "  </Slave>\n</Topology>\n";
  auto net = build(path);
  ASSERT_TRUE(net.ok()) << net.error().message();
  slavesim::Slave& slave = net->segment->slave(0);
  dev::Cia402Drive* drive = dev::driveOf(slave);
  ASSERT_NE(drive, nullptr);
  auto* od = slavesim::objectDictionaryOf(slave);
  SimTime now = kNsPerMs;
  unsigned row = 0;
  for (const Step& s : GetParam().steps) {
    ASSERT_TRUE(od->set<std::uint16_t>(0x60B8, 0, s.function).ok());
    net->segment->pollSlaves(now);  // the function is taken
    now += kNsPerMs;
    drive->axis().motor().setAngle(static_cast<double>(s.counts) / kTurn * 2.0 * std::numbers::pi);
    net->segment->pollSlaves(now);  // the shaft has moved
    now += kNsPerMs;
    EXPECT_EQ(*od->get<std::uint16_t>(0x60B9, 0), s.status) << "row " << row;
    for (unsigned i = 0; i < 4; ++i) {
      EXPECT_EQ(*od->get<std::int32_t>(static_cast<std::uint16_t>(0x60BA + i), 0), s.latched[i])
          << "row " << row << ", 0x60B" << static_cast<char>('A' + i);
    }
    ++row;
  }
}

INSTANTIATE_TEST_SUITE_P(Table, DriveTouchProbe, ::testing::ValuesIn(kCases),
                         [](const auto& param) { return std::string(param.param.name); });

}  // namespace
}  // namespace ecsim::testing
