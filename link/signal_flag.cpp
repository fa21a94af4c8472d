#include "link/signal_flag.hpp"

#include <atomic>

namespace ecsim {
namespace {

// The one piece of process-wide mutable state in link/ (see signal_flag.hpp): written by the
// signal handler, read by SignalFlag. Lock-free atomics are safe to use in a handler.
std::atomic<int> gCaughtSignal{0};
static_assert(std::atomic<int>::is_always_lock_free);

void onStopSignal(int caught) {
  gCaughtSignal.store(caught, std::memory_order_relaxed);
}

}  // namespace

SignalFlag::SignalFlag(std::initializer_list<int> signals) {
  gCaughtSignal.store(0, std::memory_order_relaxed);
  for (int sig : signals) {
    struct sigaction action {};
    action.sa_handler = onStopSignal;
    sigemptyset(&action.sa_mask);
    action.sa_flags = static_cast<int>(SA_RESETHAND);  // no SA_RESTART: blocking waits return early
    Saved saved{sig, {}};
    if (::sigaction(sig, &action, &saved.previous) == 0) saved_.push_back(saved);
  }
}

SignalFlag::~SignalFlag() {
  for (const Saved& saved : saved_) ::sigaction(saved.number, &saved.previous, nullptr);
}

int SignalFlag::signal() const {
  return gCaughtSignal.load(std::memory_order_relaxed);
}

void SignalFlag::clear() {
  gCaughtSignal.store(0, std::memory_order_relaxed);
}

}  // namespace ecsim
