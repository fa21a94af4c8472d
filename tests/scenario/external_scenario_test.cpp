// Scenarios with an external master over a veth pair in a private network namespace (needs
// CAP_NET_ADMIN, CAP_NET_RAW, CAP_SYS_ADMIN: under CI=true their absence fails, elsewhere the
// tests skip). Small shell commands show the mechanics (exit status, output, stopping at the
// end, a failing report); SOEM v1.4.0's simple_test, built into the build tree by the interop
// tests' `soem` fixture (../shared/tools/build-soem.sh), runs the shipped scenarios in
// scenarios/external/.
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <thread>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "link/netns.hpp"
#include "scenario/engine.hpp"
#include "scenario/scenario.hpp"
#include "support/privileges.hpp"
#include "support/readiness.hpp"

namespace ecsim::scenario {
namespace {

const std::filesystem::path kSource = ECSIM_SOURCE_DIR;
const std::filesystem::path kSoem = ECSIM_SOEM_DIR;
const std::string kEcsim = std::string(ECSIM_BINARY_DIR) + "/tools/ecsim/ecsim";

#define ECSIM_REQUIRE_SOEM()                                                               \
  do {                                                                                     \
    ECSIM_REQUIRE_NETWORK();                                                               \
    if (!std::filesystem::exists(kSoem / "bin-v1" / "simple_test")) {                      \
      if (::ecsim::testing::ciMode())                                                      \
        FAIL() << "SOEM not built in " << kSoem << " (../shared missing?)";                \
      GTEST_SKIP() << "SOEM not built in " << kSoem << " (../shared/tools/build-soem.sh)"; \
    }                                                                                      \
  } while (false)

std::string readText(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class ExternalScenario : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("ecsim-external-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // A scenario on the demo network with the given master element and expectations.
  Scenario write(const std::string& master, const std::string& expect,
                 const std::string& attributes = "durationMs=\"300\"") {
    const auto file = dir_ / "t.xml";
    std::ofstream(file) << "<?xml version=\"1.0\"?>\n<Scenario name=\"t\" topology=\""
                        << (kSource / "examples/topologies/demo.xml").string() << "\" "
                        << attributes << ">\n"
                        << master << "\n<Expect>\n"
                        << expect << "</Expect>\n</Scenario>\n";
    auto s = loadScenario(file);
    EXPECT_TRUE(s.ok()) << s.error().message();
    return s.ok() ? *s : Scenario{};
  }

  // No namespace of this process is left behind.
  static void expectNoNamespaceLeft() {
    auto list = runCommand({"ip", "netns", "list"});
    ASSERT_TRUE(list.ok());
    EXPECT_EQ(list->output.find("ecsim-" + std::to_string(::getpid()) + "-"), std::string::npos)
        << list->output;
  }

  std::filesystem::path dir_;
};

TEST_F(ExternalScenario, AFailingCommandGivesAFailingReportNamingTheExpectation) {
  ECSIM_REQUIRE_NETWORK();
  // Line 1 declaration, 2 Scenario, 3 Master, 4 Expect, 5 and 6 the expectations.
  auto s = write("<Master kind=\"external\" command=\"false\"/>",
                 "<ExitStatus value=\"0\"/>\n<Output contains=\"slaves found\"/>\n");
  auto r = runScenario(s);
  ASSERT_TRUE(r.error.empty()) << r.error;
  EXPECT_FALSE(r.passed());
  const std::string report = formatReport(r);
  EXPECT_NE(report.find("FAIL  t.xml, line 5: ExitStatus == 0\n"), std::string::npos) << report;
  EXPECT_NE(report.find(": exit status 1\n"), std::string::npos) << report;
  EXPECT_NE(report.find("FAIL  t.xml, line 6: Output contains \"slaves found\""), std::string::npos)
      << report;
  EXPECT_NE(report.find("not found in the 0 lines of output"), std::string::npos) << report;
  EXPECT_NE(report.find("the command exited with status 1"), std::string::npos) << report;
  EXPECT_NE(report.find("never had all slaves in OP"), std::string::npos) << report;
  const std::string junit = formatJunit({r});
  EXPECT_NE(junit.find("<failure message=\""), std::string::npos) << junit;
  expectNoNamespaceLeft();
}

TEST_F(ExternalScenario, TheCommandSeesItsInterfaceAndItsOutputIsJudged) {
  ECSIM_REQUIRE_NETWORK();
  // timeZero="start": nothing brings the slaves to OP here.
  auto s = write(
      "<Master kind=\"external\" timeZero=\"start\" command=\"ip -o link show {iface}; echo "
      "done ${ECSIM_TEST_WORD}\"/>",
      "<ExitStatus value=\"0\"/>\n<Output matches=\"^[0-9]+: ecm-[0-9a-f]{8}@\"/>\n"
      "<Output contains=\"done bird\" op=\"eq\" value=\"1\"/>\n"
      "<State slave=\"Drive2\" state=\"INIT\"/>\n");
  ExternalRunOptions external;
  external.outputDir = dir_;
  external.environment = [](const std::string& name) -> std::optional<std::string> {
    if (name == "ECSIM_TEST_WORD") return std::string("bird");
    return std::nullopt;
  };
  RunOptions options;
  options.external = external;
  auto r = runScenario(s, options);
  ASSERT_TRUE(r.error.empty()) << r.error;
  EXPECT_TRUE(r.passed()) << formatReport(r);
  EXPECT_NE(readText(dir_ / "t.output.txt").find("done bird"), std::string::npos);
  expectNoNamespaceLeft();
}

TEST_F(ExternalScenario, OutputLinesAreJudgedByWhenTheyAppeared) {
  ECSIM_REQUIRE_NETWORK();
  auto s = write(
      "<Master kind=\"external\" timeZero=\"start\" command=\"echo early; sleep 0.4; echo "
      "late\"/>",
      "<Output contains=\"late\" afterMs=\"250\" withinMs=\"1000\"/>\n"
      "<Output contains=\"early\" afterMs=\"250\" withinMs=\"1000\" op=\"eq\" value=\"0\"/>\n"
      "<Output contains=\"early\" afterMs=\"0\" withinMs=\"250\"/>\n"
      "<Output contains=\"late\" afterMs=\"0\" withinMs=\"250\"/>\n",
      "durationMs=\"5000\"");
  auto r = runScenario(s);
  ASSERT_TRUE(r.error.empty()) << r.error;
  ASSERT_EQ(r.results.size(), 4u);
  EXPECT_TRUE(r.results[0].passed) << r.results[0].observed;
  EXPECT_TRUE(r.results[1].passed) << r.results[1].observed;
  EXPECT_TRUE(r.results[2].passed) << r.results[2].observed;
  EXPECT_FALSE(r.results[3].passed) << r.results[3].observed;
  EXPECT_NE(r.results[3].observed.find("not found in the 2 lines of output seen from 0.000 ms to "
                                       "250.000 ms"),
            std::string::npos)
      << r.results[3].observed;
}

// The program under test cannot crash the judge: a 300 KB line matched by (a|b)*c made
// std::regex recurse per character until SIGSEGV. Lines are judged in 64 KiB pieces by RE2.
TEST_F(ExternalScenario, A300KbOutputLineIsJudgedWithoutCrashingTheRunner) {
  ECSIM_REQUIRE_NETWORK();
  auto s = write(
      "<Master kind=\"external\" timeZero=\"start\" "
      "command=\"head -c 300000 /dev/zero | tr '\\000' a; echo c\"/>",
      "<ExitStatus value=\"0\"/>\n<Output matches=\"(a|b)*c\"/>\n"
      "<Output matches=\"^a+$\" op=\"eq\" value=\"4\"/>\n",
      "durationMs=\"5000\"");
  auto r = runScenario(s);
  ASSERT_TRUE(r.error.empty()) << r.error;
  EXPECT_TRUE(r.passed()) << formatReport(r);
  EXPECT_NE(formatReport(r).find("1 lines longer than 65536 bytes"), std::string::npos)
      << formatReport(r).substr(0, 2000);
}

TEST_F(ExternalScenario, ACommandStillRunningAtTheEndIsStopped) {
  ECSIM_REQUIRE_NETWORK();
  // The command would sleep 300 s; the run (300 ms after the start, plus the set-up, slow
  // under ASan on a busy machine) ends well within 60 s only if the command was stopped.
  auto s = write(
      "<Master kind=\"external\" timeZero=\"start\" stopGraceMs=\"500\" "
      "command=\"echo started; sleep 300\"/>",
      "<ExitStatus value=\"143\"/>\n<Output contains=\"started\"/>\n");
  const auto before = std::chrono::steady_clock::now();
  auto r = runScenario(s);
  EXPECT_LT(std::chrono::steady_clock::now() - before, std::chrono::seconds(60));
  ASSERT_TRUE(r.error.empty()) << r.error;
  EXPECT_TRUE(r.passed()) << formatReport(r);
  EXPECT_NE(formatReport(r).find("command stopped (stopped with SIGTERM)"), std::string::npos)
      << formatReport(r);
  expectNoNamespaceLeft();
}

TEST_F(ExternalScenario, ReportsDifferOnlyInMeasuredTimes) {
  ECSIM_REQUIRE_NETWORK();
  auto s = write("<Master kind=\"external\" timeZero=\"start\" command=\"echo one; echo two\"/>",
                 "<ExitStatus value=\"0\"/>\n<Output contains=\"two\"/>\n"
                 "<State slave=\"DI1\" state=\"OP\"/>\n");
  // A measured time and the padding that right-aligns it (its width varies with the value).
  const std::regex times(" *-?[0-9]+\\.[0-9]{3} ms");
  std::string first;
  for (int run = 0; run < 2; ++run) {
    auto r = runScenario(s);
    ASSERT_TRUE(r.error.empty()) << r.error;
    const std::string report = std::regex_replace(formatReport(r), times, " T ms");
    if (run == 0) {
      first = report;
      EXPECT_NE(
          report.find("FAIL  t.xml, line 7: State DI1 is OP at the end\n        at T ms: INIT"),
          std::string::npos)
          << report;
    } else {
      EXPECT_EQ(report, first);
    }
  }
}

TEST_F(ExternalScenario, SigintStopsTheCommandAndRemovesTheNamespace) {
  ECSIM_REQUIRE_NETWORK();
  // The command and the scenario would take 300 s and 600 s; the run ends well within 60 s
  // (set-up slow under ASan on a busy machine included) only if the signal stopped it.
  auto s = write("<Master kind=\"external\" timeZero=\"start\" command=\"sleep 300\"/>",
                 "<ExitStatus value=\"0\"/>\n", "durationMs=\"600000\"");
  // SIGINT to this process once the run is under way (its namespace exists, the command has
  // been started a moment later), as Ctrl-C in a terminal would. Only then: before the run
  // has installed its handler a SIGINT would end the test process. The namespace is made
  // after the handler; a fixed number of quick looks (about 5 s) could miss it on a slow start.
  std::atomic<bool> sent{false};
  std::thread interrupter([&sent] {
    const std::string tag = "ecsim-" + std::to_string(::getpid()) + "-";
    const bool underWay = ::ecsim::testing::waitUntil([&] {
      auto list = runCommand({"ip", "netns", "list"});
      return list.ok() && list->output.find(tag) != std::string::npos;
    });
    if (!underWay) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    ::kill(::getpid(), SIGINT);
    sent = true;
  });
  const auto before = std::chrono::steady_clock::now();
  auto r = runScenario(s);
  interrupter.join();
  ASSERT_TRUE(sent) << "the run's namespace never appeared";
  EXPECT_LT(std::chrono::steady_clock::now() - before, std::chrono::seconds(60));
  EXPECT_NE(r.error.find("interrupted by signal 2"), std::string::npos) << formatReport(r);
  EXPECT_FALSE(r.passed());
  expectNoNamespaceLeft();
}

// Our own master over veth as an external command: ecmaster cyclic reports the drives lost
// when their cable is pulled and brings them back to OP when it is plugged in again; with
// --no-recovery it does neither, and the report says so on the expectations about it.
TEST_F(ExternalScenario, EcmasterRecoversFromACableBreakAndFailsWithoutRecovery) {
  ECSIM_REQUIRE_NETWORK();
  auto s = loadScenario(kSource / "scenarios/external/ecmaster_cable_break.xml");
  ASSERT_TRUE(s.ok()) << s.error().message();
  ExternalRunOptions external;
  external.outputDir = dir_;
  external.environment = [](const std::string& name) -> std::optional<std::string> {
    if (name == "ECMASTER") return std::string(ECSIM_BINARY_DIR) + "/tools/ecmaster/ecmaster";
    return std::nullopt;
  };
  RunOptions options;
  options.external = external;
  auto r = runScenario(*s, options);
  std::string report = formatReport(r);
  std::cout << report;
  ASSERT_TRUE(r.error.empty()) << r.error;
  EXPECT_TRUE(r.passed()) << report;

  s->masterCommand += " --no-recovery";
  r = runScenario(*s, options);
  report = formatReport(r);
  std::cout << report;
  ASSERT_TRUE(r.error.empty()) << r.error;
  EXPECT_FALSE(r.passed());
  std::set<std::string> failed;
  for (const auto& x : r.results) {
    if (!x.passed) failed.insert(x.what.substr(0, x.what.find(' ')));
  }
  // No events, the drives stay in SAFEOP+ERR (their watchdog expired): the Output and
  // BackInOp/State expectations fail, the slaves before the break were never disturbed.
  EXPECT_TRUE(failed.count("Output")) << report;
  EXPECT_TRUE(failed.count("BackInOp")) << report;
  for (const auto& x : r.results) {
    if (x.what.find("AI1") != std::string::npos || x.what.find("DO1") != std::string::npos) {
      EXPECT_TRUE(x.passed) << x.what << ": " << x.observed;
    }
  }
  expectNoNamespaceLeft();
}

// Issue #20: a firmware update over FoE in BOOT (ETG.1000.6 §5.7; docs/devices.md "Firmware
// update over FoE") is cut by a cable pull in the middle of the transfer. ecmaster must fail
// with an error naming FoE and the slave; the module, power-cycled, must still run its old
// software (0x100A 1.0.0: the partial image, whose header carries the new version, was not
// installed); a second, whole update must then succeed and be installed at the next power
// cycle (2.0.0: the module was not bricked). A device that installed partial images fails the
// "after the interrupted update" expectation (checked by hand: see the scenario's comment).
// Not under AddressSanitizer (g++ defines __SANITIZE_ADDRESS__): the scenario's cut is timed
// for a transfer that starts about 90 ms after the command does, and an instrumented ecmaster
// took 2.3 s to read 0x100A before it (CI run of 2026-11-29), so the cut fell before the
// transfer and nothing was interrupted.
#if !defined(__SANITIZE_ADDRESS__)
TEST_F(ExternalScenario, FirmwareUpdateInterruptedByACablePullKeepsTheOldFirmware) {
  ECSIM_REQUIRE_NETWORK();
  auto s = loadScenario(kSource / "scenarios/external/firmware_update_interrupted.xml");
  ASSERT_TRUE(s.ok()) << s.error().message();
  ExternalRunOptions external;
  external.outputDir = dir_;
  external.environment = [](const std::string& name) -> std::optional<std::string> {
    if (name == "ECMASTER") return std::string(ECSIM_BINARY_DIR) + "/tools/ecmaster/ecmaster";
    return std::nullopt;
  };
  RunOptions options;
  options.external = external;
  auto r = runScenario(*s, options);
  const std::string report = formatReport(r);
  std::cout << report;
  ASSERT_TRUE(r.error.empty()) << r.error;
  EXPECT_TRUE(r.passed()) << report;
  EXPECT_NE(report.find("link-down cable=module"), std::string::npos) << report;
  const std::string output = readText(dir_ / "firmware_update_interrupted.output.txt");
  // In this order: the failed write, the old version, the good write, the new version.
  const auto failed = output.find("first update: exit 1");
  const auto old = output.find("version after the interrupted update: 1.0.0");
  const auto good = output.find("second update: exit 0");
  const auto installed = output.find("version after the second update: 2.0.0");
  ASSERT_NE(installed, std::string::npos) << output;
  EXPECT_LT(failed, old) << output;
  EXPECT_LT(old, good) << output;
  EXPECT_LT(good, installed) << output;
  expectNoNamespaceLeft();
}
#endif  // !__SANITIZE_ADDRESS__

TEST_F(ExternalScenario, SoemSimpleTestRunsToTheEndInOp) {
  ECSIM_REQUIRE_SOEM();
  auto s = loadScenario(kSource / "scenarios/external/soem_simple_test.xml");
  ASSERT_TRUE(s.ok()) << s.error().message();
  ExternalRunOptions external;
  external.outputDir = dir_;
  external.environment = [](const std::string& name) -> std::optional<std::string> {
    if (name == "SOEM_DIR") return kSoem.string();
    return std::nullopt;
  };
  RunOptions options;
  options.pcapDir = dir_;
  options.external = external;
  auto r = runScenario(*s, options);
  const std::string report = formatReport(r);
  std::cout << report;
  ASSERT_TRUE(r.error.empty()) << r.error;
  EXPECT_TRUE(r.passed()) << report;
  EXPECT_GE(r.cycles, 9900u) << "LRW frames seen after OP";
  EXPECT_GT(std::filesystem::file_size(dir_ / "soem_simple_test.pcap"), 100000u);
  EXPECT_NE(readText(dir_ / "soem_simple_test.output.txt").find("End program"), std::string::npos);
  expectNoNamespaceLeft();
}

// Through the command line, as CI runs it: the report, the JUnit file and the output next to it.
TEST_F(ExternalScenario, SoemCableBreakThroughEcsimScenarioRun) {
  ECSIM_REQUIRE_SOEM();
  const auto junit = dir_ / "junit.xml";
  const auto log = dir_ / "ecsim.log";
  // SOEM_DIR reaches ${SOEM_DIR} through ecsim's environment.
  auto child =
      spawnProcess({"env", "SOEM_DIR=" + kSoem.string(), kEcsim, "scenario", "run", "--junit",
                    junit.string(), (kSource / "scenarios/external/soem_cable_break.xml").string()},
                   SpawnOptions{log.string(), log.string()});
  ASSERT_TRUE(child.ok()) << child.error().message();
  auto rc = child->wait(std::chrono::seconds(240));  // a 5 s scenario; a bound against a hang
  const std::string out = readText(log);
  std::cout << out;
  ASSERT_TRUE(rc.ok()) << out;
  EXPECT_EQ(*rc, 0) << out;
  EXPECT_NE(out.find("link-down cable=drives"), std::string::npos) << out;
  EXPECT_NE(out.find("result: soem_cable_break PASSED"), std::string::npos) << out;
  EXPECT_NE(readText(junit).find("testsuite name=\"soem_cable_break\""), std::string::npos);
  EXPECT_NE(readText(dir_ / "soem_cable_break.output.txt").find("ERROR : slave 5 lost"),
            std::string::npos);
  expectNoNamespaceLeft();
}

}  // namespace
}  // namespace ecsim::scenario
