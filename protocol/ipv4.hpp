// The little of IPv4 an EoE device's own stack needs: ARP (RFC 826) for IPv4 over Ethernet,
// the IPv4 header (RFC 791) and ICMP echo (RFC 792), with the Internet checksum (RFC 1071).
// All multi-byte fields are big-endian (network order).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/bytes.hpp"
#include "protocol/ethernet.hpp"
#include "protocol/result.hpp"

namespace ecsim {

constexpr std::uint16_t kEtherTypeIpv4 = 0x0800;
constexpr std::uint16_t kEtherTypeArp = 0x0806;

// Dotted order: {192, 168, 9, 200} is 192.168.9.200.
using Ipv4Address = std::array<std::uint8_t, 4>;

std::string formatIpv4(const Ipv4Address& address);
// "a.b.c.d", each 0..255; the error names the text.
Result<Ipv4Address> parseIpv4(std::string_view text);
// "aa:bb:cc:dd:ee:ff" (or with '-'); the error names the text.
Result<MacAddress> parseMac(std::string_view text);

// One's complement of the one's complement sum of 16-bit big-endian words (an odd last byte
// is padded with zero). Over a block that holds its own correct checksum it returns 0.
std::uint16_t internetChecksum(ConstBytes bytes);

// ARP for IPv4 over Ethernet: hardware type 1, protocol 0x0800, sizes 6 and 4.
constexpr std::size_t kArpSize = 28;
constexpr std::uint16_t kArpHardwareEthernet = 1;
constexpr std::uint16_t kArpRequest = 1;
constexpr std::uint16_t kArpReply = 2;

struct ArpPacket {
  std::uint16_t operation{kArpRequest};
  MacAddress senderMac{};
  Ipv4Address senderIp{};
  MacAddress targetMac{};
  Ipv4Address targetIp{};

  // Fails on a short packet or one that is not Ethernet/IPv4.
  static Result<ArpPacket> decode(ConstBytes bytes);
  // Writes kArpSize bytes.
  Status encode(Bytes out) const;
};

constexpr std::size_t kIpv4MinHeaderSize = 20;
constexpr std::uint8_t kIpProtocolIcmp = 1;
constexpr std::uint8_t kIpDefaultTtl = 64;

struct Ipv4Header {
  std::size_t headerSize{kIpv4MinHeaderSize};  // IHL * 4
  std::uint8_t tos{0};
  std::uint16_t totalLength{0};
  std::uint16_t identification{0};
  std::uint16_t flagsFragment{0};  // flags (3 bits) and fragment offset
  std::uint8_t ttl{kIpDefaultTtl};
  std::uint8_t protocol{kIpProtocolIcmp};
  Ipv4Address source{};
  Ipv4Address destination{};

  bool isFragment() const;  // more fragments set or a fragment offset
  // Checks version 4, IHL >= 5, total length within `bytes`, header checksum.
  static Result<Ipv4Header> decode(ConstBytes bytes);
  // Writes a 20-byte header (options are not written) with its checksum.
  Status encode(Bytes out) const;
};

constexpr std::size_t kIcmpHeaderSize = 8;
constexpr std::uint8_t kIcmpEchoReply = 0;
constexpr std::uint8_t kIcmpEchoRequest = 8;

}  // namespace ecsim
