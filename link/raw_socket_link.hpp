// RawSocketLink: an AF_PACKET raw socket on one network interface (a veth end, a TAP device
// or a real NIC); a socket filter lets only EtherCAT frames (EtherType 0x88A4, after an
// optional VLAN tag) arrive. Frames the
// socket sends itself are never received back (PACKET_IGNORE_OUTGOING where the kernel has
// it, and a check of sll_pkttype == PACKET_OUTGOING in any case). The interface is put in
// promiscuous mode through a packet-socket membership, which the kernel drops when the socket
// closes. An 802.1Q tag, which the kernel takes off received frames, is put back in place
// (PACKET_AUXDATA), so frames arrive as they were on the wire. Needs CAP_NET_RAW.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "link/fd.hpp"
#include "link/kernel_thread_sender.hpp"
#include "link/link.hpp"
#include "link/packet_rx_ring.hpp"
#include "protocol/ethernet.hpp"

struct msghdr;

namespace ecsim {

struct RawSocketOptions {
  // Create the socket inside this named network namespace (/var/run/netns/NAME); the socket
  // stays there while the calling thread returns to its own namespace. Empty: current one.
  std::string netns;
  bool promiscuous{true};
  // Send straight to the driver, past the interface's queueing discipline
  // (PACKET_QDISC_BYPASS): less work per frame, but other packet sockets on this interface
  // (a capture) do not see the frames sent. `ecsim serve` sets it: its answers are seen
  // where the master's end receives them.
  bool qdiscBypass{false};
  // receive() does not sleep: it looks at a receive ring shared with the kernel
  // (link/packet_rx_ring.hpp) again and again until a frame is there or the timeout has
  // passed. No wake-up and no system call on the answer's path, at the price of one core kept
  // busy all the time (for a dedicated core: `ecsim serve --busy-poll`).
  bool busyPoll{false};
  // send() leaves the system call to a kernel thread polling on this CPU
  // (link/kernel_thread_sender.hpp): with busyPoll, the calling thread then never enters the
  // kernel between two frames. -1: send() calls send(2).
  int sendCpu{-1};
};

class RawSocketLink final : public Link {
 public:
  // Errors: kPermission (naming CAP_NET_RAW) when socket() is refused, kNotFound naming the
  // interface (and namespace) when it does not exist, kInvalidArgument for a bad name.
  static Result<RawSocketLink> open(std::string_view interface,
                                    const RawSocketOptions& options = {});

  RawSocketLink(RawSocketLink&&) noexcept = default;
  RawSocketLink& operator=(RawSocketLink&&) noexcept = default;
  ~RawSocketLink() override = default;

  // Frames must hold an Ethernet header and be at most kMaxFrameSize bytes; the kernel sends
  // them as they are (no padding is added on virtual interfaces).
  Status send(ConstBytes frame) override;
  Result<std::size_t> receive(Bytes buffer, std::chrono::nanoseconds timeout) override;
  int pollFd() const override { return fd_.get(); }
  std::string describe() const override;

  const std::string& interfaceName() const { return interface_; }
  int interfaceIndex() const { return ifindex_; }
  const MacAddress& macAddress() const { return mac_; }
  // True when the kernel itself drops our outgoing frames (PACKET_IGNORE_OUTGOING, Linux
  // >= 4.20); otherwise receive() skips them by their packet type.
  bool kernelIgnoresOutgoing() const { return kernelIgnoresOutgoing_; }
  // Own frames that reached receive() and were skipped (only without kernel support).
  std::uint64_t outgoingSkipped() const { return outgoingSkipped_; }
  // True when frames arrive through a receive ring (busyPoll): receive() with a zero timeout
  // is then a look at memory, not a system call.
  bool receivesWithoutSystemCalls() const { return ring_.has_value(); }
  // The sending thread (sendCpu), if any.
  const KernelThreadSender* kernelThreadSender() const { return sender_ ? &*sender_ : nullptr; }

 private:
  RawSocketLink() = default;
  // Puts back the 802.1Q tag the kernel took off (reported in PACKET_AUXDATA).
  Result<std::size_t> restoreVlanTag(const msghdr& message, Bytes buffer, std::size_t length) const;
  // Inserts `tpid` (0: 0x8100) and `tci` after the addresses of the `length` bytes in buffer.
  Result<std::size_t> insertVlanTag(Bytes buffer, std::size_t length, std::uint16_t tpid,
                                    std::uint16_t tci) const;
  // receive() through the ring (busyPoll).
  Result<std::size_t> receiveFromRing(Bytes buffer, std::chrono::nanoseconds timeout);
  // Copies the ring's front frame into buffer (its tag put back): 0 when it is not for us.
  Result<std::size_t> takeFromRing(const PacketRxRing::Frame& frame, Bytes buffer);
  // SO_RCVTIMEO, set only when it differs from the last one set.
  Status setReceiveTimeout(std::chrono::nanoseconds timeout);

  UniqueFd fd_;
  std::string interface_;
  std::string netns_;
  int ifindex_{0};
  MacAddress mac_{};
  bool kernelIgnoresOutgoing_{false};
  std::uint64_t outgoingSkipped_{0};
  std::optional<PacketRxRing> ring_;            // busyPoll: every frame arrives here
  std::optional<KernelThreadSender> sender_;    // sendCpu: every frame leaves through it
  std::chrono::nanoseconds receiveTimeout_{0};  // 0: none set (the socket waits for ever)
};

}  // namespace ecsim
