// `ecsim scenario run FILE... [--seed N] [--pcap DIR] [--junit FILE] [--no-recovery]
// [--shard I/N] [--master in-process|veth]`: runs scenario files (docs/scenarios.md) on the
// scenario engine (scenario/engine.hpp) with the master each file's <Master kind> names: ours
// in-process on virtual time, ours over a veth pair in real time, or an external master
// command over a veth pair (<Master kind="external">); `--master veth` runs the scenarios
// written for our master over veth instead. Prints a report per expectation and exits
// non-zero when any expectation fails or a scenario cannot run. An external master's output is kept next to the capture (--pcap DIR) or the JUnit
// file as <scenario name>.output.txt. `--shard I/N` runs the I-th of N stable subsets of the
// files (by position in the sorted list, round robin), so a CI matrix of N jobs runs each file
// once and their JUnit files merge.
#include <fmt/core.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <ctime>

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "scenario/engine.hpp"
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
  std::string shard;   // "I/N"
  std::string master;  // empty: each file's <Master kind>
};

struct Shard {
  std::size_t index{0};  // 0-based
  std::size_t count{1};
};

// "I/N" with 1 <= I <= N.
std::optional<Shard> parseShard(const std::string& text) {
  const auto slash = text.find('/');
  if (slash == std::string::npos) return std::nullopt;
  try {
    std::size_t used = 0;
    const unsigned long i = std::stoul(text.substr(0, slash), &used);
    if (used != slash) return std::nullopt;
    const std::string rest = text.substr(slash + 1);
    const unsigned long n = std::stoul(rest, &used);
    if (used != rest.size() || n == 0 || i == 0 || i > n) return std::nullopt;
    return Shard{i - 1, n};
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

// The files of one shard: sorted (so the split does not depend on the order of the command
// line or of a shell glob), then every N-th from the I-th.
std::vector<std::string> shardFiles(std::vector<std::string> files, const Shard& shard) {
  std::sort(files.begin(), files.end());
  files.erase(std::unique(files.begin(), files.end()), files.end());
  std::vector<std::string> out;
  for (std::size_t k = shard.index; k < files.size(); k += shard.count) out.push_back(files[k]);
  return out;
}

scenario::JunitContext junitContext() {
  scenario::JunitContext c;
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  std::array<char, 32> stamp{};
  std::strftime(stamp.data(), stamp.size(), "%Y-%m-%dT%H:%M:%S", &utc);
  c.timestamp = stamp.data();
  std::array<char, 256> host{};
  if (::gethostname(host.data(), host.size() - 1) == 0) c.hostname = host.data();
  return c;
}

int runScenarios(const ScenarioOptions& o) {
  std::vector<std::string> files = o.files;
  if (!o.shard.empty()) {
    const auto shard = parseShard(o.shard);
    if (!shard) {
      fmt::print(stderr, "ecsim scenario: --shard {}: I/N expected, 1 <= I <= N (e.g. 2/4)\n",
                 o.shard);
      return 2;
    }
    files = shardFiles(files, *shard);
    fmt::print("shard {}: {} of {} scenario files\n", o.shard, files.size(), o.files.size());
  }
  const scenario::JunitContext context = junitContext();
  scenario::RunOptions run;
  run.seed = o.seed;
  run.recovery = !o.noRecovery;
  run.master = o.master;
  if (!o.pcapDir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(o.pcapDir, ec);
    run.pcapDir = o.pcapDir;
  }
  if (!o.pcapDir.empty()) {
    run.external.outputDir = o.pcapDir;
  } else if (!o.junit.empty()) {
    run.external.outputDir = std::filesystem::absolute(o.junit).parent_path();
  }
  std::vector<scenario::ScenarioResult> results;
  bool allPassed = true;
  for (const auto& file : files) {
    const auto started = std::chrono::steady_clock::now();
    auto seconds = [&started] {
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    };
    auto loaded = scenario::loadScenario(file);
    if (!loaded.ok()) {
      fmt::print(stderr, "ecsim scenario: {}\n", loaded.error().message());
      scenario::ScenarioResult failed;
      failed.name = std::filesystem::path(file).stem().string();
      failed.file = std::filesystem::path(file).filename().string();
      failed.error = loaded.error().message();
      failed.wallSeconds = seconds();
      results.push_back(std::move(failed));
      allPassed = false;
      continue;
    }
    auto result = scenario::runScenario(*loaded, run);
    result.wallSeconds = seconds();
    fmt::print("{}\n", scenario::formatReport(result));
    allPassed = allPassed && result.passed();
    results.push_back(std::move(result));
  }
  if (!o.junit.empty()) {
    std::ofstream out(o.junit, std::ios::binary | std::ios::trunc);
    out << scenario::formatJunit(results, context);
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
  run->add_option("--shard", opts->shard,
                  "Run the I-th of N stable subsets of the files (I/N, e.g. 2/4): the sorted "
                  "list, every N-th from the I-th");
  run->add_option("--master", opts->master,
                  "Run the scenarios written for our master with it in-process (virtual time) "
                  "or over a veth pair (real time; needs CAP_NET_ADMIN, CAP_NET_RAW, "
                  "CAP_SYS_ADMIN)")
      ->check(CLI::IsMember({"in-process", "veth"}));
  return [opts] { return runScenarios(*opts); };
}

}  // namespace ecsim::tools
