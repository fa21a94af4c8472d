// The blocking convenience layer over the step-driven core. A Task is a non-blocking state
// machine (IgH's fsm_* discipline): step(now) looks at its datagrams, queues new ones and
// says whether it is still running. runTask() loops poll/step and lets time pass through a
// Bus between iterations:
//
//   RealTimeBus  a real clock; waiting means sleeping on the link's file descriptor until a
//                frame arrives or the next deadline (for RawSocketLink on an interface);
//   VirtualBus   a VirtualClock; waiting means letting the network at the other end of the
//                link serve every frame we sent (for an in-process simulator: NetworkServer
//                steps) and moving the clock by the longest round trip it reports (frames in
//                flight together pass the slaves together, as on a wire), or to the deadline
//                when nothing was waiting.
//
// The same master code therefore runs against MemoryLink + an in-process simulator on
// virtual time in tests and against a raw socket on real time in the tool.
#pragma once

#include <functional>
#include <optional>

#include "link/link.hpp"
#include "master/transport.hpp"
#include "protocol/result.hpp"
#include "protocol/time.hpp"

namespace ecsim::master {

class Bus {
 public:
  virtual ~Bus() = default;
  virtual SimTime now() const = 0;
  // Lets time pass until `deadline` at the latest; returns earlier when a frame may be waiting.
  virtual void wait(SimTime deadline) = 0;
};

class RealTimeBus final : public Bus {
 public:
  // link, clock and `second` must outlive the bus. `second`: the master's second port (cable
  // redundancy), whose frames end a wait too; null: none.
  RealTimeBus(Link& link, const Clock& clock, Link* second = nullptr)
      : link_(link), clock_(clock), second_(second) {}
  SimTime now() const override { return clock_.now(); }
  void wait(SimTime deadline) override;

 private:
  Link& link_;
  const Clock& clock_;
  Link* second_;
};

class VirtualBus final : public Bus {
 public:
  // Serves at most one frame waiting at the far end of the link at time `now` and returns
  // its round trip, or nullopt when nothing was waiting (the peer may still run its firmware).
  // wait() calls it until nothing is waiting.
  using Peer = std::function<std::optional<SimTime>(SimTime now)>;

  VirtualBus(VirtualClock& clock, Peer peer) : clock_(clock), peer_(std::move(peer)) {}
  SimTime now() const override { return clock_.now(); }
  void wait(SimTime deadline) override;

 private:
  VirtualClock& clock_;
  Peer peer_;
};

class Task {
 public:
  virtual ~Task() = default;
  // Advances the state machine; true while it is still running. Never blocks.
  virtual bool step(SimTime now) = 0;
  // When the task wants to run again even if no answer arrives (poll intervals); nullopt:
  // only when one of its datagrams is answered or times out.
  virtual std::optional<SimTime> wakeAt() const { return std::nullopt; }
  // How many times the caller's timeout the task may take, learned while it runs: the scan
  // learns from its count how much longer than usual this network's frames take.
  virtual double timeoutScale() const { return 1.0; }
};

// Steps `task` and the transport until the task finishes (ok) or `timeout` (times the task's
// timeoutScale()) has passed on the bus clock (kTimeout naming `what`). The task's own outcome is
// read from the task.
Status runTask(Task& task, Transport& transport, Bus& bus, SimTime timeout,
               std::string_view what = "task");

}  // namespace ecsim::master
