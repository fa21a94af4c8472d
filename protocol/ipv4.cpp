#include "protocol/ipv4.hpp"

#include <algorithm>
#include <charconv>
#include <cstdio>

namespace ecsim {
namespace {

// Reads `count` numbers of at most `max` in base `base` separated by one of `separators`.
template <std::size_t N>
bool parseFields(std::string_view text, std::array<std::uint8_t, N>& out, int base,
                 std::string_view separators) {
  std::size_t at = 0;
  for (std::size_t i = 0; i < N; ++i) {
    if (i > 0) {
      if (at >= text.size() || separators.find(text[at]) == std::string_view::npos) return false;
      ++at;
    }
    unsigned value = 0;
    const char* begin = text.data() + at;
    const char* end = text.data() + text.size();
    auto [ptr, ec] = std::from_chars(begin, end, value, base);
    if (ec != std::errc{} || ptr == begin || value > 0xFF || ptr - begin > 3) return false;
    out[i] = static_cast<std::uint8_t>(value);
    at = static_cast<std::size_t>(ptr - text.data());
  }
  return at == text.size();
}

}  // namespace

std::string formatIpv4(const Ipv4Address& a) {
  char text[16];
  std::snprintf(text, sizeof text, "%u.%u.%u.%u", a[0], a[1], a[2], a[3]);
  return text;
}

Result<Ipv4Address> parseIpv4(std::string_view text) {
  Ipv4Address a{};
  if (!parseFields(text, a, 10, ".")) {
    return makeError(ErrorCode::kInvalidArgument,
                     "'" + std::string(text) + "' is not an IPv4 address (a.b.c.d, 0..255)");
  }
  return a;
}

Result<MacAddress> parseMac(std::string_view text) {
  MacAddress m{};
  if (!parseFields(text, m, 16, ":-")) {
    return makeError(ErrorCode::kInvalidArgument,
                     "'" + std::string(text) + "' is not a MAC address (aa:bb:cc:dd:ee:ff)");
  }
  return m;
}

std::uint16_t internetChecksum(ConstBytes bytes) {
  std::uint32_t sum = 0;
  std::size_t i = 0;
  for (; i + 1 < bytes.size(); i += 2) sum += readBe16(bytes, i);
  if (i < bytes.size()) sum += static_cast<std::uint32_t>(bytes[i]) << 8;
  while (sum >> 16) sum = (sum & 0xFFFF) + (sum >> 16);
  return static_cast<std::uint16_t>(~sum);
}

Result<ArpPacket> ArpPacket::decode(ConstBytes b) {
  if (b.size() < kArpSize) {
    return makeError(ErrorCode::kTruncated,
                     "ARP packet needs 28 bytes, has " + std::to_string(b.size()));
  }
  if (readBe16(b, 0) != kArpHardwareEthernet || readBe16(b, 2) != kEtherTypeIpv4 || b[4] != 6 ||
      b[5] != 4) {
    return makeError(ErrorCode::kUnsupported, "ARP packet is not IPv4 over Ethernet");
  }
  ArpPacket p;
  p.operation = readBe16(b, 6);
  std::copy_n(b.begin() + 8, 6, p.senderMac.begin());
  std::copy_n(b.begin() + 14, 4, p.senderIp.begin());
  std::copy_n(b.begin() + 18, 6, p.targetMac.begin());
  std::copy_n(b.begin() + 24, 4, p.targetIp.begin());
  return p;
}

Status ArpPacket::encode(Bytes b) const {
  if (b.size() < kArpSize) return makeError(ErrorCode::kTooLarge, "ARP packet does not fit");
  writeBe16(b, 0, kArpHardwareEthernet);
  writeBe16(b, 2, kEtherTypeIpv4);
  b[4] = 6;
  b[5] = 4;
  writeBe16(b, 6, operation);
  std::copy(senderMac.begin(), senderMac.end(), b.begin() + 8);
  std::copy(senderIp.begin(), senderIp.end(), b.begin() + 14);
  std::copy(targetMac.begin(), targetMac.end(), b.begin() + 18);
  std::copy(targetIp.begin(), targetIp.end(), b.begin() + 24);
  return okStatus();
}

bool Ipv4Header::isFragment() const {
  constexpr std::uint16_t kMoreFragments = 0x2000;
  constexpr std::uint16_t kOffsetMask = 0x1FFF;
  return (flagsFragment & (kMoreFragments | kOffsetMask)) != 0;
}

Result<Ipv4Header> Ipv4Header::decode(ConstBytes b) {
  if (b.size() < kIpv4MinHeaderSize) {
    return makeError(ErrorCode::kTruncated,
                     "IPv4 header needs 20 bytes, has " + std::to_string(b.size()));
  }
  if ((b[0] >> 4) != 4) {
    return makeError(ErrorCode::kMalformed, "IPv4 byte 0: version " + std::to_string(b[0] >> 4));
  }
  Ipv4Header h;
  h.headerSize = static_cast<std::size_t>(b[0] & 0x0F) * 4;
  h.totalLength = readBe16(b, 2);
  if (h.headerSize < kIpv4MinHeaderSize || h.totalLength < h.headerSize ||
      h.totalLength > b.size()) {
    return makeError(ErrorCode::kMalformed,
                     "IPv4 byte 2: total length " + std::to_string(h.totalLength) +
                         " with a header of " + std::to_string(h.headerSize) + " in " +
                         std::to_string(b.size()) + " bytes");
  }
  if (internetChecksum(b.first(h.headerSize)) != 0) {
    return makeError(ErrorCode::kMalformed, "IPv4 byte 10: header checksum wrong");
  }
  h.tos = b[1];
  h.identification = readBe16(b, 4);
  h.flagsFragment = readBe16(b, 6);
  h.ttl = b[8];
  h.protocol = b[9];
  std::copy_n(b.begin() + 12, 4, h.source.begin());
  std::copy_n(b.begin() + 16, 4, h.destination.begin());
  return h;
}

Status Ipv4Header::encode(Bytes b) const {
  if (b.size() < kIpv4MinHeaderSize) return makeError(ErrorCode::kTooLarge, "IPv4 header");
  constexpr std::uint8_t kVersion4Ihl5 = 0x45;
  b[0] = kVersion4Ihl5;
  b[1] = tos;
  writeBe16(b, 2, totalLength);
  writeBe16(b, 4, identification);
  writeBe16(b, 6, flagsFragment);
  b[8] = ttl;
  b[9] = protocol;
  writeBe16(b, 10, 0);
  std::copy(source.begin(), source.end(), b.begin() + 12);
  std::copy(destination.begin(), destination.end(), b.begin() + 16);
  writeBe16(b, 10, internetChecksum(ConstBytes(b.data(), kIpv4MinHeaderSize)));
  return okStatus();
}

}  // namespace ecsim
