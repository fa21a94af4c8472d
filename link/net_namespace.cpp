#include "link/net_namespace.hpp"

#include <fcntl.h>
#include <sched.h>

#include <cerrno>

#include "link/fd.hpp"

namespace ecsim {

std::string netnsPath(std::string_view name) {
  return std::string(kNetnsRunDir) + "/" + std::string(name);
}

Status runInNetworkNamespace(std::string_view name, const std::function<Status()>& fn) {
  if (name.empty()) return fn();
  if (name.find('/') != std::string_view::npos || name == "." || name == "..") {
    return makeError(ErrorCode::kInvalidArgument,
                     "network namespace name '" + std::string(name) + "' is not a plain name");
  }
  UniqueFd original(::open("/proc/thread-self/ns/net", O_RDONLY | O_CLOEXEC));
  if (!original.valid()) {
    return makeError(ErrorCode::kIo, "opening /proc/thread-self/ns/net: " + errnoText(errno));
  }
  const std::string path = netnsPath(name);
  UniqueFd target(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
  if (!target.valid()) {
    const int err = errno;
    if (err == ENOENT) {
      return makeError(ErrorCode::kNotFound, "network namespace '" + std::string(name) +
                                                 "' does not exist (" + path + ")");
    }
    if (err == EACCES || err == EPERM) {
      return makeError(ErrorCode::kPermission, "opening " + path + ": " + errnoText(err));
    }
    return makeError(ErrorCode::kIo, "opening " + path + ": " + errnoText(err));
  }
  if (::setns(target.get(), CLONE_NEWNET) != 0) {
    const int err = errno;
    if (err == EPERM) {
      return makeError(ErrorCode::kPermission, "entering network namespace '" + std::string(name) +
                                                   "' needs CAP_SYS_ADMIN: " + errnoText(err));
    }
    return makeError(ErrorCode::kIo, "setns into " + path + ": " + errnoText(err));
  }
  Status result = fn();
  if (::setns(original.get(), CLONE_NEWNET) != 0) {
    return makeError(ErrorCode::kIo, "could not return from network namespace '" +
                                         std::string(name) +
                                         "', thread left inside it: " + errnoText(errno));
  }
  return result;
}

}  // namespace ecsim
