#include "slavesim/eoe/eoe_server.hpp"

#include <algorithm>

#include "slavesim/esc.hpp"

namespace ecsim::slavesim::eoe {
namespace {

// Locally administered, unicast (IEEE 802 bit 1 of the first octet set, bit 0 clear).
constexpr std::uint8_t kLocalMacPrefix = 0x02;

// Pads a frame to the Ethernet minimum as a sending NIC does.
void padFrame(std::vector<std::uint8_t>& frame) {
  if (frame.size() < kMinFrameSize) frame.resize(kMinFrameSize, 0);
}

}  // namespace

MacAddress EoeServer::mac(const Esc& esc) const {
  if (ip_.mac) return *ip_.mac;
  const std::uint16_t station = esc.stationAddress();
  return MacAddress{kLocalMacPrefix,
                    0,
                    0,
                    0,
                    static_cast<std::uint8_t>(station >> 8),
                    static_cast<std::uint8_t>(station)};
}

void EoeServer::reset() {
  reassembler_.reset();
  pending_.clear();
}

void EoeServer::answer(MailboxReplies& replies, EoeFrameType type, std::uint8_t port,
                       EoeResult result, ConstBytes body) {
  EoeHeader h;
  h.type = static_cast<std::uint8_t>(type);
  h.port = port;
  h.result = static_cast<std::uint16_t>(result);
  auto message = encodeEoeMessage(h, body);
  if (message.ok()) replies.send(std::move(*message));
}

void EoeServer::onMessage(Esc& esc, const MailboxMessage& message, MailboxReplies& replies,
                          SimTime now) {
  auto header = EoeHeader::decode(message.payload);
  if (!header.ok()) {
    ++counters_.unsupportedRequests;
    return;
  }
  const ConstBytes body = message.payload.subspan(kEoeHeaderSize);
  switch (header->frameType()) {
    case EoeFrameType::kFragment: {
      ++counters_.fragmentsReceived;
      port_ = header->port;
      auto frame = reassembler_.add(*header, body);
      if (!frame.ok()) {
        ++counters_.reassemblyErrors;
      } else if (frame->has_value()) {
        ++counters_.framesReceived;
        handleFrame(esc, std::move(**frame));
      }
      break;
    }
    case EoeFrameType::kSetIpRequest: {
      ++counters_.setIpRequests;
      auto update = EoeIpParameters::decode(body);
      if (!update.ok()) {
        answer(replies, EoeFrameType::kSetIpResponse, header->port, EoeResult::kUnspecifiedError);
        break;
      }
      ip_.merge(*update);
      answer(replies, EoeFrameType::kSetIpResponse, header->port, EoeResult::kSuccess);
      break;
    }
    case EoeFrameType::kGetIpRequest: {
      ++counters_.getIpRequests;
      EoeIpParameters current = ip_;
      if (!current.mac) current.mac = mac(esc);
      auto block = current.encode();
      if (block.ok()) {
        answer(replies, EoeFrameType::kGetIpResponse, header->port, EoeResult::kSuccess, *block);
      }
      break;
    }
    case EoeFrameType::kSetAddressFilterRequest:
      ++counters_.filterRequests;
      answer(replies, EoeFrameType::kSetAddressFilterResponse, header->port,
             EoeResult::kNoFilterSupport);
      break;
    case EoeFrameType::kGetAddressFilterRequest:
      ++counters_.filterRequests;
      answer(replies, EoeFrameType::kGetAddressFilterResponse, header->port,
             EoeResult::kNoFilterSupport);
      break;
    default:
      ++counters_.unsupportedRequests;
      break;
  }
  poll(esc, replies, now);
}

void EoeServer::poll(Esc& /*esc*/, MailboxReplies& replies, SimTime /*now*/) {
  flush(replies);
}

void EoeServer::sendFrame(std::vector<std::uint8_t> frame) {
  if (pending_.size() >= options_.maxPendingFrames) {
    ++counters_.framesDropped;
    return;
  }
  pending_.push_back(std::move(frame));
}

void EoeServer::flush(MailboxReplies& replies) {
  // One frame's fragments at a time, so a frame is never interleaved with another's.
  while (!pending_.empty() && replies.queuedMessages() == 0) {
    std::vector<std::uint8_t> frame = std::move(pending_.front());
    pending_.pop_front();
    frameNumber_ = static_cast<std::uint8_t>((frameNumber_ + 1) & kEoeFrameNumberMax);
    auto fragments = fragmentEoeFrame(frame, replies.mailboxSize(), port_, frameNumber_);
    if (!fragments.ok()) {
      ++counters_.framesDropped;
      continue;
    }
    for (auto& f : *fragments) replies.send(std::move(f));
    ++counters_.framesSent;
  }
}

void EoeServer::handleFrame(const Esc& esc, std::vector<std::uint8_t> frame) {
  auto eth = EthernetHeader::parse(frame);
  if (eth.ok()) {
    if (eth->etherType == kEtherTypeArp && answerArp(esc, frame, *eth)) return;
    if (eth->etherType == kEtherTypeIpv4 && answerEcho(esc, frame, *eth)) return;
  }
  if (sink_) {
    ++counters_.framesForwarded;
    sink_(frame);
  } else if (options_.loopback) {
    ++counters_.framesForwarded;
    sendFrame(std::move(frame));
  } else {
    ++counters_.framesIgnored;
  }
}

bool EoeServer::answerArp(const Esc& esc, ConstBytes frame, const EthernetHeader& eth) {
  auto arp = ArpPacket::decode(frame.subspan(eth.size()));
  if (!arp.ok() || !ip_.ip || arp->targetIp != *ip_.ip) return false;
  if (arp->operation != kArpRequest) return true;  // a reply for us: nothing to do
  const MacAddress own = mac(esc);
  ArpPacket reply;
  reply.operation = kArpReply;
  reply.senderMac = own;
  reply.senderIp = *ip_.ip;
  reply.targetMac = arp->senderMac;
  reply.targetIp = arp->senderIp;
  EthernetHeader out = eth;
  out.destination = arp->senderMac;
  out.source = own;
  std::vector<std::uint8_t> bytes(out.size() + kArpSize, 0);
  if (!out.write(bytes).ok() || !reply.encode(Bytes(bytes).subspan(out.size())).ok()) {
    return true;
  }
  padFrame(bytes);
  ++counters_.arpReplies;
  sendFrame(std::move(bytes));
  return true;
}

bool EoeServer::answerEcho(const Esc& esc, ConstBytes frame, const EthernetHeader& eth) {
  const ConstBytes packet = frame.subspan(eth.size());
  auto ip = Ipv4Header::decode(packet);
  if (!ip.ok() || !ip_.ip || ip->destination != *ip_.ip) return false;
  if (ip->protocol != kIpProtocolIcmp || ip->isFragment()) return true;  // ours, not answered
  const ConstBytes icmp = packet.subspan(ip->headerSize, ip->totalLength - ip->headerSize);
  if (icmp.size() < kIcmpHeaderSize || icmp[0] != kIcmpEchoRequest || icmp[1] != 0 ||
      internetChecksum(icmp) != 0) {
    return true;
  }
  Ipv4Header replyIp;
  replyIp.totalLength = static_cast<std::uint16_t>(kIpv4MinHeaderSize + icmp.size());
  replyIp.identification = ip->identification;
  replyIp.protocol = kIpProtocolIcmp;
  replyIp.source = *ip_.ip;
  replyIp.destination = ip->source;
  EthernetHeader out = eth;
  out.destination = eth.source;
  out.source = mac(esc);
  std::vector<std::uint8_t> bytes(out.size() + replyIp.totalLength, 0);
  const Bytes ipBytes = Bytes(bytes).subspan(out.size());
  if (!out.write(bytes).ok() || !replyIp.encode(ipBytes).ok()) return true;
  const Bytes reply = ipBytes.subspan(kIpv4MinHeaderSize);
  std::copy(icmp.begin(), icmp.end(), reply.begin());
  reply[0] = kIcmpEchoReply;
  writeBe16(reply, 2, 0);
  writeBe16(reply, 2, internetChecksum(reply));
  padFrame(bytes);
  ++counters_.echoReplies;
  sendFrame(std::move(bytes));
  return true;
}

}  // namespace ecsim::slavesim::eoe
