// Digital inputs 0x60FD of a CiA 402 drive (IEC 61800-7-201 / CiA 402-2 object 0x60FD: bit 0
// negative limit switch, bit 1 positive limit switch, bit 2 home switch, bits 16-31
// manufacturer-specific): where the device's dictionary has the object, the drive shows its
// switches there, from the shaft position against the positions the topology's
// drive.homeSwitch / drive.negativeLimitSwitch / drive.positiveLimitSwitch give (encoder counts
// before the home offset). The ECS7201 has no 0x60FD: a test variant of its ESI adds it.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <numbers>

#include "slavesim/devices/device_models.hpp"
#include "tests/slavesim/esi_variant.hpp"
#include "tests/slavesim/one_slave_topology.hpp"

namespace ecsim::testing {
namespace {

constexpr double kCountsPerTurn = 131072.0;  // the default encoder

class DriveDigitalInputs : public OneSlaveTopology {
 protected:
  Result<topology::Network> buildWith(const std::string& params) {
    EsiVariant v;
    v.objects = varObject("#x60FD", "Digital inputs", "UDINT", 32, "ro", "T");
    const auto esi = writeEcs7201Variant(dir_ / "drives.xml", v);
    const auto path = dir_ / "net.xml";
    std::ofstream(path) << "<Topology name=\"t\">\n  <Slave name=\"Axis\" esi=\"" << esi.string()
                        << "\" product=\"" << kEcs7201 << "\">\n"
                        << params << "  </Slave>\n</Topology>\n";
    return build(path);
  }
};

TEST_F(DriveDigitalInputs, SwitchesFollowTheShaftPosition) {
  auto net = buildWith(
      "    <Param name=\"drive.negativeLimitSwitch\" value=\"-262144\"/>\n"
      "    <Param name=\"drive.positiveLimitSwitch\" value=\"262144\"/>\n"
      "    <Param name=\"drive.homeSwitch\" value=\"65536\"/>\n");
  ASSERT_TRUE(net.ok()) << net.error().message();
  slavesim::Slave& slave = net->segment->slave(0);
  dev::Cia402Drive* drive = dev::driveOf(slave);
  ASSERT_NE(drive, nullptr);
  auto* od = slavesim::objectDictionaryOf(slave);
  struct Row {
    double counts;
    std::uint32_t bits;  // 0x60FD
  };
  const Row rows[] = {
      {0, 0x0},                 // between the switches, below the home switch
      {65536, 0x4},             // home switch from 65536 on
      {200000, 0x4},
      {262144, 0x6},            // positive limit switch (and still the home switch)
      {400000, 0x6},
      {-262144, 0x1},           // negative limit switch
      {-1000000, 0x1},
      {-100, 0x0},
  };
  SimTime now = kNsPerMs;
  for (const Row& r : rows) {
    drive->axis().motor().setAngle(r.counts / kCountsPerTurn * 2.0 * std::numbers::pi);
    net->segment->pollSlaves(now);
    now += kNsPerMs;
    net->segment->pollSlaves(now);
    now += kNsPerMs;
    EXPECT_EQ(*od->get<std::uint32_t>(c402::obj::kDigitalInputs, 0), r.bits) << r.counts;
    EXPECT_EQ(drive->digitalInputs(), r.bits) << r.counts;
  }
}

TEST_F(DriveDigitalInputs, NoneRemovesTheHomeSwitch) {
  // By default the home switch is at 0 (DriveParams) and there are no limit switches; "none"
  // removes the home switch (homing methods 19 and 20 then end in a homing error).
  auto net = buildWith("    <Param name=\"drive.homeSwitch\" value=\"none\"/>\n");
  ASSERT_TRUE(net.ok()) << net.error().message();
  dev::Cia402Drive* drive = dev::driveOf(net->segment->slave(0));
  ASSERT_NE(drive, nullptr);
  drive->axis().motor().setAngle(5 * 2.0 * std::numbers::pi);
  net->segment->pollSlaves(kNsPerMs);
  net->segment->pollSlaves(2 * kNsPerMs);
  EXPECT_EQ(*slavesim::objectDictionaryOf(net->segment->slave(0))
                 ->get<std::uint32_t>(c402::obj::kDigitalInputs, 0),
            0u);
  EXPECT_FALSE(drive->params().homeSwitchCounts.has_value());
}

TEST_F(DriveDigitalInputs, CrossedLimitSwitchesAreAnErrorNamingTheLine) {
  auto net = buildWith(
      "    <Param name=\"drive.positiveLimitSwitch\" value=\"-5\"/>\n"
      "    <Param name=\"drive.negativeLimitSwitch\" value=\"10\"/>\n");
  ASSERT_FALSE(net.ok());
  const std::string m = net.error().message();
  EXPECT_NE(m.find("line 4"), std::string::npos) << m;
  EXPECT_NE(m.find("drive.negativeLimitSwitch"), std::string::npos) << m;
  auto bad = buildWith("    <Param name=\"drive.homeSwitch\" value=\"left\"/>\n");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message().find("line 3"), std::string::npos) << bad.error().message();
}

}  // namespace
}  // namespace ecsim::testing
