// A bounded wait for readability, for the links (the owning descriptor and errno text are in
// protocol/unique_fd.hpp). waitReadable() does not allocate.
#pragma once

#include <chrono>
#include "protocol/result.hpp"
#include "protocol/unique_fd.hpp"

namespace ecsim {

// Waits until fd is readable or timeout passes (zero or negative: just look). Returns true
// when readable, false on timeout or when a signal interrupted the wait (so that a caller's
// loop can look at its SignalFlag promptly).
Result<bool> waitReadable(int fd, std::chrono::nanoseconds timeout);

}  // namespace ecsim
