// Entering a named network namespace (as made by `ip netns add NAME`, bound at
// /var/run/netns/NAME) for the duration of one call. Network namespaces are per thread, and a
// socket or TAP device keeps the namespace it was created in, so a link opened inside
// runInNetworkNamespace() keeps working there after the thread has switched back.
#pragma once

#include <functional>
#include <string>
#include <string_view>

#include "protocol/result.hpp"

namespace ecsim {

// Directory where iproute2 binds named network namespaces.
inline constexpr std::string_view kNetnsRunDir = "/var/run/netns";

// "/var/run/netns/NAME"; NAME must be a plain file name (checked by runInNetworkNamespace).
std::string netnsPath(std::string_view name);

// Moves the calling thread into network namespace `name`, runs fn, and moves it back. An
// empty name runs fn where the thread is. Errors: kNotFound (no such namespace), kPermission
// (setns needs CAP_SYS_ADMIN), kIo; otherwise fn's own status. If moving back fails the
// thread is left inside the namespace and the error says so.
Status runInNetworkNamespace(std::string_view name, const std::function<Status()>& fn);

}  // namespace ecsim
