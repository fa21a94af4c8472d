#include "topology/network_server.hpp"

#include <algorithm>
#include <thread>

namespace ecsim::topology {
namespace {

// A paced wait sleeps in slices of at most this (looking at the stop callback after each)
// until kPacedSpin is left, which it spins so that the answer leaves on time.
constexpr SimTime kPacedSlice = kNsPerMs;
constexpr SimTime kPacedSpin = 200 * kNsPerUs;

}  // namespace

NetworkServer::NetworkServer(Link& link, Segment& segment, const Clock& clock,
                             ServerOptions options)
    : link_(link), segment_(segment), clock_(clock), options_(options) {}

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

Status NetworkServer::step(const std::function<bool()>& stop) {
  // A firmware run put off: the wait for the next frame ends when it is due, so that the
  // last frame of a burst is followed by the firmware's reaction as promptly as before.
  std::chrono::nanoseconds wait = options_.idleWait;
  if (firmwarePending_) {
    wait = std::clamp(std::chrono::nanoseconds(firmwareDueAt() - clock_.now()),
                      std::chrono::nanoseconds::zero(), options_.idleWait);
  }
  auto received = link_.receive(buffer_, wait);
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
  FrameOutcome outcome = segment_.processFrame(frame, now);
  if (!outcome.delivered) {
    ++counters_.framesDropped;
    // A malformed frame is left as it came (the segment refuses it before changing a byte).
    if (options_.malformedObserver != nullptr &&
        segment_.counters().framesMalformed != malformedBefore) {
      options_.malformedObserver->onFrame(frame, now, true);
    }
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
  if (auto sent = link_.send(frame); !sent.ok()) {
    ++counters_.sendErrors;
  } else {
    ++counters_.framesAnswered;
  }
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
