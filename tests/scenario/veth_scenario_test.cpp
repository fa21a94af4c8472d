// Every shipped scenario written for our master (scenarios/*.xml) with our master over a veth
// pair in a private network namespace, through the tool as a user runs it:
// `ecsim scenario run --master veth FILE`. The engine is the one the in-process runs use; only
// the strategy differs (real time, raw sockets, the network served paced on the pair's other
// end). Needs CAP_NET_ADMIN, CAP_NET_RAW and CAP_SYS_ADMIN: under CI=true their absence fails,
// elsewhere the tests skip.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "link/netns.hpp"
#include "support/privileges.hpp"

namespace ecsim::scenario {
namespace {

const std::filesystem::path kScenarios = std::filesystem::path(ECSIM_SOURCE_DIR) / "scenarios";
const std::string kEcsim = std::string(ECSIM_BINARY_DIR) + "/tools/ecsim/ecsim";

std::vector<std::string> shippedScenarios() {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(kScenarios)) {
    if (entry.path().extension() == ".xml") names.push_back(entry.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

struct ToolRun {
  int exitCode{-1};
  std::string output;
  pid_t pid{-1};
};

// Runs `ecsim scenario run --master veth ARGS...`; its namespace is named after its pid.
ToolRun runTool(std::vector<std::string> args) {
  args.insert(args.begin(), {kEcsim, "scenario", "run", "--master", "veth"});
  const auto out = std::filesystem::temp_directory_path() /
                   ("ecsim-veth-test-" + std::to_string(::getpid()) + ".txt");
  ToolRun run;
  auto child = spawnProcess(args, SpawnOptions{out.string(), out.string()});
  if (!child.ok()) {
    run.output = child.error().message();
    return run;
  }
  run.pid = child->pid();
  auto code = child->wait(std::chrono::minutes(2));
  if (code.ok()) run.exitCode = *code;
  std::ifstream in(out);
  std::stringstream text;
  text << in.rdbuf();
  run.output = text.str();
  std::filesystem::remove(out);
  return run;
}

// The run removed its namespace (and with it the veth pair).
void expectNoNamespaceLeft(pid_t pid) {
  auto list = runCommand({"ip", "netns", "list"});
  ASSERT_TRUE(list.ok());
  EXPECT_EQ(list->output.find("ecsim-" + std::to_string(pid) + "-"), std::string::npos)
      << list->output;
}

class ShippedOverVeth : public ::testing::TestWithParam<std::string> {};

TEST_P(ShippedOverVeth, Passes) {
  ECSIM_REQUIRE_NETWORK();
  const auto file = kScenarios / (GetParam() + ".xml");
  const ToolRun run = runTool({file.string()});
  std::cout << run.output;
  EXPECT_EQ(run.exitCode, 0) << run.output;
  EXPECT_NE(run.output.find("scenario " + GetParam() + " (" + GetParam() + ".xml), master veth"),
            std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("result: " + GetParam() + " PASSED"), std::string::npos);
  expectNoNamespaceLeft(run.pid);
}

INSTANTIATE_TEST_SUITE_P(Scenarios, ShippedOverVeth, ::testing::ValuesIn(shippedScenarios()),
                         [](const auto& test) { return test.param; });

// Over veth the master is ours, so the expectations on its reaction are judged, and fail when
// it does not react: without recovery the drives are never reported lost nor brought back.
TEST(OurMasterOverVeth, WithoutRecoveryTheCableBreakScenarioFailsOnWhatNeedsRecovery) {
  ECSIM_REQUIRE_NETWORK();
  const auto file = kScenarios / "cable_break.xml";
  const ToolRun run = runTool({"--no-recovery", file.string()});
  std::cout << run.output;
  EXPECT_EQ(run.exitCode, 1) << run.output;
  EXPECT_NE(run.output.find("FAIL  cable_break.xml, line 13: Detected slave-lost of Drive1"),
            std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("FAIL  cable_break.xml, line 18: BackInOp"), std::string::npos);
  // What does not depend on the master's recovery still passes.
  EXPECT_NE(run.output.find("PASS  cable_break.xml, line 12: Detected wkc-error"),
            std::string::npos);
  expectNoNamespaceLeft(run.pid);
}

}  // namespace
}  // namespace ecsim::scenario
