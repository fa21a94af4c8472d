// <Param name="drive.mode">: the mode of operation 0x6060 a drive starts in must be one of the
// CiA 402 modes of operation (IEC 61800-7-201 / CiA 402 object 0x6060: 1 PP, 2 VL, 3 PV, 4 TQ,
// 6 HM, 7 IP, 8 CSP, 9 CSV, 10 CST; negative values manufacturer-specific) that ecsim's drive
// models (PP, PV, HM, CSP, CSV, CST), or 0 (no mode); and one the device's supported drive
// modes 0x6502 lists (bit 0 PP, 2 PV, 5 HM, 7 CSP, 8 CSV, 9 CST; a 0x6502 of 0 lists all).
// Anything else is an error naming the topology file and the <Param>'s line, with the modes
// allowed.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "slavesim/devices/device_models.hpp"
#include "tests/slavesim/esi_variant.hpp"
#include "tests/slavesim/one_slave_topology.hpp"

namespace ecsim::testing {
namespace {

constexpr const char* kAllModelled =
    "allowed: 0 (no mode), 1 (PP), 3 (PV), 6 (HM), 8 (CSP), 9 (CSV), 10 (CST)";

struct ModeCase {
  const char* value;
  std::uint32_t supported;  // 0x6502 of the device (0x3A5: the ECS7201's)
  const char* error;        // nullptr: accepted, the drive starts in the mode
};

void PrintTo(const ModeCase& c, std::ostream* os) {
  *os << "drive.mode=" << c.value << " 0x6502=0x" << std::hex << c.supported;
}

const ModeCase kCases[] = {
    {"8", 0x3A5, nullptr},
    {"1", 0x3A5, nullptr},
    {"10", 0x3A5, nullptr},
    {"0", 0x3A5, nullptr},  // no mode: the master chooses one
    {"2", 0x3A5, kAllModelled},    // VL: a CiA 402 mode ecsim does not model
    {"4", 0x3A5, kAllModelled},    // TQ
    {"7", 0x3A5, kAllModelled},    // IP
    {"5", 0x3A5, kAllModelled},    // reserved
    {"11", 0x3A5, kAllModelled},   // beyond the profile's modes
    {"-1", 0x3A5, kAllModelled},   // manufacturer-specific: nothing to model
    {"csp", 0x3A5, "not a number"},
    {"200", 0x3A5, "must be within"},
    // A device whose 0x6502 lists PP and CSP only (bits 0 and 7).
    {"8", 0x081, nullptr},
    {"0", 0x081, nullptr},
    {"9", 0x081, "0x6502 = 0x00000081 do not list it; allowed: 0 (no mode), 1 (PP), 8 (CSP)"},
    {"6", 0x081, "0x6502 = 0x00000081 do not list it; allowed: 0 (no mode), 1 (PP), 8 (CSP)"},
    // 0x6502 = 0 (SOES placeholder): every modelled mode.
    {"9", 0x000, nullptr},
};

class DriveModeParam : public OneSlaveTopology, public ::testing::WithParamInterface<ModeCase> {
 protected:
  // examples/esi/ecsim_devices.xml with the ECS7201's 0x6502 default replaced, in dir_.
  std::filesystem::path esiWith(std::uint32_t supported) {
    char replacement[64];
    std::snprintf(replacement, sizeof replacement, "<DefaultValue>#x%08X</DefaultValue>",
                  supported);
    return writeEcs7201Variant(
        dir_ / "drives.xml",
        {"", "", {{"<DefaultValue>#x000003A5</DefaultValue>", replacement}}});
  }
};

TEST_P(DriveModeParam, IsACia402ModeTheDeviceSupports) {
  const ModeCase& c = GetParam();
  const auto path = dir_ / "net.xml";
  // Line 3 is the Param's (line 2 the Slave's).
  std::ofstream(path) << "<Topology name=\"t\">\n"
                      << "  <Slave name=\"Axis\" esi=\"" << esiWith(c.supported).string()
                      << "\" product=\"" << kEcs7201 << "\">\n"
                      << "    <Param name=\"drive.mode\" value=\"" << c.value << "\"/>\n"
                      << "  </Slave>\n</Topology>\n";
  auto net = build(path);
  if (c.error == nullptr) {
    ASSERT_TRUE(net.ok()) << net.error().message();
    dev::Cia402Drive* drive = dev::driveOf(net->segment->slave(0));
    ASSERT_NE(drive, nullptr);
    auto* od = slavesim::objectDictionaryOf(net->segment->slave(0));
    EXPECT_EQ(*od->get<std::int8_t>(c402::obj::kModesOfOperation, 0), std::stoi(c.value));
    net->segment->pollSlaves(kNsPerMs);
    EXPECT_EQ(drive->activeMode(), std::stoi(c.value)) << "the drive runs the mode";
    return;
  }
  ASSERT_FALSE(net.ok()) << "drive.mode=" << c.value << " accepted";
  const std::string m = net.error().message();
  RecordProperty("message", m);
  EXPECT_NE(m.find(path.string()), std::string::npos) << m;
  EXPECT_NE(m.find("line 3"), std::string::npos) << m;
  EXPECT_NE(m.find("drive.mode"), std::string::npos) << m;
  EXPECT_NE(m.find(c.error), std::string::npos) << m;
}

INSTANTIATE_TEST_SUITE_P(Table, DriveModeParam, ::testing::ValuesIn(kCases));

}  // namespace
}  // namespace ecsim::testing
