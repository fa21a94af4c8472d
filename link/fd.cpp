#include "link/fd.hpp"

#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>

namespace ecsim {

Result<bool> waitReadable(int fd, std::chrono::nanoseconds timeout) {
  const auto ns = timeout.count() > 0 ? timeout.count() : 0;
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(ns / 1'000'000'000);
  ts.tv_nsec = static_cast<long>(ns % 1'000'000'000);
  pollfd pfd{};
  pfd.fd = fd;
  pfd.events = POLLIN;
  const int rc = ::ppoll(&pfd, 1, &ts, nullptr);
  if (rc < 0) {
    if (errno == EINTR) return false;
    return makeError(ErrorCode::kIo, "ppoll on fd " + std::to_string(fd) + ": " + errnoText(errno));
  }
  if (rc == 0) return false;
  if ((pfd.revents & (POLLERR | POLLNVAL)) != 0 && (pfd.revents & POLLIN) == 0) {
    return makeError(ErrorCode::kIo, "ppoll on fd " + std::to_string(fd) + ": error condition " +
                                         std::to_string(pfd.revents));
  }
  return true;
}

}  // namespace ecsim
