#include "master/bus.hpp"

#include <poll.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <ctime>
#include <string>

namespace ecsim::master {
namespace {

// Without a file descriptor to sleep on, a real-time wait sleeps in slices this long.
constexpr SimTime kSleepSlice = 100 * kNsPerUs;

timespec toTimespec(SimTime ns) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(ns / kNsPerSecond);
  ts.tv_nsec = static_cast<long>(ns % kNsPerSecond);
  return ts;
}

}  // namespace

void RealTimeBus::wait(SimTime deadline) {
  const SimTime remaining = deadline - clock_.now();
  if (remaining <= 0) return;
  const int fd = link_.pollFd();
  const int secondFd = second_ != nullptr ? second_->pollFd() : -1;
  if (fd >= 0 && (second_ == nullptr || secondFd >= 0)) {
    std::array<pollfd, 2> p{pollfd{fd, POLLIN, 0}, pollfd{secondFd, POLLIN, 0}};
    const timespec ts = toTimespec(remaining);
    // EINTR: return early, the caller loops.
    (void)::ppoll(p.data(), second_ != nullptr ? 2 : 1, &ts, nullptr);
    return;
  }
  const timespec ts = toTimespec(std::min(remaining, kSleepSlice));
  (void)::nanosleep(&ts, nullptr);
}

void VirtualBus::wait(SimTime deadline) {
  const SimTime now = clock_.now();
  // Every frame waiting went out together and travels the network at the same time (frames
  // follow each other through a line, they do not wait for each other's round trip): all are
  // served, and the clock moves to the latest return.
  SimTime latest = 0;
  bool served = false;
  while (auto roundTrip = peer_(now)) {
    latest = std::max(latest, *roundTrip);
    served = true;
  }
  if (served) {
    clock_.advance(std::max<SimTime>(1, latest));
    return;
  }
  if (deadline > now) {
    clock_.set(deadline);
    (void)peer_(deadline);  // the firmware runs at the new time
  }
}

Status runTask(Task& task, Transport& transport, Bus& bus, SimTime timeout, std::string_view what) {
  const SimTime start = bus.now();
  for (;;) {
    const SimTime now = bus.now();
    transport.poll(now);
    const bool running = task.step(now);
    transport.flush(now);  // send what the step queued; answers wait for the next poll
    if (!running) return okStatus();
    const SimTime deadline =
        start + static_cast<SimTime>(static_cast<double>(timeout) * task.timeoutScale());
    if (now >= deadline) {
      return makeError(ErrorCode::kTimeout, std::string(what) + ": not finished after " +
                                                std::to_string((now - start) / kNsPerMs) + " ms");
    }
    SimTime next = deadline;
    if (auto t = transport.nextDeadline()) next = std::min(next, *t);
    if (auto t = task.wakeAt()) next = std::min(next, *t);
    bus.wait(std::max(next, now));
  }
}

}  // namespace ecsim::master
