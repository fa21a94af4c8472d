#include "topology/network_server.hpp"

#include <poll.h>
#include <time.h>

#include <algorithm>
#include <thread>

namespace ecsim::topology {
namespace {

// A paced wait sleeps in slices of at most this (looking at the stop callback after each)
// until kPacedSpin is left, which it spins so that the answer leaves on time.
constexpr SimTime kPacedSlice = kNsPerMs;
constexpr SimTime kPacedSpin = 200 * kNsPerUs;
// Redundancy: frames that one step answers besides the first, each coming within kPairWait of
// the one before.
constexpr int kRedundantBurst = 8;
constexpr std::chrono::nanoseconds kPairWait = std::chrono::microseconds(200);
// ESCs fetched ahead between two looks at the link (prefetchWhileIdle): about 0.2 us of work
// at 7 ns each, all a frame arriving meanwhile waits.
constexpr std::size_t kPrefetchGroup = 32;

}  // namespace

NetworkServer::NetworkServer(Link& link, Segment& segment, const Clock& clock,
                             ServerOptions options)
    : link_(link), segment_(segment), clock_(clock), options_(options) {}

void NetworkServer::setRedundantLink(Link* link) {
  redundant_ = link;
  if (link != nullptr && segment_.redundant()) {
    segment_.setLinkUp(segment_.redundantSlave(), segment_.redundantPortNumber(), true);
  }
}

Status NetworkServer::step() {
  return step(std::function<bool()>());
}

bool NetworkServer::waitUntil(SimTime t, const std::function<bool()>& stop) {
  while (true) {
    const SimTime left = t - clock_.now();
    if (left <= 0) return true;
    if (left > kPacedSpin) {
      std::this_thread::sleep_for(
          std::chrono::nanoseconds(std::min(left - kPacedSpin, kPacedSlice)));
      if (stop && stop()) return false;
    }
  }
}

SimTime NetworkServer::firmwareDueAt() const {
  return firmwareDoneAt_ + static_cast<SimTime>(options_.firmwareSpacing) * firmwareTook_;
}

void NetworkServer::runFirmware(bool idle) {
  const SimTime start = clock_.now();
  if (!idle && options_.firmwareSpacing != 0 && start < firmwareDueAt()) {
    firmwarePending_ = true;
    return;
  }
  segment_.pollSlaves(start);
  firmwarePending_ = false;
  firmwareDoneAt_ = clock_.now();
  firmwareTook_ = firmwareDoneAt_ - start;
}

Result<std::size_t> NetworkServer::receiveEither(std::chrono::nanoseconds wait, MasterPort& from) {
  redundantFirst_ = !redundantFirst_;
  Link* order[2] = {&link_, redundant_};
  if (redundantFirst_) std::swap(order[0], order[1]);
  auto take = [&](Link* l, std::chrono::nanoseconds w) -> Result<std::size_t> {
    from = l == &link_ ? MasterPort::kPrimary : MasterPort::kSecondary;
    return l->receive(buffer_, w);
  };
  for (Link* l : order) {  // a frame already waiting
    auto r = take(l, std::chrono::nanoseconds::zero());
    if (!r.ok() || *r != 0) return r;
  }
  const int fds[2] = {order[0]->pollFd(), order[1]->pollFd()};
  if (fds[0] < 0 || fds[1] < 0) {  // links without a descriptor: half the wait on each
    auto r = take(order[0], wait / 2);
    if (!r.ok() || *r != 0) return r;
    return take(order[1], wait / 2);
  }
  pollfd p[2] = {{fds[0], POLLIN, 0}, {fds[1], POLLIN, 0}};
  const timespec ts{static_cast<time_t>(wait.count() / kNsPerSecond),
                    static_cast<long>(wait.count() % kNsPerSecond)};
  if (::ppoll(p, 2, &ts, nullptr) <= 0) return std::size_t{0};  // nothing, or a signal
  for (int i = 0; i < 2; ++i) {
    if ((p[i].revents & POLLIN) == 0) continue;
    auto r = take(order[i], std::chrono::nanoseconds::zero());
    if (!r.ok() || *r != 0) return r;
  }
  return std::size_t{0};
}

Result<std::size_t> NetworkServer::receiveWhilePrefetching(std::chrono::nanoseconds wait) {
  for (;;) {
    auto r = link_.receive(buffer_, std::chrono::nanoseconds::zero());
    if (!r.ok() || *r != 0) return r;
    if (prefetchNext_ >= segment_.size()) {
      prefetchNext_ = SIZE_MAX;
      return link_.receive(buffer_, wait);
    }
    prefetchNext_ = segment_.prefetchForNextFrame(prefetchNext_, kPrefetchGroup);
  }
}

Status NetworkServer::step(const std::function<bool()>& stop) {
  // A firmware run put off: the wait for the next frame ends when it is due, so that the
  // last frame of a burst is followed by the firmware's reaction as promptly as before.
  std::chrono::nanoseconds wait = options_.idleWait;
  if (firmwarePending_) {
    wait = std::clamp(std::chrono::nanoseconds(firmwareDueAt() - clock_.now()),
                      std::chrono::nanoseconds::zero(), options_.idleWait);
  }
  if (redundant_ == nullptr) return answer(wait, stop);
  // Redundancy: a redundant master sends the two frames of a cycle back to back, one at each
  // port; they are on the wire together. The frames following within kPairWait are answered
  // before the step ends (and the caller looks at its control socket), so that a fault is not
  // applied between the two: it would cut the ring between frames that travel together (a
  // cable pulled in that instant destroys a frame on hardware too, but there the window is the
  // frames' few microseconds, here the server's whole turn, and the master's time apart).
  const std::uint64_t before = counters_.framesReceived;
  ECSIM_TRY(answer(wait, stop));
  for (int more = 0; more < kRedundantBurst && counters_.framesReceived != before; ++more) {
    const std::uint64_t got = counters_.framesReceived;
    ECSIM_TRY(answer(kPairWait, stop));
    if (counters_.framesReceived == got) break;
  }
  return okStatus();
}

Status NetworkServer::answer(std::chrono::nanoseconds wait, const std::function<bool()>& stop) {
  MasterPort from = MasterPort::kPrimary;
  auto received = redundant_ != nullptr          ? receiveEither(wait, from)
                  : prefetchNext_ != SIZE_MAX ? receiveWhilePrefetching(wait)
                                              : link_.receive(buffer_, wait);
  const SimTime now = clock_.now();
  if (!received.ok()) {
    ++counters_.receiveErrors;  // e.g. an oversize frame: dropped by the link
    runFirmware(false);
    return okStatus();
  }
  if (*received == 0) {
    runFirmware(true);
    return okStatus();
  }
  ++counters_.framesReceived;
  Bytes frame(buffer_.data(), *received);
  const std::uint64_t malformedBefore = segment_.counters().framesMalformed;
  FrameOutcome outcome = segment_.processFrame(frame, now, from);
  if (!outcome.delivered) {
    if (segment_.counters().framesMalformed == malformedBefore) {
      ++counters_.framesLost;  // well-formed, and it met a pulled cable or an injected loss
      return okStatus();
    }
    ++counters_.framesDropped;
    // A malformed frame is left as it came (the segment refuses it before changing a byte).
    if (options_.malformedObserver != nullptr)
      options_.malformedObserver->onFrame(frame, now, true);
    return okStatus();
  }
  counters_.lastRoundTrip = outcome.returnTime - now;
  if (options_.paced) {
    if (outcome.returnTime - now > options_.maxPacedWait.count()) {
      ++counters_.framesLate;
      runFirmware(false);
      return okStatus();
    }
    if (!waitUntil(outcome.returnTime, stop)) return okStatus();
  }
  Link& out = outcome.exit == MasterPort::kSecondary && redundant_ != nullptr ? *redundant_ : link_;
  if (auto sent = out.send(frame); !sent.ok()) {
    ++counters_.sendErrors;
  } else {
    ++counters_.framesAnswered;
  }
  if (options_.prefetchWhileIdle) prefetchNext_ = 0;
  // The firmware reacts after the frame has passed, as on hardware.
  runFirmware(false);
  return okStatus();
}

Status NetworkServer::run(const std::function<bool()>& stop) {
  while (!stop()) {
    ECSIM_TRY(step(stop));
  }
  return okStatus();
}

}  // namespace ecsim::topology
