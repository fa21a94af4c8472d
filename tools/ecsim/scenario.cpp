// `ecsim scenario run FILE... [--seed N] [--pcap DIR] [--junit FILE] [--no-recovery]`: runs
// scenario files (docs/scenarios.md) with our master in-process on virtual time, or with an
// external master command over a veth pair in real time (<Master kind="external">), prints a
// report per expectation and exits non-zero when any expectation fails or a scenario cannot
// run. An external master's output is kept next to the capture (--pcap DIR) or the JUnit
// file as <scenario name>.output.txt.
#include <fmt/core.h>

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "scenario/external_runner.hpp"
#include "scenario/runner.hpp"
#include "scenario/scenario.hpp"
#include "tools/ecsim/commands.hpp"

namespace ecsim::tools {
namespace {

struct ScenarioOptions {
  std::vector<std::string> files;
  std::optional<std::uint64_t> seed;
  std::string pcapDir;
  std::string junit;
  bool noRecovery{false};
};

int runScenarios(const ScenarioOptions& o) {
  scenario::RunOptions run;
  run.seed = o.seed;
  run.recovery = !o.noRecovery;
  if (!o.pcapDir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(o.pcapDir, ec);
    run.pcapDir = o.pcapDir;
  }
  scenario::ExternalRunOptions external;
  if (!o.pcapDir.empty()) {
    external.outputDir = o.pcapDir;
  } else if (!o.junit.empty()) {
    external.outputDir = std::filesystem::absolute(o.junit).parent_path();
  }
  std::vector<scenario::ScenarioResult> results;
  bool allPassed = true;
  for (const auto& file : o.files) {
    auto loaded = scenario::loadScenario(file);
    if (!loaded.ok()) {
      fmt::print(stderr, "ecsim scenario: {}\n", loaded.error().message());
      scenario::ScenarioResult failed;
      failed.name = std::filesystem::path(file).stem().string();
      failed.file = std::filesystem::path(file).filename().string();
      failed.error = loaded.error().message();
      results.push_back(std::move(failed));
      allPassed = false;
      continue;
    }
    auto result = scenario::runAnyScenario(*loaded, run, external);
    fmt::print("{}\n", scenario::formatReport(result));
    allPassed = allPassed && result.passed();
    results.push_back(std::move(result));
  }
  if (!o.junit.empty()) {
    std::ofstream out(o.junit, std::ios::binary | std::ios::trunc);
    out << scenario::formatJunit(results);
    if (!out) {
      fmt::print(stderr, "ecsim scenario: cannot write {}\n", o.junit);
      return 2;
    }
  }
  std::size_t passed = 0;
  for (const auto& r : results) passed += r.passed() ? 1 : 0;
  fmt::print("{} of {} scenarios passed\n", passed, results.size());
  return allPassed ? 0 : 1;
}

}  // namespace

CommandRunner addScenarioCommand(CLI::App& app) {
  auto opts = std::make_shared<ScenarioOptions>();
  auto* cmd = app.add_subcommand("scenario", "Run fault-injection scenarios (docs/scenarios.md)");
  cmd->require_subcommand(1);
  auto* run = cmd->add_subcommand("run", "Run scenario files and report each expectation");
  run->add_option("files", opts->files, "Scenario files")->required()->check(CLI::ExistingFile);
  run->add_option("--seed", opts->seed, "Seed for every scenario (default: each file's)");
  run->add_option("--pcap", opts->pcapDir, "Capture the master's cable to DIR/<scenario>.pcap");
  run->add_option("--junit", opts->junit, "Write a JUnit XML report to FILE");
  run->add_flag("--no-recovery", opts->noRecovery,
                "The master only exchanges process data: no state reads, no restart");
  return [opts] { return runScenarios(*opts); };
}

}  // namespace ecsim::tools
