// Runs a scenario whose master is an external command under test (docs/scenarios.md,
// "External masters"): a private network namespace with a veth pair, the scenario's network
// served on the simulator's end in real time (paced, as `ecsim serve --paced`, in a thread of
// its own), the command started in the namespace with {iface} naming the master's end, the
// timeline applied at wall-clock times from the moment every slave is in OP as the simulator
// sees it, and the expectations that need no look inside the master checked: slave states,
// ESC registers, back in OP, the command's exit status and its output.
//
// The command is stopped (SIGTERM, then SIGKILL after the scenario's stopGraceMs) when the
// duration after time zero has passed, or when the network has not reached OP within
// startTimeoutMs. The namespace and the pair are removed on every return path, also after
// SIGINT/SIGTERM (the run then stops the command and reports an error).
//
// Real time: the report carries measured times and counts (and the command's own output), so
// two runs do not give the same bytes; everything else in it is the same from run to run.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "protocol/result.hpp"
#include "scenario/runner.hpp"
#include "scenario/scenario.hpp"

namespace ecsim::scenario {

// Looks up an environment variable for ${NAME} in a command (nullopt: not set).
using Environment = std::function<std::optional<std::string>(const std::string& name)>;

struct ExternalRunOptions {
  // The command's stdout and stderr go to DIR/<scenario name>.output.txt; empty: to a
  // temporary file that is removed after the run (the report keeps the last lines).
  std::filesystem::path outputDir;
  bool realtime{true};        // SCHED_FIFO for the simulator's thread where permitted
  std::size_t tailLines{12};  // output lines quoted in the report
  Environment environment;    // default: the process environment
};

// The command line with {iface} replaced by `iface` and ${NAME} by the environment's value.
// An unset variable or an unterminated ${ is an error naming the scenario file and the
// <Master> line.
Result<std::string> expandCommand(const Scenario& scenario, std::string_view iface,
                                  const Environment& environment);

// Needs CAP_NET_ADMIN, CAP_NET_RAW and CAP_SYS_ADMIN; without them the result carries the
// error (naming the missing capabilities) and no expectation is judged.
ScenarioResult runExternalScenario(const Scenario& scenario, const RunOptions& options = {},
                                   const ExternalRunOptions& external = {});

// The in-process runner or the external one, by the scenario's <Master kind>.
ScenarioResult runAnyScenario(const Scenario& scenario, const RunOptions& options = {},
                              const ExternalRunOptions& external = {});

}  // namespace ecsim::scenario
