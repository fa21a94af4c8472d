// Small POSIX helpers shared by the links: an owning file descriptor, errno text, and a
// bounded wait for readability. Off the cyclic path except waitReadable(), which does not
// allocate.
#pragma once

#include <chrono>
#include <string>
#include <utility>

#include "protocol/result.hpp"

namespace ecsim {

// Owns one file descriptor and closes it on destruction. Move-only.
class UniqueFd {
 public:
  UniqueFd() = default;
  explicit UniqueFd(int fd) : fd_(fd) {}
  UniqueFd(UniqueFd&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}
  UniqueFd& operator=(UniqueFd&& other) noexcept {
    if (this != &other) {
      reset();
      fd_ = std::exchange(other.fd_, -1);
    }
    return *this;
  }
  UniqueFd(const UniqueFd&) = delete;
  UniqueFd& operator=(const UniqueFd&) = delete;
  ~UniqueFd() { reset(); }

  int get() const { return fd_; }
  bool valid() const { return fd_ >= 0; }
  int release() { return std::exchange(fd_, -1); }
  void reset(int fd = -1);

 private:
  int fd_{-1};
};

// "Operation not permitted (errno 1)".
std::string errnoText(int err);

// Waits until fd is readable or timeout passes (zero or negative: just look). Returns true
// when readable, false on timeout or when a signal interrupted the wait (so that a caller's
// loop can look at its SignalFlag promptly).
Result<bool> waitReadable(int fd, std::chrono::nanoseconds timeout);

}  // namespace ecsim
