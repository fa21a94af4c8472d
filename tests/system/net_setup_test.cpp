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

// Runs a set-up command inside the namespace: "" when it succeeded, else what went wrong.
std::string setUp(const VethNamespace& ns, const std::vector<std::string>& argv) {
  auto out = ns.run(argv);
  if (!out.ok()) return out.error().message();
  return out->exitCode == 0 ? "" : out->output;
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

// Interfaces ecsim did not create are never touched: `net up` and `serve --veth` refuse a name
// that exists (either end), and the failure removes nothing (it used to delete the pair).
TEST(NetSetup, UpAndServeVethRefuseAnExistingInterfaceAndLeaveIt) {
  ECSIM_REQUIRE_NETWORK();
  auto ns = VethNamespace::create();
  ASSERT_TRUE(ns.ok()) << ns.error().message();
  const std::string name = uniqueName() + "e";
  ASSERT_EQ(setUp(*ns, {"ip", "link", "add", name, "type", "veth", "peer", "name", name + "q"}),
            "");
  auto up = ns->run({kEcsim, "net", "up", name});
  ASSERT_TRUE(up.ok());
  EXPECT_NE(up->exitCode, 0) << up->output;
  EXPECT_NE(up->output.find("'" + name + "' already exists"), std::string::npos) << up->output;
  EXPECT_TRUE(linkExists(*ns, name)) << "a failed up deleted someone else's interface";
  EXPECT_TRUE(linkExists(*ns, name + "q")) << "a failed up deleted the peer";
  const std::string log = uniqueTempPath("serve_veth_" + name + ".log");
  auto serve =
      ns->spawn({kEcsim, "serve", "--veth", name, "--slaves", "1"}, SpawnOptions{log, log});
  ASSERT_TRUE(serve.ok());
  auto code = serve->wait(kReadyTimeout);
  if (!code.ok()) (void)serve->stop();
  ASSERT_TRUE(code.ok()) << "serve --veth of an existing name serves: " << readWholeFile(log);
  EXPECT_NE(*code, 0) << readWholeFile(log);
  EXPECT_NE(readWholeFile(log).find("already exists"), std::string::npos) << readWholeFile(log);
  if (!HasFailure()) std::filesystem::remove(log);
  EXPECT_TRUE(linkExists(*ns, name)) << "a failed serve --veth deleted someone else's interface";
  EXPECT_TRUE(linkExists(*ns, name + "q"));
  auto down = ns->run({kEcsim, "net", "down", name});
  ASSERT_TRUE(down.ok());
  EXPECT_NE(down->exitCode, 0) << "nothing of ecsim's to remove: " << down->output;
  EXPECT_TRUE(linkExists(*ns, name)) << "down removed an interface up never made";
  // The simulator's end NAMEs taken by someone else: refused the same way.
  const std::string other = uniqueName() + "f";
  ASSERT_EQ(
      setUp(*ns, {"ip", "link", "add", other + "s", "type", "veth", "peer", "name", other + "q"}),
      "");
  up = ns->run({kEcsim, "net", "up", other});
  ASSERT_TRUE(up.ok());
  EXPECT_NE(up->exitCode, 0) << up->output;
  EXPECT_NE(up->output.find("'" + other + "s' already exists"), std::string::npos) << up->output;
  EXPECT_TRUE(linkExists(*ns, other + "s"));
  EXPECT_TRUE(linkExists(*ns, other + "q"));
  EXPECT_FALSE(linkExists(*ns, other)) << "nothing half-made left behind";
}

// The state file proves what `up` made: a pair of the same name made later by someone else
// (after ours was removed by hand) is not ours, and `down` leaves it alone.
TEST(NetSetup, DownLeavesAPairOfTheSameNameItDidNotCreate) {
  ECSIM_REQUIRE_NETWORK();
  auto ns = VethNamespace::create();
  ASSERT_TRUE(ns.ok()) << ns.error().message();
  const std::string name = uniqueName() + "r";
  auto up = ns->run({kEcsim, "net", "up", name});
  ASSERT_TRUE(up.ok());
  ASSERT_EQ(up->exitCode, 0) << up->output;
  ASSERT_EQ(setUp(*ns, {"ip", "link", "del", name}), "");
  ASSERT_EQ(setUp(*ns, {"ip", "link", "add", name, "type", "veth", "peer", "name", name + "s"}),
            "");
  auto down = ns->run({kEcsim, "net", "down", name});
  ASSERT_TRUE(down.ok());
  EXPECT_NE(down->exitCode, 0) << down->output;
  EXPECT_NE(down->output.find("left alone"), std::string::npos) << down->output;
  EXPECT_TRUE(linkExists(*ns, name)) << "down deleted a pair it did not create";
  EXPECT_TRUE(linkExists(*ns, name + "s"));
  // The stale record is gone: a second down finds nothing, an up refuses the existing name.
  auto again = ns->run({kEcsim, "net", "down", name});
  ASSERT_TRUE(again.ok());
  EXPECT_NE(again->exitCode, 0);
  EXPECT_TRUE(linkExists(*ns, name));
  up = ns->run({kEcsim, "net", "up", name});
  ASSERT_TRUE(up.ok());
  EXPECT_NE(up->exitCode, 0) << up->output;
  EXPECT_TRUE(linkExists(*ns, name));
}

TEST(NetSetup, SigkilledServeLeavesAPairTheNextUpCleans) {
  ECSIM_REQUIRE_NETWORK();
  auto ns = VethNamespace::create();
  ASSERT_TRUE(ns.ok()) << ns.error().message();
  const std::string name = uniqueName() + "k";
  const std::string log = uniqueTempPath("serve_veth_" + name + ".log");
  // SIGKILL leaves the control socket behind: in the temporary folder, removed below.
  const std::string control = uniqueTempPath("serve_veth_" + name + ".sock");
  auto serve = ns->spawn({kEcsim, "serve", "--veth", name, "--slaves", "2", "--control", control},
                         SpawnOptions{log, log});
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
  std::filesystem::remove(control);
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
