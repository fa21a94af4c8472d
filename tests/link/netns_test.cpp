#include "link/netns.hpp"

#include <gtest/gtest.h>
#include <sched.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "link/net_namespace.hpp"
#include "link/realtime.hpp"
#include "test_support.hpp"

namespace ecsim {
namespace {

using namespace std::chrono_literals;

bool namespaceListed(const std::string& name) {
  auto out = runCommand({"ip", "netns", "list"});
  return out.ok() && out->output.find(name) != std::string::npos;
}

std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(VethNamespace, CreatesAPairInsideItsOwnNamespaceAndRemovesIt) {
  ECSIM_REQUIRE_NETWORK_PRIVILEGES();
  const std::string ownDefault = "/proc/sys/net/ipv6/conf/default/disable_ipv6";
  const bool ipv6Available = std::filesystem::exists(ownDefault);
  const std::string ownBefore = readText(ownDefault);
  auto ns = VethNamespace::create();
  ASSERT_TRUE(ns.ok()) << ns.error().message();
  // The sysctl was written inside the namespace, not in the test's own.
  EXPECT_EQ(readText(ownDefault), ownBefore);
  const std::string name = ns->name();
  EXPECT_EQ(name.rfind("ecsim-" + std::to_string(::getpid()) + "-", 0), 0u) << name;
  EXPECT_LE(ns->masterInterface().size(), 15u);
  EXPECT_LE(ns->simulatorInterface().size(), 15u);
  EXPECT_NE(ns->masterInterface(), ns->simulatorInterface());
  EXPECT_TRUE(namespaceListed(name));
  EXPECT_TRUE(std::filesystem::exists(netnsPath(name)));

  for (const std::string& iface : {ns->masterInterface(), ns->simulatorInterface()}) {
    auto inside = ns->run({"ip", "-d", "-o", "link", "show", iface});
    ASSERT_TRUE(inside.ok()) << inside.error().message();
    EXPECT_EQ(inside->exitCode, 0) << inside->output;
    EXPECT_NE(inside->output.find("veth"), std::string::npos) << inside->output;
    EXPECT_NE(inside->output.find(",UP"), std::string::npos) << inside->output;
    EXPECT_NE(inside->output.find("mtu 1500"), std::string::npos) << inside->output;
    // Not visible in the namespace the test runs in.
    auto outside = runCommand({"ip", "-o", "link", "show", iface});
    ASSERT_TRUE(outside.ok());
    EXPECT_NE(outside->exitCode, 0) << outside->output;
    // IPv6 disabled, so the kernel sends nothing of its own on the pair.
    if (ipv6Available) {
      auto ipv6 = ns->run({"cat", "/proc/sys/net/ipv6/conf/" + iface + "/disable_ipv6"});
      ASSERT_TRUE(ipv6.ok()) << ipv6.error().message();
      EXPECT_EQ(ipv6->output, "1\n");
    }
  }

  ASSERT_TRUE(ns->destroy().ok());
  EXPECT_TRUE(ns->name().empty());
  EXPECT_FALSE(namespaceListed(name));
  EXPECT_FALSE(std::filesystem::exists(netnsPath(name)));
  EXPECT_TRUE(ns->destroy().ok());  // twice is harmless
}

TEST(VethNamespace, DestructorRemovesTheNamespace) {
  ECSIM_REQUIRE_NETWORK_PRIVILEGES();
  std::string name;
  {
    auto ns = VethNamespace::create(VethOptions{9000, true});
    ASSERT_TRUE(ns.ok()) << ns.error().message();
    name = ns->name();
    auto link = ns->run({"ip", "-o", "link", "show", ns->masterInterface()});
    ASSERT_TRUE(link.ok());
    EXPECT_NE(link->output.find("mtu 9000"), std::string::npos) << link->output;
    // Moving keeps one owner.
    VethNamespace moved = std::move(*ns);
    EXPECT_EQ(moved.name(), name);
    EXPECT_TRUE(namespaceListed(name));
  }
  EXPECT_FALSE(namespaceListed(name));
}

TEST(VethNamespace, TwoNamespacesHaveDistinctNames) {
  ECSIM_REQUIRE_NETWORK_PRIVILEGES();
  auto first = VethNamespace::create();
  auto second = VethNamespace::create();
  ASSERT_TRUE(first.ok()) << first.error().message();
  ASSERT_TRUE(second.ok()) << second.error().message();
  EXPECT_NE(first->name(), second->name());
  EXPECT_NE(first->masterInterface(), second->masterInterface());
}

TEST(VethNamespace, SpawnsProgramsInsideTheNamespace) {
  ECSIM_REQUIRE_NETWORK_PRIVILEGES();
  auto ns = VethNamespace::create();
  ASSERT_TRUE(ns.ok()) << ns.error().message();
  const std::string out =
      std::filesystem::temp_directory_path() / ("ecsim-link-spawn-" + std::to_string(::getpid()));
  auto lister = ns->spawn({"ip", "-o", "link"}, SpawnOptions{out, out});
  ASSERT_TRUE(lister.ok()) << lister.error().message();
  auto code = lister->wait(30s);
  ASSERT_TRUE(code.ok()) << code.error().message();
  EXPECT_EQ(*code, 0);
  std::ifstream in(out);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find(ns->masterInterface()), std::string::npos) << text.str();
  EXPECT_EQ(text.str().find("eth0"), std::string::npos) << text.str();
  std::filesystem::remove(out);

  auto sleeper = ns->spawn({"sleep", "60"});
  ASSERT_TRUE(sleeper.ok()) << sleeper.error().message();
  EXPECT_GT(sleeper->pid(), 0);
  EXPECT_TRUE(sleeper->running());
  auto timeout = sleeper->wait(10ms);
  ASSERT_FALSE(timeout.ok());
  EXPECT_EQ(timeout.error().code, ErrorCode::kTimeout);
  auto stopped = sleeper->stop(5s);
  ASSERT_TRUE(stopped.ok()) << stopped.error().message();
  EXPECT_EQ(*stopped, 128 + SIGTERM);
  EXPECT_FALSE(sleeper->running());
}

// The scenario engine starts an external master at SCHED_FIFO below its own thread (scenario/
// external_master.cpp): the priority reaches the program and what it starts, and the thread's
// own policy comes back when the guard ends.
TEST(RealTime, SpawnPriorityReachesTheProgramAndTheThreadGetsItsPolicyBack) {
  const int before = sched_getscheduler(0);
  {
    RealTimeThread rt(30);
    if (!rt.ok()) {
      if (::ecsim::testing::ciMode()) FAIL() << "CI=true and SCHED_FIFO " << rt.note();
      GTEST_SKIP() << "SCHED_FIFO " << rt.note();
    }
    EXPECT_EQ(sched_getscheduler(0), SCHED_FIFO);
    EXPECT_EQ(rt.note(), "SCHED_FIFO 30");
    const std::string out =
        std::filesystem::temp_directory_path() / ("ecsim-link-fifo-" + std::to_string(::getpid()));
    auto child =
        spawnProcess({"sh", "-c", "chrt -p $$; sh -c 'chrt -p $$'"}, SpawnOptions{out, out, 12});
    ASSERT_TRUE(child.ok()) << child.error().message();
    auto code = child->wait(30s);
    ASSERT_TRUE(code.ok()) << code.error().message();
    EXPECT_EQ(*code, 0);
    const std::string text = readText(out);
    std::filesystem::remove(out);
    std::size_t fifo = 0;
    std::size_t twelve = 0;
    for (std::size_t at = 0; (at = text.find("SCHED_FIFO", at)) != std::string::npos; ++at) ++fifo;
    for (std::size_t at = 0; (at = text.find("priority: 12", at)) != std::string::npos; ++at) {
      ++twelve;
    }
    EXPECT_EQ(fifo, 2u) << text;  // the shell and the shell it started
    EXPECT_EQ(twelve, 2u) << text;
  }
  EXPECT_EQ(sched_getscheduler(0), before);
}

TEST(VethNamespace, ReportsAMissingProgram) {
  auto child = spawnProcess({"ecsim-no-such-program-xyz"});
  ASSERT_FALSE(child.ok());
  EXPECT_EQ(child.error().code, ErrorCode::kNotFound);
  EXPECT_NE(child.error().context.find("ecsim-no-such-program-xyz"), std::string::npos);
}

TEST(NetworkNamespace, UnknownNamespaceIsNotFound) {
  ECSIM_REQUIRE_NETWORK_PRIVILEGES();
  bool ran = false;
  Status status = runInNetworkNamespace("ecsim-no-such-namespace", [&] {
    ran = true;
    return okStatus();
  });
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().code, ErrorCode::kNotFound);
  EXPECT_NE(status.error().context.find("ecsim-no-such-namespace"), std::string::npos);
  EXPECT_FALSE(ran);
  Status bad = runInNetworkNamespace("../etc", [] { return okStatus(); });
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().code, ErrorCode::kInvalidArgument);
}

TEST(NetworkNamespace, RunsInsideAndReturns) {
  ECSIM_REQUIRE_NETWORK_PRIVILEGES();
  auto ns = VethNamespace::create();
  ASSERT_TRUE(ns.ok()) << ns.error().message();
  auto ownNamespace = [] { return std::filesystem::read_symlink("/proc/thread-self/ns/net"); };
  const auto before = ownNamespace();
  std::filesystem::path inside;
  Status status = runInNetworkNamespace(ns->name(), [&] {
    inside = ownNamespace();
    return makeError(ErrorCode::kAborted, "from inside");
  });
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().code, ErrorCode::kAborted);  // fn's own status comes back
  EXPECT_NE(inside, before);
  EXPECT_EQ(ownNamespace(), before);
}

}  // namespace
}  // namespace ecsim
