// The "master under test" strategy of the scenario engine (scenario/engine.hpp): what differs
// between our master in-process, our master over veth and an external command. The engine owns
// the run loop; a strategy owns its clock (virtual or real), its links, its master or command,
// and says when the run is at its next tick and what the tick's exchange showed.
//
//   start()     links, namespace, master or command; ours returns at time zero (all slaves in
//               OP), an external command reaches it later (next() waits for it).
//   next()      waits for the next moment to act at: our next cycle's start (paced by the clock;
//               cycles the master had no time for are reported as skipped), or the simulator's
//               next step for an external master. nullopt: the run is over.
//   exchange()  the tick's process data: one Master::cycle() of ours (its observations fed to
//               the judge), nothing for an external master (the simulator's step was it).
//   stop()      stops the master or command; how the run ended.
//
// Internal to the scenario library.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "protocol/result.hpp"
#include "protocol/time.hpp"
#include "scenario/engine.hpp"
#include "scenario/expectations.hpp"

namespace ecsim {
class SignalFlag;
}
namespace ecsim::topology {
struct Network;
class FaultInjector;
}  // namespace ecsim::topology

namespace ecsim::scenario {

// What the engine gives a strategy; everything outlives it.
struct RunContext {
  const Scenario& scenario;
  const RunOptions& options;
  topology::Network& network;
  topology::FaultInjector& faults;
  Judge& judge;
  RunLog& log;
  const SignalFlag* signals;  // real-time strategies: SIGINT/SIGTERM end the run in order
};

struct Tick {
  std::uint64_t cycle{0};    // since time zero: ours, the master's cycles; external, the
                             // process-data frames the simulator saw
  SimTime now{0};            // on the strategy's clock
  std::uint64_t skipped{0};  // cycles before this one that had no exchange (ours)
  bool end{false};           // the skipped cycles reached the end: no exchange, no action
};

struct Exchange {
  std::optional<bool> good;  // ours: the master got its process data (Continuity)
  bool clean{false};         // every slave in OP with process data flowing (BackInOp)
};

class MasterUnderTest {
 public:
  virtual ~MasterUnderTest() = default;
  virtual const Clock& clock() const = 0;
  // Virtual time: the run is deterministic and its capture stamped from the DC epoch; real
  // time: stamped with the Unix time, as `ecsim serve --pcap`.
  virtual bool virtualTime() const = 0;
  // pause-master: the master can be told to send nothing for a while (ours).
  virtual bool pausable() const { return false; }
  virtual Status start() = 0;
  virtual std::optional<SimTime> zero() const = 0;
  virtual std::optional<Tick> next() = 0;
  virtual Exchange exchange(const Tick& tick, bool paused) = 0;
  virtual RunEnd stop() = 0;
  virtual std::uint64_t cycles() const = 0;
  // An external command's exit status and output (ExitStatus, Output); null for ours.
  virtual const CommandFacts* command() const { return nullptr; }
  // Lines the report adds after the log (an external command's last output lines).
  virtual std::vector<std::string> trailer() const { return {}; }
  // Why the run could not be carried out to its end (interrupted, the simulator stopped).
  virtual std::string error() const { return {}; }
};

std::unique_ptr<MasterUnderTest> makeInProcessMaster(RunContext& context);
std::unique_ptr<MasterUnderTest> makeVethMaster(RunContext& context);
std::unique_ptr<MasterUnderTest> makeExternalMaster(RunContext& context);

// SCHED_FIFO for the calling thread while it lives (answers must come within a master's
// timeout, SOEM: 2 ms, even on a busy host); the previous policy is restored at the end.
class RealtimeScheduling {
 public:
  RealtimeScheduling() = default;
  RealtimeScheduling(const RealtimeScheduling&) = delete;
  RealtimeScheduling& operator=(const RealtimeScheduling&) = delete;
  ~RealtimeScheduling();
  // Empty, or a note saying why it was not permitted.
  std::string enable();

 private:
  bool enabled_{false};
  int policy_{0};
  int priority_{0};
};

}  // namespace ecsim::scenario
