#include "link/raw_socket_link.hpp"

#include <arpa/inet.h>
#include <linux/filter.h>
#include <linux/if_ether.h>   // ETH_P_ALL
#include <linux/if_packet.h>  // tpacket_auxdata, besides what netpacket/packet.h has
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/time.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>

#include "link/net_namespace.hpp"

namespace ecsim {
namespace {

std::string where(std::string_view interface, std::string_view netns) {
  std::string s = "interface '" + std::string(interface) + "'";
  if (!netns.empty()) s += " in network namespace '" + std::string(netns) + "'";
  return s;
}

Status checkInterfaceName(std::string_view interface) {
  if (interface.empty() || interface.size() >= IFNAMSIZ) {
    return makeError(ErrorCode::kInvalidArgument, "interface name '" + std::string(interface) +
                                                      "' must have 1 to " +
                                                      std::to_string(IFNAMSIZ - 1) + " characters");
  }
  return okStatus();
}

ifreq interfaceRequest(std::string_view interface) {
  ifreq ifr{};
  std::memcpy(ifr.ifr_name, interface.data(), interface.size());  // checked < IFNAMSIZ
  return ifr;
}

}  // namespace

Result<RawSocketLink> RawSocketLink::open(std::string_view interface,
                                          const RawSocketOptions& options) {
  ECSIM_TRY(checkInterfaceName(interface));
  RawSocketLink link;
  link.interface_ = std::string(interface);
  link.netns_ = options.netns;
  const std::string place = where(interface, options.netns);

  // Protocol 0 at creation: the socket receives nothing until bind() names the interface and
  // EtherType, so no frame from another interface slips in between.
  ECSIM_TRY(runInNetworkNamespace(options.netns, [&]() -> Status {
    link.fd_.reset(::socket(AF_PACKET, SOCK_RAW | SOCK_CLOEXEC, 0));
    if (link.fd_.valid()) return okStatus();
    const int err = errno;
    if (err == EPERM || err == EACCES) {
      return makeError(
          ErrorCode::kPermission,
          "opening a raw AF_PACKET socket for " + place +
              " needs CAP_NET_RAW (run as root or grant cap_net_raw): " + errnoText(err));
    }
    return makeError(ErrorCode::kIo, "socket(AF_PACKET) for " + place + ": " + errnoText(err));
  }));
  const int fd = link.fd_.get();

  ifreq ifr = interfaceRequest(interface);
  if (::ioctl(fd, SIOCGIFINDEX, &ifr) != 0) {
    const int err = errno;
    if (err == ENODEV) return makeError(ErrorCode::kNotFound, place + " does not exist");
    return makeError(ErrorCode::kIo, "SIOCGIFINDEX for " + place + ": " + errnoText(err));
  }
  link.ifindex_ = ifr.ifr_ifindex;
  ifr = interfaceRequest(interface);
  if (::ioctl(fd, SIOCGIFHWADDR, &ifr) == 0) {
    for (std::size_t i = 0; i < link.mac_.size(); ++i) {
      link.mac_[i] = static_cast<std::uint8_t>(ifr.ifr_hwaddr.sa_data[i]);
    }
  }

  const int one = 1;
  if (::setsockopt(fd, SOL_PACKET, PACKET_IGNORE_OUTGOING, &one, sizeof one) == 0) {
    link.kernelIgnoresOutgoing_ = true;
  }  // else: older kernel, receive() filters on sll_pkttype
  if (options.qdiscBypass &&
      ::setsockopt(fd, SOL_PACKET, PACKET_QDISC_BYPASS, &one, sizeof one) != 0) {
    return makeError(ErrorCode::kIo, "PACKET_QDISC_BYPASS on " + place + ": " + errnoText(errno));
  }
  // The kernel takes an 802.1Q tag off a received frame and reports it aside; receive() puts
  // it back, so a tagged request is answered tagged, as a real ESC passes the tag through.
  if (::setsockopt(fd, SOL_PACKET, PACKET_AUXDATA, &one, sizeof one) != 0) {
    return makeError(ErrorCode::kIo, "PACKET_AUXDATA on " + place + ": " + errnoText(errno));
  }

  // Only EtherCAT frames reach the socket's queue (a busy NIC's other traffic would crowd
  // it). Any VLAN tag is already off the data here, so the EtherType is at byte 12.
  std::array<sock_filter, 4> filter{{
      BPF_STMT(BPF_LD | BPF_H | BPF_ABS, 12),
      BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, kEtherTypeEtherCat, 0, 1),
      BPF_STMT(BPF_RET | BPF_K, 0xFFFF),  // the whole frame
      BPF_STMT(BPF_RET | BPF_K, 0),       // nothing
  }};
  const sock_fprog program{static_cast<unsigned short>(filter.size()), filter.data()};
  if (::setsockopt(fd, SOL_SOCKET, SO_ATTACH_FILTER, &program, sizeof program) != 0) {
    return makeError(ErrorCode::kIo, "EtherCAT filter on " + place + ": " + errnoText(errno));
  }

  // Busy-polling looks at a ring in memory instead of asking the socket: set up before bind()
  // so that no frame queues outside it.
  if (options.busyPoll) {
    ECSIM_ASSIGN_OR_RETURN(auto ring, PacketRxRing::attach(fd, "raw socket on " + place));
    link.ring_.emplace(std::move(ring));
  }

  if (options.sendCpu >= 0) {
    ECSIM_ASSIGN_OR_RETURN(auto sender,
                           KernelThreadSender::open(fd, options.sendCpu, "raw socket on " + place));
    link.sender_.emplace(std::move(sender));
  }

  sockaddr_ll addr{};
  addr.sll_family = AF_PACKET;
  // All EtherTypes, filtered in receive(): a socket bound to 0x88A4 gets a VLAN-tagged frame
  // only after the kernel has dropped its tag for good (no VLAN device of that ID), while one
  // bound to all sees the tag in PACKET_AUXDATA.
  addr.sll_protocol = htons(ETH_P_ALL);
  addr.sll_ifindex = link.ifindex_;
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    return makeError(ErrorCode::kIo, "binding raw socket to " + place + ": " + errnoText(errno));
  }

  if (options.promiscuous) {
    packet_mreq mreq{};
    mreq.mr_ifindex = link.ifindex_;
    mreq.mr_type = PACKET_MR_PROMISC;
    if (::setsockopt(fd, SOL_PACKET, PACKET_ADD_MEMBERSHIP, &mreq, sizeof mreq) != 0) {
      return makeError(ErrorCode::kIo, "promiscuous mode on " + place + ": " + errnoText(errno));
    }
  }
  return link;
}

Status RawSocketLink::send(ConstBytes frame) {
  if (frame.size() < kEthernetHeaderSize || frame.size() > kMaxFrameSize) {
    return makeError(
        frame.size() > kMaxFrameSize ? ErrorCode::kTooLarge : ErrorCode::kInvalidArgument,
        describe() + ": frame of " + std::to_string(frame.size()) + " bytes (allowed " +
            std::to_string(kEthernetHeaderSize) + " to " + std::to_string(kMaxFrameSize) + ")");
  }
  for (;;) {
    ssize_t n = 0;
    int err = 0;
    if (sender_) {
      ECSIM_ASSIGN_OR_RETURN(const long sent, sender_->send(frame));
      n = sent < 0 ? -1 : sent;
      err = sent < 0 ? static_cast<int>(-sent) : 0;
    } else {
      n = ::send(fd_.get(), frame.data(), frame.size(), 0);
      err = errno;
    }
    if (n == static_cast<ssize_t>(frame.size())) return okStatus();
    if (n >= 0) {
      return makeError(ErrorCode::kIo, describe() + ": short send of " + std::to_string(n) +
                                           " of " + std::to_string(frame.size()) + " bytes");
    }
    if (err == EINTR) continue;
    if (err == ENETDOWN || err == ENXIO) {
      return makeError(ErrorCode::kIo, describe() + " is down: " + errnoText(err));
    }
    return makeError(ErrorCode::kIo, describe() + ": send: " + errnoText(err));
  }
}

Status RawSocketLink::setReceiveTimeout(std::chrono::nanoseconds timeout) {
  if (timeout == receiveTimeout_) return okStatus();
  // Rounded up to whole microseconds: a zero timeval would mean "wait for ever".
  const auto us = std::max<std::int64_t>(1, (timeout.count() + 999) / 1000);
  timeval tv{};
  tv.tv_sec = static_cast<time_t>(us / 1'000'000);
  tv.tv_usec = static_cast<suseconds_t>(us % 1'000'000);
  if (::setsockopt(fd_.get(), SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv) != 0) {
    return makeError(ErrorCode::kIo, describe() + ": SO_RCVTIMEO: " + errnoText(errno));
  }
  receiveTimeout_ = timeout;
  return okStatus();
}

namespace {
// Waits at least this long are one blocking recvmsg (SO_RCVTIMEO, counted in scheduler ticks);
// shorter ones poll() with an exact timer (receive() below). `ecsim serve` idles 10 ms.
constexpr std::chrono::nanoseconds kBlockingReceiveMin = std::chrono::milliseconds(10);
}  // namespace

Result<std::size_t> RawSocketLink::receive(Bytes buffer, std::chrono::nanoseconds timeout) {
  // A long wait (a server idling between frames) is one blocking recvmsg bounded by the
  // socket's receive timeout (set again only when the timeout changes): one system call per
  // frame, where trying first and then polling took three. SO_RCVTIMEO counts in scheduler
  // ticks (4 ms at HZ=250), so a short wait (a master waiting for its frame, a server sharing
  // its thread with a master) tries first and then waits in poll(), whose timer is exact.
  // Busy-polling looks at the receive ring instead, never at the socket.
  if (ring_) return receiveFromRing(buffer, timeout);
  const bool wait = timeout >= kBlockingReceiveMin;
  const bool pollWait = !wait && timeout > std::chrono::nanoseconds::zero();
  if (wait) ECSIM_TRY(setReceiveTimeout(timeout));
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    sockaddr_ll from{};
    iovec data{buffer.data(), buffer.size()};
    alignas(cmsghdr) std::array<std::uint8_t, CMSG_SPACE(sizeof(tpacket_auxdata))> control{};
    msghdr message{};
    message.msg_name = &from;
    message.msg_namelen = sizeof from;
    message.msg_iov = &data;
    message.msg_iovlen = 1;
    message.msg_control = control.data();
    message.msg_controllen = control.size();
    // MSG_TRUNC: the return value is the real frame length even when the buffer is smaller.
    const ssize_t n = ::recvmsg(fd_.get(), &message, MSG_TRUNC | (wait ? 0 : MSG_DONTWAIT));
    if (n < 0) {
      // EAGAIN: the receive timeout passed (or nothing waits); EINTR: a signal, so that a
      // loop looks at its SignalFlag (SO_RCVTIMEO waits are never restarted).
      if (errno == EINTR) return std::size_t{0};
      if (errno == EAGAIN || errno == EWOULDBLOCK) {
        const auto left = deadline - std::chrono::steady_clock::now();
        if (wait || left <= std::chrono::nanoseconds::zero()) return std::size_t{0};
        if (pollWait) {
          ECSIM_ASSIGN_OR_RETURN(
              const bool readable,
              waitReadable(fd_.get(), std::chrono::duration_cast<std::chrono::nanoseconds>(left)));
          if (!readable) return std::size_t{0};
        } else {
          return std::size_t{0};  // no wait asked for
        }
        continue;
      }
      return makeError(ErrorCode::kIo, describe() + ": recvmsg: " + errnoText(errno));
    }
    if (n > 0 && from.sll_pkttype != PACKET_OUTGOING &&
        // The filter passes only EtherCAT; this also holds if it were not there.
        from.sll_protocol == htons(kEtherTypeEtherCat)) {
      auto length = static_cast<std::size_t>(n);
      if (length > buffer.size()) {
        return makeError(ErrorCode::kTooLarge, describe() + ": frame of " + std::to_string(length) +
                                                   " bytes exceeds receive buffer of " +
                                                   std::to_string(buffer.size()) +
                                                   " bytes, frame dropped");
      }
      return restoreVlanTag(message, buffer, length);
    }
    if (n > 0 && from.sll_pkttype == PACKET_OUTGOING) ++outgoingSkipped_;
    // A frame skipped: look for the next one, waiting for what is left of the timeout.
    if (!wait) continue;
    const auto left = deadline - std::chrono::steady_clock::now();
    if (left <= std::chrono::nanoseconds::zero()) return std::size_t{0};
    ECSIM_TRY(setReceiveTimeout(std::chrono::duration_cast<std::chrono::nanoseconds>(left)));
  }
}

Result<std::size_t> RawSocketLink::restoreVlanTag(const msghdr& message, Bytes buffer,
                                                  std::size_t length) const {
  for (const cmsghdr* c = CMSG_FIRSTHDR(&message); c != nullptr;
       c = CMSG_NXTHDR(const_cast<msghdr*>(&message), const_cast<cmsghdr*>(c))) {
    if (c->cmsg_level != SOL_PACKET || c->cmsg_type != PACKET_AUXDATA) continue;
    tpacket_auxdata aux{};
    std::memcpy(&aux, CMSG_DATA(c), sizeof aux);
    if ((aux.tp_status & TP_STATUS_VLAN_VALID) == 0) return length;
    const bool tpidKnown = (aux.tp_status & TP_STATUS_VLAN_TPID_VALID) != 0;
    return insertVlanTag(buffer, length, tpidKnown ? aux.tp_vlan_tpid : 0, aux.tp_vlan_tci);
  }
  return length;
}

Result<std::size_t> RawSocketLink::insertVlanTag(Bytes buffer, std::size_t length,
                                                 std::uint16_t tpid, std::uint16_t tci) const {
  if (length < kEthernetHeaderSize || length + kVlanTagSize > buffer.size()) {
    return makeError(ErrorCode::kTooLarge, describe() + ": VLAN-tagged frame of " +
                                               std::to_string(length + kVlanTagSize) +
                                               " bytes exceeds " + std::to_string(buffer.size()) +
                                               " bytes, frame dropped");
  }
  // The tag sits between the source address and the EtherType, as it was on the wire.
  constexpr std::size_t kTagAt = 2 * std::tuple_size_v<MacAddress>;
  std::memmove(buffer.data() + kTagAt + kVlanTagSize, buffer.data() + kTagAt, length - kTagAt);
  writeBe16(buffer, kTagAt, tpid != 0 ? tpid : kEtherTypeVlan);
  writeBe16(buffer, kTagAt + 2, tci);
  return length + kVlanTagSize;
}

Result<std::size_t> RawSocketLink::receiveFromRing(Bytes buffer, std::chrono::nanoseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (unsigned looks = 1;; ++looks) {
    if (auto frame = ring_->front()) {
      auto taken = takeFromRing(*frame, buffer);
      ring_->pop();
      if (!taken.ok() || *taken > 0) return taken;
      continue;  // not ours: look again at once
    }
    if (timeout <= std::chrono::nanoseconds::zero()) return std::size_t{0};
    // The clock is read every 64 looks (a vDSO call, no system call either).
    if (looks % 64 == 0 && std::chrono::steady_clock::now() >= deadline) return std::size_t{0};
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();  // spinning: spare the sibling hyperthread
#endif
  }
}

Result<std::size_t> RawSocketLink::takeFromRing(const PacketRxRing::Frame& frame, Bytes buffer) {
  if (frame.packetType == PACKET_OUTGOING) {
    ++outgoingSkipped_;
    return std::size_t{0};
  }
  if (frame.protocol != kEtherTypeEtherCat) return std::size_t{0};
  const std::size_t tag = frame.vlanTci ? kVlanTagSize : 0;
  if (frame.wireLength > frame.data.size() || frame.wireLength + tag > buffer.size()) {
    return makeError(ErrorCode::kTooLarge, describe() + ": frame of " +
                                               std::to_string(frame.wireLength + tag) +
                                               " bytes exceeds receive buffer of " +
                                               std::to_string(std::min(buffer.size(),
                                                                       frame.data.size())) +
                                               " bytes, frame dropped");
  }
  std::memcpy(buffer.data(), frame.data.data(), frame.data.size());
  if (!frame.vlanTci) return frame.data.size();
  return insertVlanTag(buffer, frame.data.size(), frame.vlanTpid, *frame.vlanTci);
}

std::string RawSocketLink::describe() const {
  return "raw socket on " + where(interface_, netns_);
}

}  // namespace ecsim
