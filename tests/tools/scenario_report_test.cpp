// `ecsim scenario run` as a CI job runs it (issue #16 items 4 and 6): the JUnit file it writes
// is accepted by xmllint against tests/scenario/junit.xsd (the structure CI systems read:
// time on every suite and testcase, timestamp, hostname, failure text and type, the log in
// <system-out>), testcase names do not change when a scenario's lines move, and `--shard I/N`
// splits a list of files into disjoint subsets that together run every file once.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "link/netns.hpp"
#include "support/test_network.hpp"

namespace ecsim::testing {
namespace {

namespace fs = std::filesystem;

const std::string kEcsim = std::string(ECSIM_BINARY_DIR) + "/tools/ecsim/ecsim";
const fs::path kScenarios = fs::path(ECSIM_SOURCE_DIR) / "scenarios";
const fs::path kSchema = fs::path(ECSIM_SOURCE_DIR) / "tests/scenario/junit.xsd";

fs::path freshDir(const std::string& name) {
  auto dir = fs::path(::testing::TempDir()) / (name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A scenario of the shipped al_error.xml with one expectation that fails and one that is
// written twice, the whole body shifted down by `blankLines`.
std::string failingScenario(int blankLines) {
  std::string text = slurp(kScenarios / "al_error.xml");
  const auto expect = text.find("<Expect>");
  EXPECT_NE(expect, std::string::npos);
  text.insert(expect + 8,
              "\n    <State slave=\"DI1\" state=\"OP\" cycle=\"360\"/>"
              "\n    <State slave=\"DI1\" state=\"OP\" cycle=\"360\"/>");
  const std::string relative = "topology=\"../examples/topologies/demo.xml\"";
  const auto topology = text.find(relative);
  EXPECT_NE(topology, std::string::npos);
  text.replace(topology, relative.size(),
               "topology=\"" + (kScenarios / "../examples/topologies/demo.xml").string() + "\"");
  const auto body = text.find("<Timeline>");
  text.insert(body, std::string(static_cast<std::size_t>(blankLines), '\n'));
  return text;
}

std::vector<std::string> testcaseNames(const std::string& junit) {
  std::vector<std::string> names;
  const std::regex name("<testcase name=\"([^\"]*)\"");
  for (auto it = std::sregex_iterator(junit.begin(), junit.end(), name);
       it != std::sregex_iterator(); ++it) {
    names.push_back((*it)[1]);
  }
  return names;
}

TEST(ScenarioReport, JunitIsValidAndNamesAreStable) {
  if (::access("/usr/bin/xmllint", X_OK) != 0) {
    if (ciMode()) FAIL() << "CI=true but no xmllint (Debian libxml2-utils)";
    GTEST_SKIP() << "no xmllint";
  }
  const fs::path dir = freshDir("ecsim_junit_test");
  std::vector<std::string> reports;
  for (int shift : {0, 7}) {
    const fs::path file = dir / ("probe" + std::to_string(shift) + ".xml");
    std::ofstream(file) << failingScenario(shift);
    const fs::path junit = dir / ("report" + std::to_string(shift) + ".xml");
    auto run = runCommand({kEcsim, "scenario", "run", "--junit", junit.string(), file.string()});
    fs::remove(file);
    ASSERT_TRUE(run.ok());
    EXPECT_EQ(run->exitCode, 1) << "one expectation fails:\n" << run->output;
    auto lint = runCommand({"xmllint", "--noout", "--schema", kSchema.string(), junit.string()});
    ASSERT_TRUE(lint.ok());
    EXPECT_EQ(lint->exitCode, 0) << lint->output << slurp(junit);
    reports.push_back(slurp(junit));
  }
  const std::string& junit = reports[0];
  EXPECT_NE(junit.find("type=\"ExpectationFailed\">"), std::string::npos) << junit;
  EXPECT_NE(junit.find("expected: State DI1 is OP at cycle 360"), std::string::npos) << junit;
  EXPECT_NE(junit.find("<system-out>  350.000 ms  cycle    350  al-error"), std::string::npos)
      << junit;
  EXPECT_TRUE(std::regex_search(junit, std::regex("timestamp=\"\\d{4}-\\d\\d-\\d\\dT")));
  // Names from what is expected, not from lines: the same in both files; a repeated one
  // gets "#2".
  EXPECT_EQ(testcaseNames(reports[0]), testcaseNames(reports[1]));
  const auto names = testcaseNames(junit);
  EXPECT_EQ(std::set<std::string>(names.begin(), names.end()).size(), names.size());
  EXPECT_NE(junit.find("name=\"State DI1 is OP at cycle 360 #2\""), std::string::npos) << junit;
  // The line is still there, as an attribute, and it moved.
  EXPECT_NE(reports[0], reports[1]);
}

TEST(ScenarioReport, ShardsSplitTheFilesDisjointlyAndCompletely) {
  // Three quick shipped scenarios, given in an order that is not sorted.
  const std::vector<std::string> files = {(kScenarios / "sdo_abort.xml").string(),
                                          (kScenarios / "al_error.xml").string(),
                                          (kScenarios / "frame_loss.xml").string()};
  std::multiset<std::string> ran;
  for (const char* shard : {"1/2", "2/2"}) {
    std::vector<std::string> args = {kEcsim, "scenario", "run", "--shard", shard};
    args.insert(args.end(), files.begin(), files.end());
    auto run = runCommand(args);
    ASSERT_TRUE(run.ok());
    EXPECT_EQ(run->exitCode, 0) << run->output;
    const std::regex result("result: (\\w+) PASSED");
    for (auto it = std::sregex_iterator(run->output.begin(), run->output.end(), result);
         it != std::sregex_iterator(); ++it) {
      ran.insert((*it)[1]);
    }
    if (std::string(shard) == "1/2") {
      // Sorted: al_error, frame_loss, sdo_abort; shard 1 takes the 1st and 3rd.
      EXPECT_NE(run->output.find("shard 1/2: 2 of 3 scenario files"), std::string::npos)
          << run->output;
    }
  }
  EXPECT_EQ(ran, (std::multiset<std::string>{"al_error", "frame_loss", "sdo_abort"}));
  for (const char* bad : {"0/2", "3/2", "2", "1/0", "a/b"}) {
    auto run = runCommand({kEcsim, "scenario", "run", "--shard", bad, files[0]});
    ASSERT_TRUE(run.ok());
    EXPECT_EQ(run->exitCode, 2) << bad;
    EXPECT_NE(run->output.find("I/N expected"), std::string::npos) << run->output;
  }
}

// `ecsim ctl help` lists every action the server takes with its arguments, without a server.
TEST(CtlHelp, ListsTheActionsAndTheirArguments) {
  auto run = runCommand({kEcsim, "ctl", "help"});
  ASSERT_TRUE(run.ok());
  EXPECT_EQ(run->exitCode, 0) << run->output;
  EXPECT_NE(run->output.find("  link-down cable= port= slave="), std::string::npos)
      << run->output;
  EXPECT_NE(run->output.find("  al-error "), std::string::npos) << run->output;
  EXPECT_NE(run->output.find("  latch "), std::string::npos) << run->output;
  // pause-master pauses our master: a scenario action only, which no server takes.
  EXPECT_EQ(run->output.find("pause-master"), std::string::npos) << run->output;
  // Nor durationCycles: cycles are the scenario runner's, a control line has none.
  EXPECT_NE(run->output.find("  delay cable= durationMs= ns= port= slave="), std::string::npos)
      << run->output;
}

}  // namespace
}  // namespace ecsim::testing
