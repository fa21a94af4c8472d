#include "link/packet_rx_ring.hpp"

#include <arpa/inet.h>
#include <linux/if_packet.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <unistd.h>

#include <utility>

#include "protocol/unique_fd.hpp"

namespace ecsim {
namespace {

// A slot per half page: the kernel wants the block size a multiple of the page size and the
// slots not to straddle blocks.
constexpr std::size_t kBlockBytes = 4096;

}  // namespace

Result<PacketRxRing> PacketRxRing::attach(int fd, const std::string& where, std::size_t slots) {
  static_assert(kBlockBytes % kSlotBytes == 0);
  constexpr std::size_t kSlotsPerBlock = kBlockBytes / kSlotBytes;
  if (slots == 0 || slots % kSlotsPerBlock != 0) {
    return makeError(ErrorCode::kInvalidArgument,
                     "receive ring of " + std::to_string(slots) + " slots for " + where +
                         ": wants a positive multiple of " + std::to_string(kSlotsPerBlock));
  }
  const int version = TPACKET_V2;
  if (::setsockopt(fd, SOL_PACKET, PACKET_VERSION, &version, sizeof version) != 0) {
    return makeError(ErrorCode::kIo, "PACKET_VERSION (TPACKET_V2) on " + where + ": " +
                                         errnoText(errno));
  }
  tpacket_req request{};
  request.tp_block_size = static_cast<unsigned>(kBlockBytes);
  request.tp_block_nr = static_cast<unsigned>(slots / kSlotsPerBlock);
  request.tp_frame_size = static_cast<unsigned>(kSlotBytes);
  request.tp_frame_nr = static_cast<unsigned>(slots);
  if (::setsockopt(fd, SOL_PACKET, PACKET_RX_RING, &request, sizeof request) != 0) {
    return makeError(ErrorCode::kIo, "PACKET_RX_RING on " + where + ": " + errnoText(errno));
  }
  const std::size_t bytes = slots * kSlotBytes;
  void* mapped = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  if (mapped == MAP_FAILED) {
    return makeError(ErrorCode::kIo, "mapping the receive ring of " + where + ": " +
                                         errnoText(errno));
  }
  PacketRxRing ring;
  ring.base_ = static_cast<std::uint8_t*>(mapped);
  ring.bytes_ = bytes;
  ring.slots_ = slots;
  return ring;
}

PacketRxRing::PacketRxRing(PacketRxRing&& other) noexcept
    : base_(std::exchange(other.base_, nullptr)),
      bytes_(std::exchange(other.bytes_, 0)),
      slots_(std::exchange(other.slots_, 0)),
      head_(std::exchange(other.head_, 0)) {}

PacketRxRing& PacketRxRing::operator=(PacketRxRing&& other) noexcept {
  if (this != &other) {
    if (base_ != nullptr) ::munmap(base_, bytes_);
    base_ = std::exchange(other.base_, nullptr);
    bytes_ = std::exchange(other.bytes_, 0);
    slots_ = std::exchange(other.slots_, 0);
    head_ = std::exchange(other.head_, 0);
  }
  return *this;
}

PacketRxRing::~PacketRxRing() {
  if (base_ != nullptr) ::munmap(base_, bytes_);
}

std::optional<PacketRxRing::Frame> PacketRxRing::front() const {
  if (base_ == nullptr) return std::nullopt;
  auto* header = reinterpret_cast<tpacket2_hdr*>(slot(head_));
  // Acquire: the frame's bytes, written by the kernel before the status, are seen after it.
  const std::uint32_t status = __atomic_load_n(&header->tp_status, __ATOMIC_ACQUIRE);
  if ((status & TP_STATUS_USER) == 0) return std::nullopt;
  const auto* address = reinterpret_cast<const sockaddr_ll*>(
      slot(head_) + TPACKET_ALIGN(sizeof(tpacket2_hdr)));
  Frame f;
  f.data = ConstBytes(slot(head_) + header->tp_mac, header->tp_snaplen);
  f.wireLength = header->tp_len;
  f.packetType = address->sll_pkttype;
  f.protocol = ntohs(address->sll_protocol);
  if ((status & TP_STATUS_VLAN_VALID) != 0) {
    f.vlanTci = header->tp_vlan_tci;
    if ((status & TP_STATUS_VLAN_TPID_VALID) != 0) f.vlanTpid = header->tp_vlan_tpid;
  }
  return f;
}

void PacketRxRing::pop() {
  if (base_ == nullptr) return;
  auto* header = reinterpret_cast<tpacket2_hdr*>(slot(head_));
  // Release: our reads of the slot are done before the kernel may write it again.
  __atomic_store_n(&header->tp_status, static_cast<std::uint32_t>(TP_STATUS_KERNEL),
                   __ATOMIC_RELEASE);
  head_ = (head_ + 1) % slots_;
}

}  // namespace ecsim
