// Issue #17 item 3: an ENI as the whole machine. A network from an ENI of real vendor devices
// (../shared/esi, read in place) gives every device its automatic behaviour with no other file
// (drives, counter terminals: docs/devices.md); and a topology can reference the ENI
// (<Eni file= esiDir=>) and add only behaviour to the ENI's slaves by name, strictly
// (docs/topology.md).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "config/topology_file.hpp"
#include "slavesim/devices/device_models.hpp"
#include "support/test_network.hpp"
#include "topology/network_from_eni.hpp"

namespace ecsim::testing {
namespace {

namespace dev = slavesim::devices;

// A small vendor line: Beckhoff EK1100 coupler, EL5101 encoder terminal (2006 file), Ingenia
// EVS-NET-01 and STMBL drives; ENI slaves as TwinCAT exports them (Info: Name, PhysAddr,
// VendorId, ProductCode), in a line.
const char* const kMachineEni = R"(<?xml version="1.0"?>
<EtherCATConfig>
<Config>
<Slave><Info><Name>Coupler</Name><PhysAddr>1001</PhysAddr><VendorId>2</VendorId><ProductCode>#x044c2c52</ProductCode></Info></Slave>
<Slave><Info><Name>Enc</Name><PhysAddr>1002</PhysAddr><VendorId>2</VendorId><ProductCode>#x13ed3052</ProductCode></Info></Slave>
<Slave><Info><Name>Axis1</Name><PhysAddr>1003</PhysAddr><VendorId>#x0000029c</VendorId><ProductCode>61935618</ProductCode></Info></Slave>
<Slave><Info><Name>Axis2</Name><PhysAddr>1004</PhysAddr><VendorId>4919</VendorId><ProductCode>#x20192</ProductCode></Info></Slave>
</Config>
</EtherCATConfig>
)";

class EniMachine : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("ecsim-eni-machine-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
    std::ofstream(dir_ / "machine.xml") << kMachineEni;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  // A topology on the ENI, with `body` after the <Eni> line (line 3 on).
  std::filesystem::path topology(const std::string& body) {
    const auto path = dir_ / "net.xml";
    std::ofstream(path) << "<Topology name=\"machine\">\n  <Eni file=\"machine.xml\" esiDir=\""
                        << (sharedDir() / "esi").string() << "\"/>\n"
                        << body << "</Topology>\n";
    return path;
  }
  static std::string error(const Result<TopologyConfig>& r) {
    return r.ok() ? std::string("accepted") : r.error().message();
  }
  std::filesystem::path dir_;
};

TEST_F(EniMachine, EveryDeviceGetsItsAutomaticBehaviourFromTheEniAlone) {
  ECSIM_REQUIRE_SHARED(sharedDir() / "esi" / "ingenia_esi.xml");
  auto network = topology::buildNetworkFromEni(dir_ / "machine.xml", {sharedDir() / "esi"});
  ASSERT_TRUE(network.ok()) << network.error().message();
  topology::Segment& segment = *network->segment;
  ASSERT_EQ(segment.size(), 4u);
  EXPECT_EQ(dev::deviceModelOf(segment.slave(0)), nullptr) << "a coupler has no behaviour";
  EXPECT_NE(dev::encoderTerminalOf(segment.slave(1)), nullptr) << "EL5101: encoder profile";
  EXPECT_NE(dev::driveOf(segment.slave(2)), nullptr) << "Ingenia: CiA 402 drive";
  EXPECT_NE(dev::driveOf(segment.slave(3)), nullptr) << "STMBL: CiA 402 drive";
}

TEST_F(EniMachine, ATopologyOnTheEniAddsOnlyBehaviour) {
  ECSIM_REQUIRE_SHARED(sharedDir() / "esi" / "ingenia_esi.xml");
  auto config = loadTopologyFile(topology(
      "  <Master cable=\"2\"/>\n"
      "  <Slave name=\"Enc\">\n"
      "    <Param name=\"encoder.resolution\" value=\"1000\"/>\n"
      "    <Param name=\"signal.1\" value=\"step at=0 before=0 after=2\"/>\n"
      "  </Slave>\n"
      "  <Slave name=\"Axis2\" model=\"none\"/>\n"));
  ASSERT_TRUE(config.ok()) << config.error().message();
  ASSERT_EQ(config->slaves.size(), 4u);
  EXPECT_EQ(config->name, "machine");
  EXPECT_EQ(config->masterCableMetres, 2.0);
  EXPECT_EQ(config->links.size(), 3u) << "the ENI's line";
  EXPECT_EQ(config->findSlave("Axis1"), 2u);
  auto network = topology::buildNetwork(*config);
  ASSERT_TRUE(network.ok()) << network.error().message();
  topology::Segment& segment = *network->segment;
  dev::SsiEncoderTerminal* enc = dev::encoderTerminalOf(segment.slave(1));
  ASSERT_NE(enc, nullptr);
  EXPECT_EQ(enc->encoder(1).params().countsPerRevolution, 1000u) << "its Param";
  ASSERT_TRUE(enc->script(1).has_value()) << "its signal.1";
  EXPECT_EQ(enc->script(1)->value(kNsPerSecond), 2.0);
  EXPECT_NE(dev::driveOf(segment.slave(2)), nullptr) << "Axis1 keeps its automatic model";
  EXPECT_EQ(dev::deviceModelOf(segment.slave(3)), nullptr) << "Axis2: model=\"none\"";
}

// What the ENI reader ignores with a warning (here a cycle time out of range) reaches the
// network's warnings through the topology too, as through `ecsim serve ENI`.
TEST_F(EniMachine, TheEnisWarningsBecomeTheNetworks) {
  ECSIM_REQUIRE_SHARED(sharedDir() / "esi" / "ingenia_esi.xml");
  std::string text = kMachineEni;
  text.insert(text.find("</Config>"), "<Cyclic><CycleTime>5000000</CycleTime></Cyclic>\n");
  std::ofstream(dir_ / "machine.xml") << text;
  auto config = loadTopologyFile(topology(""));
  ASSERT_TRUE(config.ok()) << config.error().message();
  auto network = topology::buildNetwork(*config);
  ASSERT_TRUE(network.ok()) << network.error().message();
  ASSERT_FALSE(network->warnings.empty());
  EXPECT_NE(network->warnings[0].find("machine.xml, line 8: CycleTime 5000000 us"),
            std::string::npos)
      << network->warnings[0];
}

TEST_F(EniMachine, MistakesNameTheTopologyLineAndTheClosestName) {
  ECSIM_REQUIRE_SHARED(sharedDir() / "esi" / "ingenia_esi.xml");
  struct Case {
    std::string body;
    std::string expected;
  };
  const std::string file = (dir_ / "net.xml").string();
  const Case cases[] = {
      {"  <Slave name=\"Axsi1\" model=\"cia402\"/>\n",
       file + ", line 3: unknown slave 'Axsi1' in machine.xml; did you mean 'Axis1'?"},
      {"  <Slave name=\"Axis1\" esi=\"x.xml\"/>\n", file + ", line 3: unknown attribute 'esi'"},
      {"  <Slave name=\"Axis1\" model=\"cia40\"/>\n", "did you mean 'cia402'?"},
      {"  <Slave name=\"Enc\"/>\n  <Slave name=\"Enc\"/>\n",
       file + ", line 4: slave 'Enc' given twice (first on line 3)"},
      {"  <Link from=\"Coupler:1\" to=\"Enc:0\"/>\n", "takes its wiring from the ENI"},
  };
  for (const Case& c : cases) {
    const std::string text = error(loadTopologyFile(topology(c.body)));
    EXPECT_NE(text.find(c.expected), std::string::npos) << c.body << " -> " << text;
  }
  // The <Eni> element itself is strict too.
  const auto path = dir_ / "eni-attr.xml";
  std::ofstream(path) << "<Topology>\n  <Eni file=\"machine.xml\" esiDirs=\"esi\"/>\n</Topology>\n";
  const std::string text = error(loadTopologyFile(path));
  EXPECT_NE(text.find(path.string() + ", line 2: unknown attribute 'esiDirs'"), std::string::npos)
      << text;
  EXPECT_NE(text.find("did you mean 'esiDir'?"), std::string::npos) << text;
}

}  // namespace
}  // namespace ecsim::testing
