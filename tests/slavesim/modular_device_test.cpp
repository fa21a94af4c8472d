// A modular device from real vendor files, end to end (issue #15 item 11): the Weidmueller
// u-remote coupler UR20-FBC-EC (Weidmueller_UR20_FBC.xml, <Slots> at line 3668) with two
// modules of Weidmueller_UR20_IO.xml chosen in the topology file (UR20-4DI-P, ModuleIdent
// #x00091F84, line 10; UR20-4DO-P, #x01012FA0, line 4810), served in-process; our master scans
// it without a configuration file, reads the PDO assignment over CoE, brings it to OP and
// exchanges process data that reaches the modules' moved objects (0x6000 in slot 0, 0x7010 in
// slot 1).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "config/topology_file.hpp"
#include "master/master.hpp"
#include "master/sim_network.hpp"
#include "slavesim/esi_slave.hpp"
#include "support/test_network.hpp"
#include "topology/network_builder.hpp"
#include "topology/network_from_eni.hpp"

namespace ecsim::testing {
namespace {

namespace fs = std::filesystem;

fs::path sharedEsi() {
  return fs::path(ECSIM_SHARED_DIR) / "esi";
}

// The real Weidmueller files live in ../shared; without them the test cannot run, and under
// CI=true that is a failure, not a skip.
#define ECSIM_REQUIRE_UR20()                                                             \
  do {                                                                                   \
    if (!fs::exists(sharedEsi() / "Weidmueller_UR20_FBC.xml")) {                         \
      if (ciMode()) FAIL() << "CI=true but no " << sharedEsi();                          \
      GTEST_SKIP() << "reference data not present: " << sharedEsi();                     \
    }                                                                                    \
  } while (false)

TEST(ModularDevice, Ur20WithModulesReachesOpAndExchangesProcessData) {
  ECSIM_REQUIRE_UR20();
  const fs::path dir = fs::temp_directory_path() / ("ecsim-modular-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path topologyFile = dir / "ur20.xml";
  std::ofstream(topologyFile) << "<Topology>\n"
                              << "  <Slave name=\"Station\" esi=\""
                              << (sharedEsi() / "Weidmueller_UR20_FBC.xml").string()
                              << "\" product=\"#x4F911C30\" revision=\"#x00000001\" modules=\""
                              << (sharedEsi() / "Weidmueller_UR20_IO.xml").string() << "\">\n"
                              << "    <Module type=\"UR20-4DI-P\"/>\n"
                              << "    <Module ident=\"#x01012FA0\"/>\n"
                              << "  </Slave>\n</Topology>\n";
  auto config = loadTopologyFile(topologyFile);
  fs::remove_all(dir);
  ASSERT_TRUE(config.ok()) << config.error().message();
  SimNetwork net;
  topology::SlaveFactory factory;
  auto station = factory.make(config->slaves.at(0));
  ASSERT_TRUE(station.ok()) << station.error().message();
  EXPECT_TRUE(factory.warnings().empty()) << factory.warnings().front();
  topology::Segment& segment = net.segment();
  segment.addSlave(std::move(station).value());
  auto* od = slavesim::objectDictionaryOf(segment.slave(0));
  ASSERT_NE(od, nullptr);
  EXPECT_EQ(od->get<std::uint8_t>(0xF050, 0).value(), 2);
  EXPECT_EQ(od->get<std::uint32_t>(0xF030, 1).value(), 0x00091F84u);
  EXPECT_EQ(od->get<std::uint32_t>(0xF050, 2).value(), 0x01012FA0u);

  net.start();
  master::Master m(net.masterLink(), net.bus());
  auto status = m.start();
  ASSERT_TRUE(status.ok()) << status.error().message();
  EXPECT_EQ(segment.slave(0).state(), AlState::kOp);
  // Outputs: the head's 0x16FF + the UR20-4DO-P's 0x1601; inputs: 0x1AFF + UR20-4DI-P's 0x1A00.
  const auto* rx = od->find(0x1C12);
  ASSERT_NE(rx, nullptr);
  EXPECT_EQ(od->get<std::uint8_t>(0x1C12, 0).value(), 2);
  EXPECT_EQ(od->get<std::uint16_t>(0x1C12, 2).value(), 0x1601);
  EXPECT_EQ(od->get<std::uint16_t>(0x1C13, 2).value(), 0x1A00);
  const std::size_t outBytes = m.layout().outputBytes;
  ASSERT_GT(outBytes, 0u);
  ASSERT_GT(m.layout().inputBytes, 0u);

  // DI3 of the input module in slot 0 (0x6000:03) and DO2 of the output module in slot 1
  // (0x7010:02; its output byte is the last: the head's 0x16FF comes first).
  ASSERT_TRUE(od->set<bool>(0x6000, 3, true).ok());
  std::vector<std::uint8_t> outputs(outBytes, 0);
  for (int cycle = 0; cycle < 5; ++cycle) {
    outputs.back() = 0x02;  // the output module's byte is the last: DO2
    ASSERT_TRUE(m.writeData(0, outputs).ok());
    auto s = m.exchange();
    ASSERT_TRUE(s.ok()) << s.error().message();
  }
  EXPECT_TRUE(od->get<bool>(0x7010, 2).value()) << "DO2 of the module in slot 1";
  std::vector<std::uint8_t> inputs(m.layout().inputBytes);
  ASSERT_TRUE(m.readData(outBytes, inputs).ok());
  // Inputs: the head's 0x1AFF, then the UR20-4DI-P's DI1-4 + gap byte and module state, then
  // the UR20-4DO-P's module state byte.
  ASSERT_GE(inputs.size(), 3u);
  EXPECT_EQ(inputs[inputs.size() - 3], 0x04) << "DI3 of the module in slot 0";
  ASSERT_TRUE(m.stop().ok());
}

// A module type no ESI file has is an error with its line and the closest module type.
TEST(ModularDevice, UnknownModuleTypeNamesTheClosest) {
  ECSIM_REQUIRE_UR20();
  TopologySlave entry;
  entry.name = "Station";
  entry.esiFile = sharedEsi() / "Weidmueller_UR20_FBC.xml";
  entry.productCode = 0x4F911C30;
  entry.moduleFile = sharedEsi() / "Weidmueller_UR20_IO.xml";
  entry.modules.push_back({"UR20-4DI-PP", std::nullopt, 7});
  topology::SlaveFactory factory;
  auto slave = factory.make(entry);
  ASSERT_FALSE(slave.ok());
  EXPECT_NE(slave.error().context.find("line 7: unknown module type 'UR20-4DI-PP'; did you mean "
                                       "'UR20-4DI-P'?"),
            std::string::npos)
      << slave.error().context;
}

// The same station from an ENI: TwinCAT configures a modular device by downloading its module
// idents to 0xF030 (ETG.5001 Configured Module List) as a CoE init command; the simulated
// device gets those modules, by complete access (sub 0 padded to 16 bits, as the entries of
// 0xF030 start at bit 16 in the vendor's dictionary) or one subindex at a time.
std::string ur20Eni(const std::string& initCmds) {
  return "<?xml version=\"1.0\"?>\n<EtherCATConfig><Config>\n<Slave>\n"
         "<Info><Name>Station</Name><PhysAddr>1001</PhysAddr><VendorId>#x00000230</VendorId>"
         "<ProductCode>#x4F911C30</ProductCode><RevisionNo>#x00000001</RevisionNo></Info>\n"
         "<Mailbox><Send><Start>#x1000</Start><Length>128</Length></Send>"
         "<Recv><Start>#x1080</Start><Length>128</Length></Recv>\n<CoE><InitCmds>\n" +
         initCmds + "</InitCmds></CoE></Mailbox>\n</Slave>\n</Config></EtherCATConfig>\n";
}

std::string downloadCmd(int sub, const char* data, bool completeAccess) {
  return std::string("<InitCmd") + (completeAccess ? " CompleteAccess=\"1\"" : "") +
         "><Transition>PS</Transition><Comment>download slot cfg</Comment><Ccs>1</Ccs>"
         "<Index>#xF030</Index><SubIndex>" + std::to_string(sub) + "</SubIndex><Data>" + data +
         "</Data></InitCmd>\n";
}

Result<topology::Network> networkFromEniText(const std::string& text) {
  const fs::path file =
      fs::temp_directory_path() / ("ecsim-modular-eni-" + std::to_string(::getpid()) + ".xml");
  std::ofstream(file) << text;
  auto network = topology::buildNetworkFromEni(file, {sharedEsi()});
  fs::remove(file);
  return network;
}

TEST(ModularDevice, EniModuleListDownloadChoosesTheModules) {
  ECSIM_REQUIRE_UR20();
  const std::string completeAccess = downloadCmd(0, "0200841F0900A02F0101", true);
  const std::string oneByOne = downloadCmd(0, "00", false) +
                               downloadCmd(1, "841F0900", false) +
                               downloadCmd(2, "A02F0101", false) + downloadCmd(0, "02", false);
  for (const std::string& cmds : {completeAccess, oneByOne}) {
    auto network = networkFromEniText(ur20Eni(cmds));
    ASSERT_TRUE(network.ok()) << network.error().message();
    auto* od = slavesim::objectDictionaryOf(network->segment->slave(0));
    ASSERT_NE(od, nullptr);
    EXPECT_EQ(od->get<std::uint8_t>(0xF050, 0).value(), 2);
    EXPECT_EQ(od->get<std::uint32_t>(0xF050, 1).value(), 0x00091F84u) << "UR20-4DI-P";
    EXPECT_EQ(od->get<std::uint32_t>(0xF050, 2).value(), 0x01012FA0u) << "UR20-4DO-P";
    // The UR20-4DO-P in slot 1 brings its RxPDO 0x1601 into the assignment.
    EXPECT_EQ(od->get<std::uint16_t>(0x1C12, 2).value(), 0x1601);
  }
}

TEST(ModularDevice, EniModuleListWithAMissingSubindexIsAnError) {
  ECSIM_REQUIRE_UR20();
  auto network = networkFromEniText(
      ur20Eni(downloadCmd(1, "841F0900", false) + downloadCmd(0, "02", false)));
  ASSERT_FALSE(network.ok());
  EXPECT_NE(network.error().context.find("0xF030 lists 2 modules but sets no sub 2"),
            std::string::npos)
      << network.error().context;
}

}  // namespace
}  // namespace ecsim::testing
