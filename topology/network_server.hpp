// Serves a Segment on a Link: every EtherCAT frame the master sends is carried through the
// simulated network and sent back, processed, on the same link. Malformed frames are dropped
// and counted, never answered. In paced mode a frame goes back only when its modelled return
// time has come on the injected clock, so an external master sees realistic round trips.
// A paced wait is bounded: a frame whose modelled return lies more than maxPacedWait after it
// arrived (a delay spike, docs/scenarios.md) is not answered and counted as late, as a real
// master sees such a frame: lost, its timeout long past. While an answer is held, run()'s stop
// callback is consulted at least every millisecond (the serve loop's signal flag and control
// socket), and a raised stop ends the wait without answering.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>

#include "link/link.hpp"
#include "protocol/ethernet.hpp"
#include "protocol/time.hpp"
#include "topology/segment.hpp"

namespace ecsim::topology {

struct ServerOptions {
  bool paced{false};
  // How long one step waits for a frame before running the slaves' firmware anyway.
  std::chrono::nanoseconds idleWait{std::chrono::milliseconds(1)};
  // Paced mode: the longest an answer is held.
  std::chrono::nanoseconds maxPacedWait{std::chrono::seconds(1)};
  // The slaves' firmware (Segment::pollSlaves) off the answers' path. 0: it runs after every
  // frame. N > 0: after a frame it runs only when the time since its last run (on the clock)
  // is at least N times what that run took, so that while frames come back to back it takes
  // at most 1/(N+1) of the server's time and most frames find the server waiting for them,
  // not busy with the firmware (as a real ESC's frame path does not wait for its PDI side).
  // It always runs when the wait for a frame ends empty, and a run put off ends the wait
  // for the next frame when it is due. A clock that does not advance while
  // the firmware runs (virtual time) makes every run due: the same as 0.
  unsigned firmwareSpacing{0};
  // Between frames, while none is there, ask the cache for the ESCs' state ahead of the next
  // frame (Segment::prefetchForNextFrame), a group at a time, looking at the link between
  // groups; a frame that arrives ends the pass. Only for a link that looks without a system
  // call (a RawSocketLink with busyPoll, `ecsim serve --busy-poll`): otherwise each look
  // would undo what the pass brought in.
  bool prefetchWhileIdle{false};
  // Sees every malformed frame the server drops, as received, stamped with the clock's time
  // (`ecsim serve --pcap-malformed`). Not owned; null: none.
  CableObserver* malformedObserver{nullptr};
};

struct ServerCounters {
  std::uint64_t framesReceived{0};
  std::uint64_t framesAnswered{0};
  std::uint64_t framesDropped{0};  // malformed: not answered
  std::uint64_t framesLost{0};     // lost in the network (a pulled cable, an injected loss)
  std::uint64_t framesLate{0};     // paced: modelled return beyond maxPacedWait, not answered
  std::uint64_t receiveErrors{0};
  std::uint64_t sendErrors{0};
  SimTime lastRoundTrip{0};
};

class NetworkServer {
 public:
  NetworkServer(Link& link, Segment& segment, const Clock& clock, ServerOptions options = {});

  // Cable redundancy: the master's second port (Segment::setRedundantPort). Frames from either
  // link enter the network at that master port and go back out of the link at the master port
  // they leave the network at (on a whole ring, the other one). The redundant port's link
  // comes up: a master port is wired to it now. Not owned; null: none.
  void setRedundantLink(Link* link);

  // Waits up to the idle wait for one frame, processes and answers it, runs the firmware.
  Status step();
  // Steps until stop() returns true; stop() is also consulted during a paced wait.
  Status run(const std::function<bool()>& stop);

  const ServerCounters& counters() const { return counters_; }

 private:
  Link& link_;
  Link* redundant_{nullptr};
  bool redundantFirst_{false};  // which link is looked at first (they take turns)
  Segment& segment_;
  // A frame from either link (redundancy): its length, and the master port it came from.
  Result<std::size_t> receiveEither(std::chrono::nanoseconds wait, MasterPort& from);
  Status step(const std::function<bool()>& stop);
  // Waits up to `wait` for one frame, answers it and runs the firmware.
  Status answer(std::chrono::nanoseconds wait, const std::function<bool()>& stop);
  // prefetchWhileIdle: a frame already there, else the rest of the pass over the ESCs a
  // group at a time while none comes, then the wait.
  Result<std::size_t> receiveWhilePrefetching(std::chrono::nanoseconds wait);
  // Paced: holds until `t` on the clock; false when stop() was raised first.
  bool waitUntil(SimTime t, const std::function<bool()>& stop);
  // Runs the firmware now, or (firmwareSpacing) only when it is due; `idle`: always.
  void runFirmware(bool idle);
  SimTime firmwareDueAt() const;

  const Clock& clock_;
  ServerOptions options_;
  ServerCounters counters_{};
  SimTime firmwareDoneAt_{0};    // when the last firmware run ended
  SimTime firmwareTook_{0};      // how long it took
  bool firmwarePending_{false};  // a run was put off
  std::size_t prefetchNext_{SIZE_MAX};  // the next ESC of the pass (SIZE_MAX: none under way)
  std::array<std::uint8_t, kMaxFrameSize> buffer_{};
};

}  // namespace ecsim::topology
