// POSIX file helpers every library may use: an owning file descriptor, errno text, what
// kind of file a mode names, and a whole write. (link/fd.hpp adds the bounded wait the links need.)
#pragma once

#include <sys/types.h>

#include <string>
#include <utility>

#include "protocol/bytes.hpp"
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

// What a file that is not a regular one is, for error messages: "a FIFO", "a directory",
// "a character device", "a block device", "a socket", "a symbolic link", else
// "not a regular file".
const char* fileKindText(mode_t mode);

// Writes all of `data` to `fd`: write(2) until done, EINTR retried. On failure a kIo error
// "SHOWN: write failed: <errno text>", SHOWN naming the file (and what was being written).
Status writeAll(int fd, ConstBytes data, const std::string& shown);

}  // namespace ecsim
