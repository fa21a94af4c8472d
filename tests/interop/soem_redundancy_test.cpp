// Issue #20 item 4 acceptance: a cable pulled in the middle of the ring during cyclic exchange
// at 1 kHz loses no cycle for a redundant master, and the ring is whole again when healed.
// SOEM v1.4.0 (our red_client.c, ec_init_redundant, built against its libsoem.a) runs the
// ring example (examples/topologies/ring.xml: the demo network with Drive2's port 1 back to
// the master's second port) over two veth pairs in a private namespace, `ecsim serve --iface
// --redundant-iface`. Midway `ecsim ctl link-down cable=drives` cuts AI1 from Drive1; two
// seconds later link-up heals it. With both ports SOEM's frames reach every slave from one
// side or the other (ecx_waitinframe_red sends the primary's result again from the second
// port), so every cycle has the whole working counter. The control run has the first port only
// (ec_init, no second port served): the same break costs it cycles, so the test could not pass
// with a break that did nothing.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "interop/soem_support.hpp"

namespace ecsim::testing {
namespace {

struct RingRun {
  std::string master;  // the client's output
  std::string serve;   // ecsim serve's
  int lost{-1};
  int cycles{-1};
};

// Serves the ring, runs red_client for 5 s of cycles, breaks the drives cable after 1.5 s and
// heals it 2 s later. `redundant` false: the master and the simulator use the first port only
// (the ring is open at the second, as with that cable unplugged).
RingRun runRing(bool redundant) {
  RingRun run;
  const auto client = kSoem / "bin-v1" / "red_client";
  auto ns = VethNamespace::create();
  EXPECT_TRUE(ns.ok()) << (ns.ok() ? "" : ns.error().message());
  if (!ns.ok()) return run;
  // The second pair, inside the test's namespace (deleted with it).
  const std::string tag = std::to_string(::getpid() % 100000) + (redundant ? "r" : "p");
  const std::string simB = "ersb" + tag;
  const std::string masterB = "ermb" + tag;
  for (const auto& argv : std::vector<std::vector<std::string>>{
           {"ip", "link", "add", simB, "type", "veth", "peer", "name", masterB},
           {"ip", "link", "set", simB, "up"},
           {"ip", "link", "set", masterB, "up"}}) {
    auto r = ns->run(argv);
    EXPECT_TRUE(r.ok() && r->exitCode == 0) << (r.ok() ? r->output : r.error().message());
    if (!r.ok() || r->exitCode != 0) return run;
  }
  EXPECT_TRUE(waitOperational(ns->name(), simB).ok());
  EXPECT_TRUE(waitOperational(ns->name(), masterB).ok());
  const std::string socket = ::testing::TempDir() + "ecsim_ring_" + tag + ".sock";
  const std::string serveLog = ::testing::TempDir() + "ring_serve_" + tag + ".log";
  const std::string masterLog = ::testing::TempDir() + "ring_master_" + tag + ".log";
  std::vector<std::string> serve{kEcsim,      "serve", "--rt", "--iface", ns->simulatorInterface(),
                                 "--control", socket};
  if (redundant) serve.insert(serve.end(), {"--redundant-iface", simB});
  serve.push_back(std::string(ECSIM_SOURCE_DIR) + "/examples/topologies/ring.xml");
  auto server = ns->spawn(serve, SpawnOptions{serveLog, serveLog});
  EXPECT_TRUE(server.ok());
  if (!server.ok()) return run;
  EXPECT_TRUE(waitForText(serveLog, "ecsim: control socket", *server, std::chrono::seconds(20)))
      << readText(serveLog);
  auto master =
      ns->spawn(withRealtimePriority({"timeout", "60", client.string(), ns->masterInterface(),
                                      redundant ? masterB : "-", "5"}),
                SpawnOptions{masterLog, masterLog});
  EXPECT_TRUE(master.ok());
  if (!master.ok()) return run;
  EXPECT_TRUE(waitForText(masterLog, "op wkc", *master, std::chrono::seconds(40)))
      << readText(masterLog) << "\nserve:\n"
      << readText(serveLog);
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  const CtlResult down = ctl(socket, {"link-down", "cable=drives"});
  EXPECT_EQ(down.status, 0) << down.out;
  std::this_thread::sleep_for(std::chrono::seconds(2));
  const CtlResult up = ctl(socket, {"link-up", "cable=drives"});
  EXPECT_EQ(up.status, 0) << up.out;
  auto code = master->wait(std::chrono::seconds(30));
  EXPECT_TRUE(code.ok() && *code == 0) << readText(masterLog);
  EXPECT_TRUE(server->running()) << "ecsim serve died:\n" << readText(serveLog);
  (void)server->kill(SIGINT);
  (void)server->wait(std::chrono::seconds(5));
  run.master = readText(masterLog);
  run.serve = readText(serveLog);
  std::smatch m;
  if (std::regex_search(run.master, m, std::regex("done cycles (\\d+) lost (\\d+)"))) {
    run.cycles = std::stoi(m[1]);
    run.lost = std::stoi(m[2]);
  }
  std::filesystem::remove(masterLog);
  std::filesystem::remove(serveLog);
  return run;
}

class SoemRedundancy : public ::testing::Test {
 protected:
  void SetUp() override {
    ECSIM_REQUIRE_SOEM();
    if (!std::filesystem::exists(kSoem / "bin-v1" / "red_client")) {
      if (ciMode()) FAIL() << "red_client not built (tests/interop/build_soem.sh)";
      GTEST_SKIP() << "red_client not built";
    }
  }
};

// A cycle can also be lost to a scheduling stall of a loaded machine (no answer within SOEM's
// 2 ms, wkc -1, anywhere in the run): up to three runs, the first without a lost cycle passes.
// A redundancy that does not hold loses cycles at the break in every run.
TEST_F(SoemRedundancy, CablePulledMidRingLosesNoCycleForARedundantMaster) {
  std::string attempts;
  for (int attempt = 1; attempt <= 3; ++attempt) {
    const RingRun ring = runRing(true);
    EXPECT_NE(ring.master.find("slaves 6"), std::string::npos) << ring.master;
    EXPECT_EQ(ring.cycles, 5000) << ring.master;
    if (ring.lost == 0) {
      if (attempt > 1)
        std::fprintf(stderr, "note: passed on run %d; before:\n%s", attempt, attempts.c_str());
      return;
    }
    attempts += "run " + std::to_string(attempt) + ":\n" + ring.master + "serve:\n" + ring.serve;
  }
  ADD_FAILURE() << "cycles lost in each of 3 runs:\n" << attempts;
}

TEST_F(SoemRedundancy, TheSameBreakCostsASinglePortMasterCycles) {
  const RingRun line = runRing(false);
  EXPECT_EQ(line.cycles, 5000) << line.master;
  EXPECT_GT(line.lost, 100) << "2 s without Drive1 and Drive2\n" << line.master;
}

}  // namespace
}  // namespace ecsim::testing
