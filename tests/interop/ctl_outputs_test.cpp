// Issue #19 item 5 acceptance: an external master's outputs are checked by `ecsim ctl get`.
// SOEM v1.4.0 (our output_client.c, built against its libsoem.a) brings the demo network to
// OP over a veth pair in a private namespace and writes 0xA5 to DO1's output byte every
// millisecond; `ecsim ctl get DO1 "Output N"` from outside reads each bit as the simulated
// slave took it from its SyncManager: 0xA5 = outputs 1, 3, 6, 8 on; 2, 4, 5, 7 off (bit 0 of
// the byte is the first mapped entry, ETG.1000.4 bit order; ecsim_devices.xml ECS2008's
// RxPDO lists "Output 1".."Output 8" in that order).
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "interop/soem_support.hpp"

namespace ecsim::testing {
namespace {

TEST(CtlOutputs, EcsimCtlGetReadsWhatSoemWroteToDO1) {
  ECSIM_REQUIRE_SOEM();
  const auto client = kSoem / "bin-v1" / "output_client";
  if (!std::filesystem::exists(client)) {
    if (ciMode()) FAIL() << client << " not built (tests/interop/build_soem.sh)";
    GTEST_SKIP() << client << " not built";
  }
  auto ns = VethNamespace::create();
  ASSERT_TRUE(ns.ok()) << ns.error().message();
  const std::string tag = std::to_string(::getpid());
  const std::string socket = ::testing::TempDir() + "ecsim_ctl_" + tag + ".sock";
  const std::string serveLog = ::testing::TempDir() + "ctl_serve_" + tag + ".log";
  const std::string masterLog = ::testing::TempDir() + "ctl_master_" + tag + ".log";
  auto server =
      ns->spawn({kEcsim, "serve", "--rt", "--iface", ns->simulatorInterface(), "--control", socket,
                 std::string(ECSIM_SOURCE_DIR) + "/examples/topologies/demo.xml"},
                SpawnOptions{serveLog, serveLog});
  ASSERT_TRUE(server.ok()) << server.error().message();
  ASSERT_TRUE(waitForText(serveLog, "ecsim: control socket", *server, std::chrono::seconds(20)))
      << readText(serveLog);
  // Before the master: DO1 is in INIT and its outputs are off.
  EXPECT_EQ(ctl(socket, {"get", "DO1", "Output 8"}).out, "0\n");
  // A subscriber from before the master: told the value now and once when the master sets it.
  const std::string subscribeLog = ::testing::TempDir() + "ctl_subscribe_" + tag + ".log";
  auto subscriber = spawnProcess(
      {kEcsim, "ctl", "--socket", socket, "subscribe", "DO1", "Output 8", "--count", "1"},
      SpawnOptions{subscribeLog, subscribeLog});
  ASSERT_TRUE(subscriber.ok()) << subscriber.error().message();
  ASSERT_TRUE(waitForText(subscribeLog, "DO1.Output 8 0", *subscriber, std::chrono::seconds(10)))
      << readText(subscribeLog);

  // DO1 is SOEM's slave 3 (Coupler 1, DI1 2); 30 s of cycles bound the test, it stops the
  // master when done.
  auto master = ns->spawn(withRealtimePriority({"timeout", "60", client.string(),
                                                ns->masterInterface(), "3", "0xA5", "30"}),
                          SpawnOptions{masterLog, masterLog});
  ASSERT_TRUE(master.ok()) << master.error().message();
  ASSERT_TRUE(waitForText(masterLog, "op outputs 0xa5", *master, std::chrono::seconds(40)))
      << "the master did not reach OP:\n"
      << readText(masterLog) << "\nserve:\n"
      << readText(serveLog);
  // The outputs reach the slave with the next frames; the master cycles every millisecond.
  std::this_thread::sleep_for(std::chrono::milliseconds(100));

  const std::string expected = "10100101";  // Output 8 .. Output 1
  for (int n = 1; n <= 8; ++n) {
    const CtlResult r = ctl(socket, {"get", "DO1", "Output " + std::to_string(n)});
    EXPECT_EQ(r.status, 0) << r.out;
    EXPECT_EQ(r.out, std::string(1, expected[static_cast<std::size_t>(8 - n)]) + "\n")
        << "Output " << n;
  }
  auto subscribed = subscriber->wait(std::chrono::seconds(10));
  ASSERT_TRUE(subscribed.ok());
  EXPECT_EQ(*subscribed, 0);
  EXPECT_EQ(readText(subscribeLog), "DO1.Output 8 0\nDO1.Output 8 1\n");
  std::filesystem::remove(subscribeLog);
  // The slave is in OP as the master left it, and the state query says so.
  const CtlResult state = ctl(socket, {"state"});
  EXPECT_EQ(state.status, 0);
  EXPECT_NE(state.out.find("DO1              OP"), std::string::npos) << state.out;
  // A name the slave does not have: exit 1 and the closest names.
  const CtlResult unknown = ctl(socket, {"get", "DO1", "Output 9"});
  EXPECT_EQ(unknown.status, 1);
  EXPECT_NE(unknown.out.find("closest: DO1.Output 1"), std::string::npos) << unknown.out;

  (void)master->stop(std::chrono::seconds(2));
  EXPECT_TRUE(server->running()) << "ecsim serve died:\n" << readText(serveLog);
  (void)server->kill(SIGINT);
  (void)server->wait(std::chrono::seconds(5));
  std::filesystem::remove(serveLog);
  std::filesystem::remove(masterLog);
}

}  // namespace
}  // namespace ecsim::testing
