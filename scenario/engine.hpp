// The scenario engine (docs/scenarios.md): one run loop for every master under test. It builds
// the scenario's network, starts the master, waits for time zero (every slave in OP), applies
// the timeline's actions at their cycle or time, checks the expectations at theirs (one
// evaluator, scenario/expectations.hpp), stops and reports. What differs between masters is a
// strategy (scenario/master_under_test.hpp), chosen by <Master kind="...">:
//
//   in-process  our Master in this process over a memory link, on virtual time: one
//               Master::cycle() after another, the network served in between. The same
//               scenario and seed give the same report and capture, byte for byte.
//   veth        our Master in this process over a raw socket on one end of a veth pair in a
//               private network namespace, the network served on the other end in real time
//               (paced, as `ecsim serve --paced`). Cycles are paced by the wall clock; every
//               expectation of the in-process master is judged, on measured times.
//   external    a command under test (<Master kind="external" command="prog {iface}"/>),
//               started in the namespace with {iface} naming the master's end; the network is
//               served as for veth and a cycle is a process-data frame the simulator saw.
//               Judged on what needs no look inside the master: slave states, ESC registers,
//               back in OP, the command's exit status and output.
//
// The engine is the application and nothing more: it never reads a slave for the master,
// restarts the bus or helps it. What the master reports (its cycle results, its events) is what
// Detected and Statistic judge; the simulator's side (AL state, registers) is what State,
// Register and BackInOp look at. RunOptions::recovery is MasterOptions::recovery: without it
// our master only exchanges process data (ecsim scenario run --no-recovery).
//
// veth and external need CAP_NET_ADMIN, CAP_NET_RAW and CAP_SYS_ADMIN; without them the
// result carries the error naming what is missing and no expectation is judged. The namespace
// and the pair are removed on every return path, also after SIGINT/SIGTERM (the run then stops
// and reports an error). Real-time reports carry measured times and counts, so two runs do not
// give the same bytes.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/result.hpp"
#include "scenario/scenario.hpp"

namespace ecsim::scenario {

// Looks up an environment variable for ${NAME} in a command (nullopt: not set).
using Environment = std::function<std::optional<std::string>(const std::string& name)>;

struct ExternalRunOptions {
  // The command's stdout and stderr go to DIR/<scenario name>.output.txt; empty: to a
  // temporary file that is removed after the run (the report keeps the last lines).
  std::filesystem::path outputDir;
  bool realtime{true};        // SCHED_FIFO for the run's thread where permitted (veth only)
  std::size_t tailLines{12};  // output lines quoted in the report
  Environment environment;    // default: the process environment
};

struct RunOptions {
  std::optional<std::uint64_t> seed;  // overrides the file's
  std::filesystem::path pcapDir;      // empty: no capture; else DIR/<name>.pcap
  bool recovery{true};                // MasterOptions::recovery (our master)
  // Empty: the file's <Master kind>. "in-process" or "veth" runs a scenario written for our
  // master with that strategy (ecsim scenario run --master veth); an external scenario cannot
  // be run by our master, nor ours by a command.
  std::string master;
  ExternalRunOptions external;  // veth and external
};

struct ExpectationResult {
  int line{0};
  std::string what;  // "State Drive1 == OP at 2900.000 ms"
  bool passed{false};
  SimTime at{0};         // when it was decided, ns after time zero
  std::string observed;  // what the run showed
  bool needsRecovery{false};
};

struct ScenarioResult {
  std::string name;
  std::string file;
  std::string master;  // the strategy that ran it: in-process, veth or external
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

// Runs the scenario with the master its <Master kind> (or options.master) names.
ScenarioResult runScenario(const Scenario& scenario, const RunOptions& options = {});

// The strategy a run uses: options.master or the file's kind; an error naming the file and the
// <Master> line when the two do not go together.
Result<std::string> masterKindFor(const Scenario& scenario, const RunOptions& options);

// An external master's command line with {iface} replaced by `iface` and ${NAME} by the
// environment's value. An unset variable or an unterminated ${ is an error naming the scenario
// file and the <Master> line.
Result<std::string> expandCommand(const Scenario& scenario, std::string_view iface,
                                  const Environment& environment);

// Human-readable report of one run (no wall-clock content: deterministic for in-process runs).
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
