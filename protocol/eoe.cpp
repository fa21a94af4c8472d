#include "protocol/eoe.hpp"

#include <algorithm>

namespace ecsim {
namespace {

constexpr std::uint16_t kTypeMask = 0x000F;
constexpr unsigned kPortShift = 4;
constexpr std::uint16_t kLastFragmentBit = 1u << 8;
constexpr std::uint16_t kTimeAppendedBit = 1u << 9;
constexpr std::uint16_t kTimeRequestedBit = 1u << 10;
constexpr unsigned kOffsetShift = 6;
constexpr unsigned kFrameNumberShift = 12;

// IP parameter block layout.
constexpr std::uint32_t kIncludesMac = 1u << 0;
constexpr std::uint32_t kIncludesIp = 1u << 1;
constexpr std::uint32_t kIncludesSubnet = 1u << 2;
constexpr std::uint32_t kIncludesGateway = 1u << 3;
constexpr std::uint32_t kIncludesDnsServer = 1u << 4;
constexpr std::uint32_t kIncludesDnsName = 1u << 5;
constexpr std::size_t kMacAt = 4;
constexpr std::size_t kIpAt = kMacAt + 6;
constexpr std::size_t kSubnetAt = kIpAt + 4;
constexpr std::size_t kGatewayAt = kSubnetAt + 4;
constexpr std::size_t kDnsServerAt = kGatewayAt + 4;
constexpr std::size_t kDnsNameAt = kDnsServerAt + 4;

// UINT32, little-endian: the last dotted octet comes first.
Ipv4Address readIp(ConstBytes b, std::size_t at) {
  return {b[at + 3], b[at + 2], b[at + 1], b[at]};
}
void writeIp(Bytes b, std::size_t at, const Ipv4Address& ip) {
  for (std::size_t i = 0; i < 4; ++i) b[at + i] = ip[3 - i];
}

std::size_t roundUpUnits(std::size_t bytes) {
  return (bytes + kEoeFragmentUnit - 1) / kEoeFragmentUnit;
}

}  // namespace

std::string_view toString(EoeFrameType type) {
  switch (type) {
    case EoeFrameType::kFragment:
      return "fragment";
    case EoeFrameType::kInitResponseTimestamp:
      return "timestamp";
    case EoeFrameType::kSetIpRequest:
      return "set IP request";
    case EoeFrameType::kSetIpResponse:
      return "set IP response";
    case EoeFrameType::kSetAddressFilterRequest:
      return "set address filter request";
    case EoeFrameType::kSetAddressFilterResponse:
      return "set address filter response";
    case EoeFrameType::kGetIpRequest:
      return "get IP request";
    case EoeFrameType::kGetIpResponse:
      return "get IP response";
    case EoeFrameType::kGetAddressFilterRequest:
      return "get address filter request";
    case EoeFrameType::kGetAddressFilterResponse:
      return "get address filter response";
  }
  return "reserved";
}

std::string_view eoeResultText(std::uint16_t result) {
  switch (static_cast<EoeResult>(result)) {
    case EoeResult::kSuccess:
      return "success";
    case EoeResult::kUnspecifiedError:
      return "unspecified error";
    case EoeResult::kUnsupportedFrameType:
      return "unsupported frame type";
    case EoeResult::kNoIpSupport:
      return "no IP support";
    case EoeResult::kNoDhcpSupport:
      return "no DHCP support";
    case EoeResult::kNoFilterSupport:
      return "no address filter support";
  }
  return "unknown EoE result";
}

Result<EoeHeader> EoeHeader::decode(ConstBytes b) {
  if (b.size() < kEoeHeaderSize) {
    return makeError(ErrorCode::kTruncated,
                     "EoE header needs 4 bytes, has " + std::to_string(b.size()));
  }
  const std::uint16_t w1 = readLe16(b, 0);
  const std::uint16_t w2 = readLe16(b, 2);
  EoeHeader h;
  h.type = static_cast<std::uint8_t>(w1 & kTypeMask);
  h.port = static_cast<std::uint8_t>((w1 >> kPortShift) & kEoePortMax);
  h.lastFragment = (w1 & kLastFragmentBit) != 0;
  h.timeAppended = (w1 & kTimeAppendedBit) != 0;
  h.timeRequested = (w1 & kTimeRequestedBit) != 0;
  h.fragmentNumber = static_cast<std::uint8_t>(w2 & kEoeFragmentNumberMax);
  h.offsetUnits = static_cast<std::uint8_t>((w2 >> kOffsetShift) & kEoeOffsetUnitsMax);
  h.frameNumber = static_cast<std::uint8_t>((w2 >> kFrameNumberShift) & kEoeFrameNumberMax);
  h.result = w2;
  return h;
}

Result<std::size_t> EoeHeader::encode(Bytes out) const {
  if (out.size() < kEoeHeaderSize) {
    return makeError(ErrorCode::kTooLarge, "EoE header needs 4 bytes");
  }
  if (type > kTypeMask || port > kEoePortMax || fragmentNumber > kEoeFragmentNumberMax ||
      offsetUnits > kEoeOffsetUnitsMax || frameNumber > kEoeFrameNumberMax) {
    return makeError(ErrorCode::kInvalidArgument,
                     "EoE header field out of range (type " + std::to_string(type) + ", port " +
                         std::to_string(port) + ", fragment " + std::to_string(fragmentNumber) +
                         ", offset " + std::to_string(offsetUnits) + ", frame " +
                         std::to_string(frameNumber) + ")");
  }
  std::uint16_t w1 = static_cast<std::uint16_t>(type | (port << kPortShift));
  if (lastFragment) w1 |= kLastFragmentBit;
  if (timeAppended) w1 |= kTimeAppendedBit;
  if (timeRequested) w1 |= kTimeRequestedBit;
  const std::uint16_t w2 =
      type == static_cast<std::uint8_t>(EoeFrameType::kFragment)
          ? static_cast<std::uint16_t>(fragmentNumber | (offsetUnits << kOffsetShift) |
                                       (frameNumber << kFrameNumberShift))
          : result;
  writeLe16(out, 0, w1);
  writeLe16(out, 2, w2);
  return kEoeHeaderSize;
}

Result<EoeIpParameters> EoeIpParameters::decode(ConstBytes b) {
  if (b.size() < kMacAt) {
    return makeError(ErrorCode::kTruncated, "EoE IP parameters: byte " + std::to_string(b.size()) +
                                                ": the 4-byte flags word is cut short");
  }
  const std::uint32_t flags = readLe32(b, 0);
  auto need = [&](std::size_t at, std::size_t size, const char* what) -> Status {
    if (at + size > b.size()) {
      return makeError(ErrorCode::kTruncated, "EoE IP parameters: byte " + std::to_string(at) +
                                                  ": " + what + " flagged but cut short (" +
                                                  std::to_string(b.size()) + " bytes)");
    }
    return okStatus();
  };
  EoeIpParameters p;
  if (flags & kIncludesMac) {
    ECSIM_TRY(need(kMacAt, 6, "MAC address"));
    MacAddress mac{};
    std::copy_n(b.begin() + kMacAt, 6, mac.begin());
    p.mac = mac;
  }
  struct Field {
    std::uint32_t flag;
    std::size_t at;
    std::optional<Ipv4Address>* out;
    const char* what;
  };
  const Field fields[] = {{kIncludesIp, kIpAt, &p.ip, "IP address"},
                          {kIncludesSubnet, kSubnetAt, &p.subnetMask, "subnet mask"},
                          {kIncludesGateway, kGatewayAt, &p.gateway, "default gateway"},
                          {kIncludesDnsServer, kDnsServerAt, &p.dnsServer, "DNS server"}};
  for (const Field& f : fields) {
    if ((flags & f.flag) == 0) continue;
    ECSIM_TRY(need(f.at, 4, f.what));
    *f.out = readIp(b, f.at);
  }
  if (flags & kIncludesDnsName) {
    // SOEM copies what is there up to 32 bytes; accept a shorter name block the same way.
    if (b.size() <= kDnsNameAt) ECSIM_TRY(need(kDnsNameAt, 1, "DNS name"));
    const std::size_t size = std::min(kEoeDnsNameSize, b.size() - kDnsNameAt);
    auto name = b.subspan(kDnsNameAt, size);
    auto end = std::find(name.begin(), name.end(), std::uint8_t{0});
    p.dnsName = std::string(name.begin(), end);
  }
  return p;
}

Result<std::vector<std::uint8_t>> EoeIpParameters::encode() const {
  if (dnsName && dnsName->size() > kEoeDnsNameSize) {
    return makeError(ErrorCode::kTooLarge, "EoE DNS name '" + *dnsName + "' is longer than 32");
  }
  std::vector<std::uint8_t> out(kEoeIpParameterSize, 0);
  std::uint32_t flags = 0;
  if (mac) {
    flags |= kIncludesMac;
    std::copy(mac->begin(), mac->end(), out.begin() + kMacAt);
  }
  auto put = [&](const std::optional<Ipv4Address>& address, std::uint32_t flag, std::size_t at) {
    if (!address) return;
    flags |= flag;
    writeIp(out, at, *address);
  };
  put(ip, kIncludesIp, kIpAt);
  put(subnetMask, kIncludesSubnet, kSubnetAt);
  put(gateway, kIncludesGateway, kGatewayAt);
  put(dnsServer, kIncludesDnsServer, kDnsServerAt);
  if (dnsName) {
    flags |= kIncludesDnsName;
    std::copy(dnsName->begin(), dnsName->end(), out.begin() + kDnsNameAt);
  }
  writeLe32(out, 0, flags);
  return out;
}

void EoeIpParameters::merge(const EoeIpParameters& u) {
  if (u.mac) mac = u.mac;
  if (u.ip) ip = u.ip;
  if (u.subnetMask) subnetMask = u.subnetMask;
  if (u.gateway) gateway = u.gateway;
  if (u.dnsServer) dnsServer = u.dnsServer;
  if (u.dnsName) dnsName = u.dnsName;
}

Result<std::vector<std::uint8_t>> encodeEoeMessage(const EoeHeader& eoe, ConstBytes body,
                                                   MailboxHeader header) {
  std::vector<std::uint8_t> out(kMailboxHeaderSize + kEoeHeaderSize + body.size(), 0);
  ECSIM_TRY(eoe.encode(Bytes(out).subspan(kMailboxHeaderSize)));
  std::copy(body.begin(), body.end(), out.begin() + kMailboxHeaderSize + kEoeHeaderSize);
  header.type = MailboxType::kEoe;
  ECSIM_TRY(finishMailbox(out, header, kEoeHeaderSize + body.size()));
  return out;
}

Result<std::vector<std::vector<std::uint8_t>>> fragmentEoeFrame(ConstBytes frame,
                                                                std::size_t mailboxSize,
                                                                std::uint8_t port,
                                                                std::uint8_t frameNumber) {
  if (frame.empty() || frame.size() > kEoeMaxFrameSize) {
    return makeError(ErrorCode::kInvalidArgument, "EoE frame of " + std::to_string(frame.size()) +
                                                      " bytes (1.." +
                                                      std::to_string(kEoeMaxFrameSize) + ")");
  }
  const std::size_t room = mailboxSize > kMailboxHeaderSize + kEoeHeaderSize
                               ? mailboxSize - kMailboxHeaderSize - kEoeHeaderSize
                               : 0;
  const std::size_t chunk = room / kEoeFragmentUnit * kEoeFragmentUnit;
  if (chunk == 0) {
    return makeError(ErrorCode::kTooLarge, "a mailbox of " + std::to_string(mailboxSize) +
                                               " bytes cannot carry an EoE fragment");
  }
  std::vector<std::vector<std::uint8_t>> out;
  std::size_t offset = 0;
  while (offset < frame.size()) {
    if (out.size() > kEoeFragmentNumberMax) {
      return makeError(ErrorCode::kTooLarge, "EoE frame of " + std::to_string(frame.size()) +
                                                 " bytes needs more than 64 fragments");
    }
    const std::size_t left = frame.size() - offset;
    // The last fragment may use the whole room, not just whole 32-byte units.
    const std::size_t size = left <= room ? left : chunk;
    EoeHeader h;
    h.type = static_cast<std::uint8_t>(EoeFrameType::kFragment);
    h.port = port;
    h.lastFragment = size == left;
    h.fragmentNumber = static_cast<std::uint8_t>(out.size());
    h.offsetUnits = static_cast<std::uint8_t>(offset == 0 ? roundUpUnits(frame.size())
                                                          : offset / kEoeFragmentUnit);
    h.frameNumber = frameNumber;
    ECSIM_ASSIGN_OR_RETURN(auto message, encodeEoeMessage(h, frame.subspan(offset, size)));
    out.push_back(std::move(message));
    offset += size;
  }
  return out;
}

void EoeReassembler::reset() {
  frame_.clear();
  announced_ = 0;
  nextFragment_ = 0;
  inProgress_ = false;
}

Result<std::optional<std::vector<std::uint8_t>>> EoeReassembler::add(const EoeHeader& h,
                                                                     ConstBytes data) {
  if (h.fragmentNumber == 0) {
    reset();
    announced_ = static_cast<std::size_t>(h.offsetUnits) * kEoeFragmentUnit;
    frameNumber_ = h.frameNumber;
    inProgress_ = true;
  } else {
    std::string problem;
    if (!inProgress_) {
      problem = "fragment " + std::to_string(h.fragmentNumber) + " without fragment 0";
    } else if (h.fragmentNumber != nextFragment_) {
      problem = "fragment " + std::to_string(h.fragmentNumber) + " where " +
                std::to_string(nextFragment_) + " was due";
    } else if (h.frameNumber != frameNumber_) {
      problem = "fragment of frame " + std::to_string(h.frameNumber) + " inside frame " +
                std::to_string(frameNumber_);
    } else if (static_cast<std::size_t>(h.offsetUnits) * kEoeFragmentUnit != frame_.size()) {
      problem = "fragment offset " + std::to_string(h.offsetUnits * kEoeFragmentUnit) + " where " +
                std::to_string(frame_.size()) + " was due";
    }
    if (!problem.empty()) {
      reset();
      return makeError(ErrorCode::kMalformed, "EoE reassembly: " + problem);
    }
  }
  if (frame_.size() + data.size() > announced_ + (h.timeAppended ? kEoeTimestampSize : 0)) {
    const std::size_t total = frame_.size() + data.size();
    const std::size_t announced = announced_;
    reset();
    return makeError(ErrorCode::kMalformed, "EoE reassembly: " + std::to_string(total) +
                                                " bytes where the frame was announced with " +
                                                std::to_string(announced) + " at most");
  }
  frame_.insert(frame_.end(), data.begin(), data.end());
  ++nextFragment_;
  if (!h.lastFragment) {
    if (nextFragment_ > kEoeFragmentNumberMax) {
      reset();
      return makeError(ErrorCode::kMalformed, "EoE reassembly: more than 64 fragments");
    }
    return std::optional<std::vector<std::uint8_t>>{};
  }
  if (h.timeAppended) {
    if (frame_.size() < kEoeTimestampSize) {
      reset();
      return makeError(ErrorCode::kMalformed, "EoE reassembly: timestamp flagged, no room for it");
    }
    frame_.resize(frame_.size() - kEoeTimestampSize);
  }
  std::vector<std::uint8_t> done = std::move(frame_);
  reset();
  return std::optional<std::vector<std::uint8_t>>{std::move(done)};
}

}  // namespace ecsim
