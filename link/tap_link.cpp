#include "link/tap_link.hpp"

#include <fcntl.h>
#include <linux/if_tun.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "link/net_namespace.hpp"
#include "protocol/ethernet.hpp"

namespace ecsim {
namespace {

constexpr const char* kTunDevice = "/dev/net/tun";
// Largest frame a TAP device can hand out: 65535-byte MTU, Ethernet header and a VLAN tag.
constexpr std::size_t kTapScratchSize = 65535 + kEthernetHeaderSize + kVlanTagSize;

std::string where(std::string_view name, std::string_view netns) {
  std::string s = "TAP device '" + std::string(name) + "'";
  if (!netns.empty()) s += " in network namespace '" + std::string(netns) + "'";
  return s;
}

Status bringInterfaceUp(const std::string& name, const std::string& place) {
  UniqueFd control(::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0));
  if (!control.valid()) control.reset(::socket(AF_INET6, SOCK_DGRAM | SOCK_CLOEXEC, 0));
  if (!control.valid()) {
    return makeError(ErrorCode::kIo,
                     "control socket to bring up " + place + ": " + errnoText(errno));
  }
  ifreq ifr{};
  std::memcpy(ifr.ifr_name, name.data(), name.size());
  if (::ioctl(control.get(), SIOCGIFFLAGS, &ifr) != 0) {
    return makeError(ErrorCode::kIo, "SIOCGIFFLAGS on " + place + ": " + errnoText(errno));
  }
  ifr.ifr_flags = static_cast<short>(ifr.ifr_flags | IFF_UP);
  if (::ioctl(control.get(), SIOCSIFFLAGS, &ifr) != 0) {
    const int err = errno;
    if (err == EPERM || err == EACCES) {
      return makeError(ErrorCode::kPermission,
                       "bringing up " + place + " needs CAP_NET_ADMIN: " + errnoText(err));
    }
    return makeError(ErrorCode::kIo, "SIOCSIFFLAGS on " + place + ": " + errnoText(err));
  }
  return okStatus();
}

}  // namespace

Result<TapLink> TapLink::open(std::string_view name, const TapOptions& options) {
  if (name.size() >= IFNAMSIZ) {
    return makeError(ErrorCode::kInvalidArgument, "TAP name '" + std::string(name) +
                                                      "' is longer than " +
                                                      std::to_string(IFNAMSIZ - 1) + " characters");
  }
  TapLink link;
  link.netns_ = options.netns;
  ECSIM_TRY(runInNetworkNamespace(options.netns, [&]() -> Status {
    // The device is created in the namespace of the thread that issues TUNSETIFF.
    link.fd_.reset(::open(kTunDevice, O_RDWR | O_CLOEXEC | O_NONBLOCK));
    if (!link.fd_.valid()) {
      const int err = errno;
      if (err == ENOENT || err == ENODEV || err == ENXIO) {
        return makeError(ErrorCode::kNotFound,
                         std::string(kTunDevice) +
                             " is missing (load the tun module, or pass the device into the "
                             "container): " +
                             errnoText(err));
      }
      if (err == EACCES || err == EPERM) {
        return makeError(ErrorCode::kPermission, std::string("opening ") + kTunDevice +
                                                     " was refused (needs access to the "
                                                     "device and CAP_NET_ADMIN): " +
                                                     errnoText(err));
      }
      return makeError(ErrorCode::kIo,
                       std::string("opening ") + kTunDevice + ": " + errnoText(err));
    }
    ifreq ifr{};
    ifr.ifr_flags = IFF_TAP | IFF_NO_PI;
    std::memcpy(ifr.ifr_name, name.data(), name.size());
    if (::ioctl(link.fd_.get(), TUNSETIFF, &ifr) != 0) {
      const int err = errno;
      const std::string place = where(name, options.netns);
      if (err == EPERM || err == EACCES) {
        return makeError(ErrorCode::kPermission,
                         "creating " + place + " needs CAP_NET_ADMIN: " + errnoText(err));
      }
      return makeError(ErrorCode::kIo, "TUNSETIFF for " + place + ": " + errnoText(err));
    }
    link.name_ = std::string(ifr.ifr_name, ::strnlen(ifr.ifr_name, IFNAMSIZ));
    if (options.bringUp) return bringInterfaceUp(link.name_, where(link.name_, options.netns));
    return okStatus();
  }));
  link.scratch_.resize(kTapScratchSize);
  return link;
}

Status TapLink::send(ConstBytes frame) {
  if (frame.size() < kEthernetHeaderSize || frame.size() > kMaxFrameSize) {
    return makeError(
        frame.size() > kMaxFrameSize ? ErrorCode::kTooLarge : ErrorCode::kInvalidArgument,
        describe() + ": frame of " + std::to_string(frame.size()) + " bytes (allowed " +
            std::to_string(kEthernetHeaderSize) + " to " + std::to_string(kMaxFrameSize) + ")");
  }
  for (;;) {
    const ssize_t n = ::write(fd_.get(), frame.data(), frame.size());
    if (n == static_cast<ssize_t>(frame.size())) return okStatus();
    if (n >= 0) {
      return makeError(ErrorCode::kIo, describe() + ": short write of " + std::to_string(n) +
                                           " of " + std::to_string(frame.size()) + " bytes");
    }
    if (errno == EINTR) continue;
    return makeError(ErrorCode::kIo, describe() + ": write: " + errnoText(errno));
  }
}

Result<std::size_t> TapLink::receive(Bytes buffer, std::chrono::nanoseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    const ssize_t n = ::read(fd_.get(), scratch_.data(), scratch_.size());
    if (n > 0) {
      const auto length = static_cast<std::size_t>(n);
      const ConstBytes frame(scratch_.data(), length);
      if (length < kEthernetHeaderSize || readBe16(frame, 12) != kEtherTypeEtherCat) {
        ++droppedNonEtherCat_;
        continue;
      }
      if (length > buffer.size()) {
        return makeError(ErrorCode::kTooLarge, describe() + ": frame of " + std::to_string(length) +
                                                   " bytes exceeds receive buffer of " +
                                                   std::to_string(buffer.size()) +
                                                   " bytes, frame dropped");
      }
      std::memcpy(buffer.data(), frame.data(), length);
      return length;
    }
    if (n < 0 && errno == EINTR) return std::size_t{0};
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK) {
      return makeError(ErrorCode::kIo, describe() + ": read: " + errnoText(errno));
    }
    const auto left = deadline - std::chrono::steady_clock::now();
    if (left <= std::chrono::nanoseconds::zero()) return std::size_t{0};
    ECSIM_ASSIGN_OR_RETURN(
        const bool readable,
        waitReadable(fd_.get(), std::chrono::duration_cast<std::chrono::nanoseconds>(left)));
    if (!readable) return std::size_t{0};
  }
}

std::string TapLink::describe() const {
  return where(name_, netns_);
}

}  // namespace ecsim
