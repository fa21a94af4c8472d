// Runs a scenario with our master in-process on virtual time: the network from the topology,
// the master brought to OP, then one Master::cycle() after another with the timeline's actions
// applied at their cycle or time and the expectations checked at theirs. Everything is virtual
// time and seeded randomness: the same scenario and seed give the same report and capture, byte
// for byte.
//
// The runner is the application and nothing more: it never reads a slave, restarts the bus or
// helps the master. What the master reports (its cycle results, its events: lost, returned,
// reset, error, recovered, recovery failed; its health) is what Detected and Statistic
// expectations judge; the simulator's side (AL state, registers) is what State, Register and
// BackInOp look at. RunOptions::recovery is MasterOptions::recovery: without it the master
// only exchanges process data (ecsim scenario run --no-recovery).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "scenario/scenario.hpp"
#include "topology/network_builder.hpp"

namespace ecsim::scenario {

struct RunOptions {
  std::optional<std::uint64_t> seed;  // overrides the file's
  std::filesystem::path pcapDir;      // empty: no capture; else DIR/<name>.pcap
  bool recovery{true};                // MasterOptions::recovery
};

struct ExpectationResult {
  int line{0};
  std::string what;  // "State Drive1 == OP at 2900.000 ms"
  bool passed{false};
  SimTime at{0};         // when it was decided, ns after OP
  std::string observed;  // what the run showed
  bool needsRecovery{false};
};

struct ScenarioResult {
  std::string name;
  std::string file;
  std::uint64_t seed{0};
  SimTime cycleTime{0};
  std::uint64_t cycles{0};
  std::vector<std::string> log;  // "  12.000 ms  cycle 12  link-down cable=drives: ..."
  std::vector<ExpectationResult> results;
  std::string error;  // the run could not be carried out (setup, master start)
  // Wall-clock seconds the run took, filled in by whoever timed it (the core reads no clock);
  // the JUnit report's `time`.
  double wallSeconds{0.0};
  bool passed() const;
  std::size_t failures() const;
};

ScenarioResult runScenario(const Scenario& scenario, const RunOptions& options = {});

// What both runners (this one and scenario/external_runner.hpp) start from: the result's
// heading (name, file, seed, cycle time) and the network of the scenario's topology file.
ScenarioResult startResult(const Scenario& scenario, const RunOptions& options);
Result<topology::Network> buildScenarioNetwork(const Scenario& scenario);

// Human-readable report of one run (no wall-clock content: deterministic).
std::string formatReport(const ScenarioResult& result);
// What a JUnit report says of where and when it ran (the caller reads clock and host name).
struct JunitContext {
  std::string timestamp;  // start of the runs, ISO 8601 without zone ("2026-11-28T18:30:00")
  std::string hostname;
};
// JUnit XML: one testsuite per scenario, one testcase per expectation, named by what it
// expects (stable when lines move; a repeated name gets " #2", " #3"); a failure's text in
// the element's body with type "ExpectationFailed", a run that could not be carried out as an
// error of type "ScenarioError"; the scenario's log in <system-out>. Every suite and testcase
// has `time`: the run's wall time, shared evenly by its testcases (one run decides them all).
// Structure: tests/scenario/junit.xsd.
std::string formatJunit(const std::vector<ScenarioResult>& results,
                        const JunitContext& context = {});

}  // namespace ecsim::scenario
