// TapLink: a TAP device created (or attached to) through /dev/net/tun. Frames written to the
// device fd appear as received on the interface; frames the kernel transmits on the interface
// are read from the fd. Only EtherCAT frames (EtherType 0x88A4) are handed to the caller:
// everything else the kernel emits on the interface (IPv6 router solicitations, MLD, ...) is
// counted and dropped. The device is brought up on open and disappears when the link closes
// (it is not made persistent). Needs CAP_NET_ADMIN.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "link/fd.hpp"
#include "link/link.hpp"

namespace ecsim {

struct TapOptions {
  // Create the device inside this named network namespace (/var/run/netns/NAME). Empty: the
  // calling thread's namespace.
  std::string netns;
  bool bringUp{true};
};

class TapLink final : public Link {
 public:
  // name: the device to create or attach to; empty lets the kernel choose ("tap0", ...).
  // Errors: kNotFound when /dev/net/tun is missing, kPermission when opening it or creating
  // the device is refused (naming CAP_NET_ADMIN), kInvalidArgument for a bad name.
  static Result<TapLink> open(std::string_view name, const TapOptions& options = {});

  TapLink(TapLink&&) noexcept = default;
  TapLink& operator=(TapLink&&) noexcept = default;
  ~TapLink() override = default;

  Status send(ConstBytes frame) override;
  Result<std::size_t> receive(Bytes buffer, std::chrono::nanoseconds timeout) override;
  int pollFd() const override { return fd_.get(); }
  std::string describe() const override;

  // The device name the kernel gave (equal to the requested one when one was given).
  const std::string& interfaceName() const { return name_; }
  // Frames read from the device that were not EtherCAT and were dropped.
  std::uint64_t droppedNonEtherCat() const { return droppedNonEtherCat_; }

 private:
  TapLink() = default;

  UniqueFd fd_;
  std::string name_;
  std::string netns_;
  std::vector<std::uint8_t> scratch_;  // one read, sized once for the largest TAP frame
  std::uint64_t droppedNonEtherCat_{0};
};

}  // namespace ecsim
