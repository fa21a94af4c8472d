// PacketRxRing: a receive ring shared with the kernel on an AF_PACKET socket (PACKET_RX_RING,
// TPACKET_V2, packet(7) and the kernel's Documentation/networking/packet_mmap.rst). The kernel
// copies each frame the socket accepts into the next slot and hands the slot over by setting
// its status word to TP_STATUS_USER; we read that word with an acquire load, take the frame
// and give the slot back by writing TP_STATUS_KERNEL. Looking for a frame is therefore a load,
// not a system call: a busy-polling server (`ecsim serve --busy-poll`) enters the kernel only
// to send. A frame that finds every slot taken is dropped by the kernel (counted in
// PACKET_STATISTICS, not here). Once a socket has a ring, recv() on it gets nothing: every
// frame goes to the ring. poll() on the socket says POLLIN while the front slot is ours.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "protocol/bytes.hpp"
#include "protocol/result.hpp"

namespace ecsim {

class PacketRxRing {
 public:
  // What the kernel wrote into one slot.
  struct Frame {
    ConstBytes data;            // as captured (the VLAN tag taken off, see vlanTci)
    std::size_t wireLength{0};  // the frame's length before capture (> data.size(): truncated)
    std::uint8_t packetType{0};  // sll_pkttype (PACKET_HOST, PACKET_OUTGOING, ...)
    std::uint16_t protocol{0};   // sll_protocol, host order
    std::optional<std::uint16_t> vlanTci;  // the 802.1Q tag the kernel took off, if any
    std::uint16_t vlanTpid{0};             // its TPID (0: the kernel did not say)
  };

  // Sets TPACKET_V2 and a ring of `slots` slots of 2048 bytes on `fd` (before bind(), so that
  // no frame queues outside it) and maps it. `where` names the socket in errors.
  static Result<PacketRxRing> attach(int fd, const std::string& where, std::size_t slots = 64);

  PacketRxRing(PacketRxRing&& other) noexcept;
  PacketRxRing& operator=(PacketRxRing&& other) noexcept;
  PacketRxRing(const PacketRxRing&) = delete;
  PacketRxRing& operator=(const PacketRxRing&) = delete;
  ~PacketRxRing();

  // The oldest frame not yet taken, if the kernel has handed one over. Stays valid until pop().
  std::optional<Frame> front() const;
  // Gives the front slot back to the kernel.
  void pop();

  // Bytes of a slot (the largest frame a slot holds is somewhat less: the slot's header).
  static constexpr std::size_t kSlotBytes = 2048;

 private:
  PacketRxRing() = default;
  std::uint8_t* slot(std::size_t i) const { return base_ + i * kSlotBytes; }

  std::uint8_t* base_{nullptr};
  std::size_t bytes_{0};
  std::size_t slots_{0};
  std::size_t head_{0};
};

}  // namespace ecsim
