// SOEM against `ecsim serve` over a veth pair inside a private network namespace. SOEM's
// sample programs always exit 0, so the checks read what they print (the success and failure
// lines are listed in ../shared/notes/soem-interop.md §4).
#include <gtest/gtest.h>
#include <unistd.h>

#include <regex>
#include <sstream>

#include "interop/soem_support.hpp"

namespace ecsim::testing {
namespace {

// The lines of text matching pattern (for failure messages).
std::string lines(const std::string& text, const std::string& pattern) {
  std::regex re(pattern);
  std::istringstream in(text);
  std::string line;
  std::string out;
  while (std::getline(in, line)) {
    if (std::regex_search(line, re)) out += line + "\n";
  }
  return out;
}

int countMatches(const std::string& text, const std::string& pattern) {
  std::regex re(pattern);
  return static_cast<int>(
      std::distance(std::sregex_iterator(text.begin(), text.end(), re), std::sregex_iterator()));
}

TEST(SoemV1, SlaveinfoListsEverySlaveWithItsIdentity) {
  ECSIM_REQUIRE_SOEM();
  SoemRun run({"--slaves", "3"});
  std::string out = run.run("bin-v1/slaveinfo", {"-map"}, std::chrono::seconds(60));
  EXPECT_NE(out.find("3 slaves found and configured."), std::string::npos) << out;
  EXPECT_EQ(countMatches(out, "\n State: 4\n"), 3) << out;
  EXPECT_EQ(countMatches(out, "Man: 00000e5c ID: 00010001 Rev: 00010000"), 3) << out;
  EXPECT_NE(out.find("Configured address: 1003"), std::string::npos) << out;
  EXPECT_EQ(out.find("Not all slaves"), std::string::npos) << out;
  EXPECT_EQ(out.find("Name:?"), std::string::npos) << out;
}

// SOEM v2's slaveinfo against 5 generic slaves served with `extra` options.
void expectSlaveinfoV2(const std::vector<std::string>& extra) {
  std::vector<std::string> serveArgs{"--slaves", "5"};
  serveArgs.insert(serveArgs.end(), extra.begin(), extra.end());
  SoemRun run(serveArgs);
  std::string out = run.run("bin-v2/slaveinfo", {"-map"}, std::chrono::seconds(60));
  EXPECT_NE(out.find("ecx_init on"), std::string::npos) << out;
  EXPECT_NE(out.find("5 slaves found and configured."), std::string::npos) << out;
  EXPECT_EQ(countMatches(out, "\n State: 4\n"), 5) << out;
  EXPECT_EQ(out.find("Not all slaves"), std::string::npos) << out;
}

TEST(SoemV2, SlaveinfoListsEverySlaveWithItsIdentity) {
  ECSIM_REQUIRE_SOEM();
  expectSlaveinfoV2({});
}

// Issue 18: the busy-polling server with its answers sent by a kernel thread on another CPU
// (--send-cpu, link/kernel_thread_sender.hpp) seen by a master that is not ours: the scan,
// the SII reads and the way to SAFE-OP go through it as through send(2).
TEST(SoemV2, SlaveinfoAgainstABusyPollingServerSendingFromAnotherCpu) {
  ECSIM_REQUIRE_SOEM();
  const long cpus = ::sysconf(_SC_NPROCESSORS_ONLN);
  ASSERT_GE(cpus, 2) << "CI machines have 2 CPUs";
  expectSlaveinfoV2({"--busy-poll", "--send-cpu", std::to_string(cpus - 1)});
}

// ---- distributed clocks: SOEM's propagation-delay measurement against the model -------------

std::vector<long> reportedDelays(const std::string& out) {
  std::vector<long> delays;
  std::regex re(" Delay: (-?[0-9]+)\\[ns\\]");
  for (auto it = std::sregex_iterator(out.begin(), out.end(), re); it != std::sregex_iterator();
       ++it) {
    delays.push_back(std::stol((*it)[1]));
  }
  return delays;
}

TEST(SoemDc, PropagationDelaysInALineEqualTheModel) {
  ECSIM_REQUIRE_SOEM();
  SoemRun run({"--slaves", "5"});
  std::string out = run.run("bin-v1/slaveinfo", {}, std::chrono::seconds(60));
  // Each hop: the ESC's 1000 ns plus 1 m of cable (5 ns), as docs/timing.md gives.
  EXPECT_EQ(reportedDelays(out), (std::vector<long>{0, 1005, 2010, 3015, 4020})) << out;
}

TEST(SoemDc, PropagationDelaysInATreeEqualTheModel) {
  ECSIM_REQUIRE_SOEM();
  SoemRun run({std::string(ECSIM_SOURCE_DIR) + "/tests/interop/dc_tree.xml"});
  std::string out = run.run("bin-v1/slaveinfo", {}, std::chrono::seconds(60));
  // Model arrival times of one frame relative to the junction: A1 = 1000 + 25; A2 = A1 +
  // 1000 + 10; B1 only after branch A has returned: A2 turns round (1000), back over 10 m of
  // cable... = 3035 + 10 + 1000 + 25 (A1 and its cable) + 1000 (junction) + 100 (20 m).
  const std::vector<long> model{0, 1025, 2035, 5170};
  auto got = reportedDelays(out);
  ASSERT_EQ(got.size(), model.size()) << out;
  for (std::size_t i = 0; i < model.size(); ++i) {
    EXPECT_LE(std::abs(got[i] - model[i]), 10) << "slave " << i + 1 << "\n" << out;
  }
}

// ---- the demo network (coupler, DI, DO, AI with CoE, two CiA 402 drives with CoE) ----------

constexpr int kDemoSlaves = 6;
// Expected LRW working counter: DO 2, DI 1, AI 1 (inputs; its mailbox-status byte in v2 rides
// on the same read), two drives 3 each.
constexpr int kDemoWkc = 10;

TEST(SoemV1, SlaveinfoMapListsTheDemoNetwork) {
  ECSIM_REQUIRE_SOEM();
  SoemRun run({});
  std::string out = run.run("bin-v1/slaveinfo", {"-map"}, std::chrono::seconds(60));
  EXPECT_NE(out.find("6 slaves found and configured."), std::string::npos) << out;
  EXPECT_NE(out.find("Calculated workcounter 10"), std::string::npos) << out;
  EXPECT_EQ(countMatches(out, "\n State: 4\n"), kDemoSlaves) << out;
  for (const char* id : {"ID: 00001100", "ID: 00001008", "ID: 00002008", "ID: 00003102"}) {
    EXPECT_NE(out.find(std::string("Man: 00000e5c ") + id), std::string::npos) << id;
  }
  EXPECT_EQ(countMatches(out, "Man: 00000e5c ID: 00007201 Rev: 00010000"), 2) << out;
  EXPECT_NE(out.find(" Name:ECS7201 CiA 402 servo drive"), std::string::npos) << out;
  EXPECT_NE(out.find("PDO mapping according to CoE :"), std::string::npos) << out;
  EXPECT_NE(out.find("0x6041:0x00 0x10 UNSIGNED16   Statusword"), std::string::npos) << out;
  EXPECT_NE(out.find("0x607A:0x00 0x20 INTEGER32    Target position"), std::string::npos) << out;
  EXPECT_NE(out.find("0x6000:0x01 0x01 BOOLEAN      Input 1"), std::string::npos) << out;
  EXPECT_NE(out.find("SM2 A:1100 L:  13 F:00010064 Type:3"), std::string::npos) << out;
  EXPECT_NE(out.find("SM3 A:1180 L:  15 F:00010020 Type:4"), std::string::npos) << out;
  EXPECT_EQ(out.find("Not all slaves"), std::string::npos) << out;
}

TEST(SoemV2, SlaveinfoMapListsTheDemoNetwork) {
  ECSIM_REQUIRE_SOEM();
  SoemRun run({});
  std::string out = run.run("bin-v2/slaveinfo", {"-map"}, std::chrono::seconds(60));
  EXPECT_NE(out.find("6 slaves found and configured."), std::string::npos) << out;
  EXPECT_EQ(countMatches(out, "\n State: 4\n"), kDemoSlaves) << out;
  EXPECT_NE(out.find("Ps:080d Psb:0 Ty:01 Act:01"), std::string::npos)
      << "v2 maps each mailbox slave's SM1 status byte\n"
      << out;
  EXPECT_EQ(out.find("Not all slaves"), std::string::npos) << out;
}

TEST(SoemV1, SlaveinfoSdoReadsTheObjectDictionaries) {
  ECSIM_REQUIRE_SOEM();
  SoemRun run({});
  std::string out = run.run("bin-v1/slaveinfo", {"-sdo"}, std::chrono::seconds(120));
  EXPECT_NE(out.find("6 slaves found and configured."), std::string::npos) << out;
  EXPECT_EQ(countMatches(out, "CoE Object Description found, 41 entries"), 2) << out;
  EXPECT_EQ(countMatches(out, "CoE Object Description found, [0-9]+ entries"), 3) << out;
  // Identity object values as the SII says (vendor 0xE5C, product 0x7201).
  EXPECT_NE(out.find("0x00000e5c"), std::string::npos) << out;
  EXPECT_NE(out.find("0x00007201"), std::string::npos) << out;
  // The only SDO errors are for subindexes that records leave out (gaps such as 0x6000:02..10,
  // as on Beckhoff MDP devices): "subindex does not exist".
  EXPECT_EQ(countMatches(out, "error:(?!06090011)[0-9a-f]{8}"), 0) << out;
  EXPECT_EQ(out.find("Mailbox error"), std::string::npos) << out;
}

// simple_test and simple_ng cycle 10000 times (about 60 s); under ASan with a loaded machine
// simple_ng took 83 s. `timeout` only guards against a hang: a run cut short loses the lines
// the checks count. Below the ctest TIMEOUT of 240 s.
constexpr std::chrono::seconds kCyclicRunTimeout{200};

TEST(SoemV1, SimpleTestReachesOpAndCyclesWithTheExpectedWorkingCounter) {
  ECSIM_REQUIRE_SOEM();
  SoemRun run({});
  std::string out = run.run("bin-v1/simple_test", {}, kCyclicRunTimeout);
  EXPECT_NE(out.find("Operational state reached for all slaves."), std::string::npos) << out;
  EXPECT_NE(out.find("Calculated workcounter 10"), std::string::npos) << out;
  const int good =
      countMatches(out, "Processdata cycle +[0-9]+, WKC " + std::to_string(kDemoWkc) + " ,");
  const int all = countMatches(out, "Processdata cycle +[0-9]+, WKC");
  EXPECT_GE(good, 9900) << "cycles with the expected WKC";
  EXPECT_EQ(good, all) << "every cycle printed had WKC " << kDemoWkc;
  EXPECT_EQ(countMatches(out, "WARNING|ERROR|lost"), 0) << out.substr(0, 4000);
  EXPECT_NE(out.find("I: 05"), std::string::npos) << "DI1 inputs 1 and 3 set by the topology";
}

TEST(SoemV2, SimpleNgReportsAllSlavesOperational) {
  ECSIM_REQUIRE_SOEM();
  SoemRun run({});
  std::string out = run.run("bin-v2/simple_ng", {}, kCyclicRunTimeout);
  EXPECT_NE(out.find("6 slaves found"), std::string::npos) << out.substr(0, 2000);
  EXPECT_NE(out.find("all slaves are now operational"), std::string::npos) << out.substr(0, 2000);
  // No slave ever leaves OP (a watchdog or AL error would show as SAFE_OP here).
  EXPECT_EQ(countMatches(out, "\\* Slave [0-9]+ is in SAFE_OP"), 0)
      << lines(out, "Slave|AL|WARNING|ERROR|wrong");
  // simple_ng waits 2 ms for each answer; a host too busy to schedule the simulator in time
  // shows as an occasional "wrong" iteration, which is the host's, not the network's. Its
  // state check right after may time out as well and print "Slave N lost" (seen once in CI:
  // iteration 9326 took 4 ms, the next ones had WKC 10 again), so a "lost" is tolerated
  // only as the echo of a wrong iteration. Up to 0.3% of the 10000: 11 were seen on an idle
  // machine and in CI on 2026-11-29 (the same day SOEM v2's redundant mode lost 0-18 frames
  // per 5000 on a whole ring, v1 none), where a network fault costs every iteration after it.
  const int wrong = countMatches(out, "wrong \\(expected");
  EXPECT_LE(wrong, 30) << lines(out, "wrong");
  EXPECT_LE(countMatches(out, "\\* Slave [0-9]+ lost"), wrong)
      << lines(out, "Slave|AL|WARNING|ERROR|wrong");
  EXPECT_GE(
      countMatches(out, "Iteration +[0-9]+: +[0-9]+ usec +WKC " + std::to_string(kDemoWkc) + " "),
      9900);
}

}  // namespace
}  // namespace ecsim::testing
