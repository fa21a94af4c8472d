// `ecsim net up/down` and `ecsim serve --veth`: the pair exists while wanted and nothing is
// left behind, also after the simulator was killed with SIGKILL (the next `up` cleans the
// stale pair). Everything runs inside a private namespace this test makes.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <thread>

#include "link/netns.hpp"
#include "support/privileges.hpp"
#include "support/readiness.hpp"
#include "support/test_network.hpp"

namespace ecsim::testing {
namespace {

const std::string kEcsim = std::string(ECSIM_BINARY_DIR) + "/tools/ecsim/ecsim";

bool linkExists(const VethNamespace& ns, const std::string& ifname) {
  auto out = ns.run({"ip", "link", "show", ifname});
  return out.ok() && out->exitCode == 0;
}

std::string uniqueName() {
  return "t" + std::to_string(::getpid() % 100000) + "x";
}

TEST(NetSetup, UpCreatesTheConfiguredPairAndDownRemovesIt) {
  ECSIM_REQUIRE_NETWORK();
  auto ns = VethNamespace::create();
  ASSERT_TRUE(ns.ok()) << ns.error().message();
  const std::string name = uniqueName();
  auto up = ns->run({kEcsim, "net", "up", name});
  ASSERT_TRUE(up.ok());
  ASSERT_EQ(up->exitCode, 0) << up->output;
  EXPECT_NE(up->output.find("master interface: " + name), std::string::npos) << up->output;
  EXPECT_TRUE(linkExists(*ns, name));
  EXPECT_TRUE(linkExists(*ns, name + "s"));
  auto v6 = ns->run({"sysctl", "-n", "net.ipv6.conf." + name + ".disable_ipv6"});
  ASSERT_TRUE(v6.ok());
  EXPECT_NE(v6->output.find('1'), std::string::npos) << "IPv6 off: " << v6->output;
  auto state = ns->run({"ip", "-br", "link", "show", name});
  ASSERT_TRUE(state.ok());
  EXPECT_NE(state->output.find("UP"), std::string::npos) << state->output;
  auto down = ns->run({kEcsim, "net", "down", name});
  ASSERT_TRUE(down.ok());
  EXPECT_EQ(down->exitCode, 0) << down->output;
  EXPECT_FALSE(linkExists(*ns, name));
  EXPECT_FALSE(linkExists(*ns, name + "s"));
  auto again = ns->run({kEcsim, "net", "down", name});
  ASSERT_TRUE(again.ok());
  EXPECT_NE(again->exitCode, 0) << "nothing left to remove is reported";
}

TEST(NetSetup, SigkilledServeLeavesAPairTheNextUpCleans) {
  ECSIM_REQUIRE_NETWORK();
  auto ns = VethNamespace::create();
  ASSERT_TRUE(ns.ok()) << ns.error().message();
  const std::string name = uniqueName() + "k";
  const std::string log = uniqueTempPath("serve_veth_" + name + ".log");
  auto serve =
      ns->spawn({kEcsim, "serve", "--veth", name, "--slaves", "2"}, SpawnOptions{log, log});
  ASSERT_TRUE(serve.ok());
  // The pair exists once serve says it serves (a start under ASan on a busy machine can take
  // longer than any fixed wait).
  ASSERT_TRUE(waitForText(log, "ecsim: serving", *serve)) << readWholeFile(log);
  ASSERT_TRUE(linkExists(*ns, name));
  ASSERT_TRUE(serve->kill(SIGKILL).ok());
  ASSERT_TRUE(serve->wait(kReadyTimeout).ok());
  EXPECT_TRUE(linkExists(*ns, name)) << "SIGKILL: no chance to clean up";
  auto up = ns->run({kEcsim, "net", "up", name});
  ASSERT_TRUE(up.ok());
  EXPECT_EQ(up->exitCode, 0) << "stale pair cleaned, new one made: " << up->output;
  auto down = ns->run({kEcsim, "net", "down", name});
  ASSERT_TRUE(down.ok());
  EXPECT_EQ(down->exitCode, 0);
  EXPECT_FALSE(linkExists(*ns, name));
  EXPECT_FALSE(linkExists(*ns, name + "s"));
  if (!HasFailure()) std::filesystem::remove(log);
}

TEST(NetSetup, ServeVethRemovesItsPairOnSigint) {
  ECSIM_REQUIRE_NETWORK();
  auto ns = VethNamespace::create();
  ASSERT_TRUE(ns.ok()) << ns.error().message();
  const std::string name = uniqueName() + "i";
  const std::string log = uniqueTempPath("serve_veth_" + name + ".log");
  auto serve = ns->spawn({kEcsim, "serve", "--veth", name}, SpawnOptions{log, log});
  ASSERT_TRUE(serve.ok());
  // "ecsim: serving" is printed after serve installed its SIGINT handler: a SIGINT that came
  // earlier (a fixed 200 ms after the pair appeared raced with a slow start) would end the
  // process the default way, exit 130, the pair left behind.
  ASSERT_TRUE(waitForText(log, "ecsim: serving", *serve)) << readWholeFile(log);
  ASSERT_TRUE(linkExists(*ns, name));
  ASSERT_TRUE(serve->kill(SIGINT).ok());
  auto code = serve->wait(kReadyTimeout);
  ASSERT_TRUE(code.ok());
  EXPECT_EQ(*code, 0) << readWholeFile(log);
  EXPECT_FALSE(linkExists(*ns, name));
  if (!HasFailure()) std::filesystem::remove(log);
}

}  // namespace
}  // namespace ecsim::testing
