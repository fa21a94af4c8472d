// A scenario (docs/scenarios.md): a network, the master that runs it, a timeline of fault
// actions and the expectations a run is judged by. Read from XML; every error names the file
// and line. The scenario engine (scenario/engine.hpp) runs it with the master under test its
// <Master kind> names: ours in-process, ours over veth, or an external command
// (<Master kind="external" command="prog {iface}"/>).
//
//   <Scenario name="cable_break" topology="../examples/topologies/demo.xml" cycleUs="1000"
//             durationMs="3000" seed="1">
//     <Master kind="in-process"/>
//     <Timeline>
//       <Action cycle="500" do="link-down" cable="drives"/>
//       <Action timeMs="800" do="link-up" cable="drives"/>
//     </Timeline>
//     <Expect>
//       <Detected condition="slave-state" slave="Drive1" afterCycle="500" withinCycles="100"/>
//       <BackInOp afterCycle="800" withinMs="1000"/>
//       <State slave="Drive1" state="OP" atMs="2900"/>
//     </Expect>
//   </Scenario>
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/result.hpp"
#include "protocol/time.hpp"
#include "topology/faults.hpp"

namespace ecsim {
struct TopologyConfig;
}
namespace ecsim::master {
struct VariableInfo;
}

namespace ecsim::scenario {

struct TimedAction {
  int line{0};
  std::optional<std::uint64_t> cycle;  // cycles after the master reached OP
  std::optional<SimTime> time;         // ns after the master reached OP
  topology::FaultAction action;        // as written (slave and cable names, logs)
  topology::Fault fault;               // parsed when the file is read: every argument checked
};

enum class ExpectKind : std::uint8_t {
  kState,       // a slave's AL state (simulator side) at a time
  kDetected,    // the master observed a condition within N cycles of a cycle
  kBackInOp,    // every slave in OP and a clean cycle within T of a cycle
  kRegister,    // an ESC register (counters 0x0300-0x0313, DL status...) at a time
  kStatistic,   // a master statistic at a time
  kContinuity,  // bounds on cycles without fresh process data
  kVariable,    // a process-data entry as the master sees it, at a time
  kExitStatus,  // external master: the command's exit status (at the end)
  kOutput,      // external master: lines of the command's output (at the end)
};

enum class Compare : std::uint8_t { kEq, kNe, kLt, kLe, kGt, kGe };

struct Expectation {
  int line{0};
  ExpectKind kind{ExpectKind::kState};
  std::optional<std::uint64_t> atCycle;  // when to check (none: at the end)
  std::optional<SimTime> atTime;
  std::string slave;                  // topology name
  std::string state;                  // kState: INIT/PREOP/SAFEOP/OP
  std::optional<bool> error;          // kState: the AL status error flag
  std::optional<std::uint16_t> code;  // kState: AL status code
  std::string condition;              // kDetected
  std::uint64_t afterCycle{0};        // kDetected, kBackInOp (ours: afterMs converted)
  std::optional<SimTime> afterTime;   // kBackInOp, kOutput (afterMs; external masters only)
  std::uint64_t withinCycles{0};      // kDetected (withinMs converted)
  SimTime within{0};                  // kBackInOp (withinCycles converted), kOutput
  std::uint16_t address{0};           // kRegister
  unsigned width{1};                  // kRegister bytes
  std::uint32_t mask{0xFFFFFFFF};     // kRegister: bits compared
  std::string name;                   // kStatistic
  std::string variable;               // kVariable by name ("Drive1.Statusword"), else:
  std::uint16_t index{0};             // kVariable
  std::uint8_t subindex{0};
  bool isSigned{false};
  Compare compare{Compare::kEq};
  double value{0};
  double tolerance{0};
  std::uint64_t maxBadCycles{0};             // kContinuity
  std::uint64_t maxConsecutiveBadCycles{0};  // kContinuity
  std::string text;                          // kOutput: contains="..." or matches="regex"
  bool isRegex{false};                       // kOutput: text is an ECMAScript regular expression
  bool countLines{false};     // kOutput: compare the number of lines found (op, value)
  bool needsRecovery{false};  // documented: fails when the master does not react
  std::string describe() const;
};

struct Scenario {
  std::filesystem::path file;
  int line{0};  // of <Scenario>
  std::string name;
  std::string description;
  std::filesystem::path topology;
  std::string masterKind{"in-process"};  // or "veth" (ours over veth), "external" (a command)
  std::string masterCommand;             // external
  // External masters (docs/scenarios.md, "External masters"):
  int masterLine{0};                        // of <Master>, for errors about the command
  SimTime startTimeout{30 * kNsPerSecond};  // command start to all slaves in OP
  SimTime stopGrace{2 * kNsPerSecond};      // SIGTERM to SIGKILL when the time is up
  bool timeFromStart{false};                // timeZero="start": time 0 is the command's start
  SimTime cycleTime{kNsPerMs};
  SimTime duration{kNsPerSecond};
  std::uint64_t seed{1};
  std::vector<TimedAction> actions;
  std::vector<Expectation> expectations;
};

// What a <Detected condition="..."> may name: the runner's own observations of a cycle and the
// master's events (master/health.hpp), "any-error" for everything but good news.
inline constexpr std::string_view kDetectableConditions[] = {
    "wkc-error",   "frame-lost",     "cycle-error", "emergency",       "slave-state",
    "slave-lost",  "slave-returned", "slave-reset", "slave-recovered", "recovery-failed",
    "ring-broken", "ring-whole",     "any-error"};

// Reading is strict (docs/scenarios.md, "Strictness"): an unknown element or attribute, an
// action or expectation after the end of the run is an error naming the file, the line and the
// closest valid name. loadScenario also reads the topology and checks the names against it
// (checkTopologyNames); parseScenario checks the file alone.
Result<Scenario> loadScenario(const std::filesystem::path& path);
Result<Scenario> parseScenario(std::string_view xml, const std::filesystem::path& path);
// Every slave and cable an action or expectation names is in the topology; the error names
// the scenario's file and line and the closest name the topology has.
Status checkTopologyNames(const Scenario& scenario, const TopologyConfig& topology);
// <Variable name="Drive1.Statusword">: process-variable names exist once the master has
// scanned (master/variables.hpp); the engine checks them against Master::variables() at the
// start of the run. A name not found is an error naming the file, the line and the closest
// names.
Status checkVariableNames(const Scenario& scenario,
                          const std::vector<master::VariableInfo>& variables);
// What each master under test can be judged on: rejects (naming file and line) the
// expectations that need the master's internals (Detected, Statistic, Variable, Continuity)
// and the pause-master action for external masters, and ExitStatus, Output and BackInOp
// afterMs for ours (in-process and veth: the rules of a scenario written for our master do not
// change with how it is run). parseScenario() calls it.
Status checkMasterKind(const Scenario& scenario);

std::string_view toString(Compare c);
bool compareValues(double observed, Compare c, double expected, double tolerance = 0);

}  // namespace ecsim::scenario
