// For tests that a reader refuses a FIFO instead of blocking on it: runs the read on another
// thread; if it is still waiting for a writer after a while (the defect), a writer opens and
// closes the FIFO so that the read sees end-of-file and the test goes on to fail on the result
// rather than hang. The wait is only a bound against a hang, never what passes or fails.
#pragma once

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <future>
#include <utility>

namespace ecsim::testing {

inline bool makeFifo(const std::filesystem::path& path) {
  return ::mkfifo(path.c_str(), 0600) == 0;
}

template <typename Read>
auto readWithoutHanging(const std::filesystem::path& fifo, Read read) {
  auto result = std::async(std::launch::async, std::move(read));
  while (result.wait_for(std::chrono::seconds(5)) != std::future_status::ready) {
    const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd >= 0) ::close(fd);
  }
  return result.get();
}

}  // namespace ecsim::testing
