// The one expectation evaluator of the scenario engine (scenario/engine.hpp): every kind of
// <Expect> element is judged here, whatever master is under test. The engine feeds it what a
// run shows: ticks (a cycle of ours, a step of the simulator for an external master), the
// master's observations (ours only: its cycle results and events), the command's exit status
// and output (external only). What a strategy can show decides what it can be judged on; the
// rules are checkMasterKind's (scenario/scenario.hpp), checked when the file is read, and an
// expectation a run cannot judge fails saying so rather than passing.
//
// Internal to the scenario library.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "scenario/engine.hpp"
#include "scenario/scenario.hpp"

namespace ecsim::master {
class Master;
}
namespace ecsim::topology {
class Segment;
class FaultInjector;
}  // namespace ecsim::topology

namespace ecsim::scenario {

class CommandOutput;

// The run's log: entries stamped on the strategy's clock, printed relative to time zero in the
// order of their time (entries of one time in the order they came).
class RunLog {
 public:
  void add(SimTime at, std::string text) { entries_.push_back({at, std::move(text)}); }
  // "  12.000 ms  text" lines relative to `origin`, sorted by time.
  std::vector<std::string> lines(SimTime origin) const;

 private:
  struct Entry {
    SimTime at;
    std::string text;
  };
  std::vector<Entry> entries_;
};

// What an external command left to be judged on (ExitStatus, Output).
struct CommandFacts {
  std::optional<int> exitStatus;
  std::string exitHow;  // " (stopped with SIGTERM)", or a reason when there is no status
  const CommandOutput* output{nullptr};
  SimTime start{0};  // on the strategy's clock
};

// How a run ended, for what was not decided during it.
struct RunEnd {
  SimTime at{0};                // on the strategy's clock
  std::optional<SimTime> zero;  // time zero, when it was reached
  bool ranToEnd{false};         // the duration passed (what is due at the end is checked now)
  std::string text;             // "the command exited with status 1"
};

std::string msText(SimTime t);  // "12.000 ms"

class Judge {
 public:
  Judge(const Scenario& scenario, const topology::Segment& segment, RunLog& log);

  // Our master, whose internals Detected, Statistic, Variable and Continuity look at; null for
  // an external one. Called once the master exists, before the first tick.
  void attach(const master::Master* master, const topology::FaultInjector* faults);

  // The master observed `condition` (Detected's names) at `cycle`; logged when it starts or
  // changes, not every cycle it lasts.
  void observe(std::uint64_t cycle, SimTime at, SimTime since, const std::string& condition,
               std::set<std::string> slaves, const std::string& text);
  // The master's events since the last call, as observations.
  void takeEvents(std::uint64_t cycle, SimTime at, SimTime since);
  // Point expectations (State, Register, Statistic, Variable) due at this tick: "at cycle N"
  // is after cycle N's actions and before its exchange.
  void checkDue(std::uint64_t cycle, SimTime since);
  // After a tick's exchange: `good` says whether the master got its process data (ours; none
  // for an external master, which Continuity does not judge), `clean` whether every slave was
  // in OP with process data flowing (BackInOp).
  void sample(std::uint64_t cycle, SimTime since, std::optional<bool> good, bool clean);
  // Everything still open, judged at the end; the results sorted by line.
  std::vector<ExpectationResult> finish(const RunEnd& end, const CommandFacts* command);

  // The topology's name of the slave at a bus position of our master ("position 3" if none).
  std::string slaveNameAtPosition(std::size_t position) const;
  // The simulator's view: every slave in OP.
  bool allOp() const;
  std::uint64_t badCycles() const { return badCycles_; }

 private:
  std::optional<std::size_t> slaveIndex(const std::string& name) const;
  std::optional<double> statistic(const Expectation& x) const;
  ExpectationResult evaluatePoint(const Expectation& x, SimTime since) const;
  ExpectationResult evaluateDetected(const Expectation& x, SimTime since) const;
  ExpectationResult evaluateBackInOp(std::size_t i, const RunEnd& end) const;
  ExpectationResult evaluateCommand(std::size_t i, const RunEnd& end,
                                    const CommandFacts* command) const;
  std::string statesText() const;

  struct Observation {
    std::uint64_t cycle{0};
    SimTime since{0};
    std::string condition;  // wkc-error, frame-lost, emergency, or an event's condition
    std::set<std::string> slaves;
    std::string text;
  };
  struct Point {  // a moment of the run: cycle and time since zero
    std::uint64_t cycle{0};
    SimTime since{0};
  };

  const Scenario& s_;
  const topology::Segment& segment_;
  RunLog& log_;
  const master::Master* master_{nullptr};
  const topology::FaultInjector* faults_{nullptr};
  std::map<std::uint16_t, std::string> stationNames_;
  std::vector<Observation> observations_;
  std::map<std::string, std::pair<std::uint64_t, std::string>> lastLogged_;
  std::size_t eventsSeen_{0};
  std::vector<bool> checked_;
  std::vector<std::optional<Point>> afterAt_;  // BackInOp: the first tick at its "after"
  std::vector<std::optional<Point>> backAt_;   // BackInOp: the first clean tick from then
  std::vector<ExpectationResult> results_;
  std::uint64_t badCycles_{0};
  std::uint64_t run_{0};
  std::uint64_t longestRun_{0};
};

}  // namespace ecsim::scenario
