// ecmaster on a real raw socket: `ecsim serve` on one end of a veth pair in a private network
// namespace, ecmaster (RealTimeBus, real clock) on the other. Needs CAP_NET_ADMIN/CAP_NET_RAW.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "link/netns.hpp"
#include "support/privileges.hpp"
#include "support/test_network.hpp"

namespace ecsim::testing {
namespace {

const std::string kEcmaster = std::string(ECSIM_BINARY_DIR) + "/tools/ecmaster/ecmaster";
const std::string kEcsim = std::string(ECSIM_BINARY_DIR) + "/tools/ecsim/ecsim";

TEST(EcmasterVeth, ScanSdoAndCyclicOverARawSocket) {
  ECSIM_REQUIRE_NETWORK();
  auto ns = VethNamespace::create();
  ASSERT_TRUE(ns.ok()) << ns.error().message();
  const std::string log = ::testing::TempDir() + "ecmaster_veth_serve.log";
  auto server = ns->spawn({kEcsim, "serve", "--iface", ns->simulatorInterface(), "--quiet"},
                          SpawnOptions{log, log});
  ASSERT_TRUE(server.ok()) << server.error().message();
  // 20 ms per try: the server is an ordinary process on a machine that may be busy (CI, two
  // cores, sanitizers); the default 2 ms x 3 tries is for a real-time set-up.
  const std::vector<std::string> base{kEcmaster, "--iface",      ns->masterInterface(),
                                      "--json",  "--timeout-ms", "20"};
  auto ecmaster = [&](std::vector<std::string> args) {
    args.insert(args.begin(), base.begin(), base.end());
    auto out = ns->run(args);
    EXPECT_TRUE(out.ok());
    return out.ok() ? *out : CommandOutput{-1, ""};
  };
  // The simulator needs a moment to open its socket.
  CommandOutput slaves;
  for (int i = 0; i < 50; ++i) {
    slaves = ecmaster({"slaves"});
    if (slaves.exitCode == 0) break;
  }
  ASSERT_EQ(slaves.exitCode, 0) << slaves.output;
  auto list = nlohmann::json::parse(slaves.output, nullptr, false);
  ASSERT_TRUE(list.is_array()) << slaves.output;
  EXPECT_EQ(list.size(), 6u);  // the demo network `ecsim serve` serves by default

  auto upload = ecmaster({"upload", "-p", "4", "0x1018:02", "--type", "uint32"});
  ASSERT_EQ(upload.exitCode, 0) << upload.output;
  EXPECT_EQ(nlohmann::json::parse(upload.output)["value"], 0x7201);

  auto cyclic = ecmaster({"cyclic", "--cycle-us", "2000", "--seconds", "1"});
  ASSERT_EQ(cyclic.exitCode, 0) << cyclic.output;
  auto stats = nlohmann::json::parse(cyclic.output, nullptr, false);
  ASSERT_FALSE(stats.is_discarded()) << cyclic.output;
  EXPECT_GT(stats["cycles"].get<int>(), 300);
  EXPECT_EQ(stats["wkcErrors"], 0);
  EXPECT_EQ(stats["simulated"], false);
  auto stopped = server->stop();
  EXPECT_TRUE(stopped.ok());
}

}  // namespace
}  // namespace ecsim::testing
