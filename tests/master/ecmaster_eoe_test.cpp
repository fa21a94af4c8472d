// `ecmaster eoe` against its in-process simulator (--sim): Set IP Parameter then Get IP
// Parameter (ETG.1000.6 §5.7) on the EL6601 EoE switch terminal of the shared Beckhoff ESI,
// bad settings named, and a slave without EoE answering with the mailbox error "unsupported
// protocol" (ETG.1000.4 §5.6, detail 0x0002).
#include <gtest/gtest.h>

#include <unistd.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "link/netns.hpp"
#include "support/test_network.hpp"

namespace ecsim::testing {
namespace {

const std::string kEcmaster = std::string(ECSIM_BINARY_DIR) + "/tools/ecmaster/ecmaster";
const std::string kDemo = std::string(ECSIM_SOURCE_DIR) + "/examples/topologies/demo.xml";

CommandOutput run(std::vector<std::string> args) {
  args.insert(args.begin(), kEcmaster);
  auto out = runCommand(args);
  EXPECT_TRUE(out.ok());
  return out.ok() ? *out : CommandOutput{-1, "", ""};
}

std::string el6601Topology() {
  const std::string file =
      ::testing::TempDir() + "ecmaster_eoe_" + std::to_string(::getpid()) + ".xml";
  std::ofstream(file) << "<Topology name=\"eoe\">\n  <Slave name=\"Switch\" esi=\""
                      << (sharedDir() / "esi" / "Beckhoff_EtherCAT_Terminals.xml").string()
                      << "\" product=\"#x19c93052\"/>\n</Topology>\n";
  return file;
}

TEST(EcmasterEoe, SetsAndReadsBackTheIpParameters) {
  ECSIM_REQUIRE_SHARED(sharedDir() / "esi" / "Beckhoff_EtherCAT_Terminals.xml");
  const std::string topology = el6601Topology();
  auto before = run({"--sim", topology, "eoe", "-p", "0"});
  ASSERT_EQ(before.exitCode, 0) << before.output;
  EXPECT_NE(before.output.find("ip   -\n"), std::string::npos) << before.output;
  // Station 0x1001: the station-derived locally administered MAC.
  EXPECT_NE(before.output.find("mac  02:00:00:00:10:01\n"), std::string::npos) << before.output;

  auto set = run({"--sim", topology, "--json", "eoe", "-p", "0", "ip=192.168.9.200",
                  "mask=255.255.255.0", "gw=192.168.9.1", "mac=02:00:00:00:00:2a", "name=switch1"});
  ASSERT_EQ(set.exitCode, 0) << set.output;
  auto j = nlohmann::json::parse(set.standardOutput, nullptr, false);
  ASSERT_FALSE(j.is_discarded()) << set.output;
  EXPECT_EQ(j["ip"], "192.168.9.200");
  EXPECT_EQ(j["mask"], "255.255.255.0");
  EXPECT_EQ(j["gw"], "192.168.9.1");
  EXPECT_EQ(j["mac"], "02:00:00:00:00:2a");
  EXPECT_EQ(j["dns"], nullptr);
  EXPECT_EQ(j["name"], "switch1");

  auto typo = run({"--sim", topology, "eoe", "gateway=1.2.3.4"});
  EXPECT_EQ(typo.exitCode, 1);
  EXPECT_NE(typo.output.find("unknown setting 'gateway'"), std::string::npos) << typo.output;
  auto bad = run({"--sim", topology, "eoe", "ip=192.168.9"});
  EXPECT_EQ(bad.exitCode, 1);
  EXPECT_NE(bad.output.find("'192.168.9' is not an IPv4 address"), std::string::npos) << bad.output;
  std::filesystem::remove(topology);
}

TEST(EcmasterEoe, ASlaveWithoutEoeAnswersUnsupportedProtocol) {
  // Slave 5 of the demo network is a CoE drive without EoE.
  auto out = run({"--sim", kDemo, "eoe", "-p", "5", "ip=10.0.0.5"});
  EXPECT_EQ(out.exitCode, 1) << out.output;
  EXPECT_NE(out.output.find("EoE Set IP Parameter to"), std::string::npos) << out.output;
  EXPECT_NE(out.output.find("protocol"), std::string::npos) << out.output;
}

}  // namespace
}  // namespace ecsim::testing
