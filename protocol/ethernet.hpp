// Ethernet II header, with an optional IEEE 802.1Q VLAN tag, as carried before EtherCAT.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "protocol/bytes.hpp"
#include "protocol/result.hpp"

namespace ecsim {

constexpr std::uint16_t kEtherTypeEtherCat = 0x88A4;
constexpr std::uint16_t kEtherTypeVlan = 0x8100;
constexpr std::size_t kEthernetHeaderSize = 14;
constexpr std::size_t kVlanTagSize = 4;
constexpr std::size_t kMaxFrameSize = 1514;  // without FCS (1518 on the wire with FCS)
constexpr std::size_t kMinFrameSize = 60;    // without FCS (64 with FCS)
// 100BASE-TX, EtherCAT's speed: a byte takes 80 ns on the wire.
constexpr std::int64_t kNsPerByte100Mbit = 80;

using MacAddress = std::array<std::uint8_t, 6>;

constexpr MacAddress kBroadcastMac{0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF};

std::string formatMac(const MacAddress& mac);

struct EthernetHeader {
  MacAddress destination{};
  MacAddress source{};
  std::optional<std::uint16_t> vlanTci;  // present when the frame carries an 802.1Q tag
  std::uint16_t etherType{kEtherTypeEtherCat};

  std::size_t size() const { return kEthernetHeaderSize + (vlanTci ? kVlanTagSize : 0); }

  // Parses the header; the payload starts at size().
  static Result<EthernetHeader> parse(ConstBytes frame);
  // Writes size() bytes at the start of out; error if out is too small.
  Status write(Bytes out) const;

  bool operator==(const EthernetHeader&) const = default;
};

}  // namespace ecsim
