#include "protocol/ethernet.hpp"

#include <algorithm>
#include <cstdio>

namespace ecsim {

std::string formatMac(const MacAddress& mac) {
  char text[18];
  std::snprintf(text, sizeof text, "%02x:%02x:%02x:%02x:%02x:%02x", mac[0], mac[1], mac[2], mac[3],
                mac[4], mac[5]);
  return text;
}

Result<EthernetHeader> EthernetHeader::parse(ConstBytes frame) {
  if (frame.size() < kEthernetHeaderSize) {
    return makeError(ErrorCode::kTruncated,
                     "Ethernet header needs 14 bytes, frame has " + std::to_string(frame.size()));
  }
  EthernetHeader h;
  std::copy_n(frame.begin(), 6, h.destination.begin());
  std::copy_n(frame.begin() + 6, 6, h.source.begin());
  std::uint16_t type = readBe16(frame, 12);
  if (type == kEtherTypeVlan) {
    if (frame.size() < kEthernetHeaderSize + kVlanTagSize) {
      return makeError(ErrorCode::kTruncated, "byte 14: VLAN tag truncated");
    }
    h.vlanTci = readBe16(frame, 14);
    type = readBe16(frame, 16);
  }
  h.etherType = type;
  return h;
}

Status EthernetHeader::write(Bytes out) const {
  if (out.size() < size()) {
    return makeError(ErrorCode::kTooLarge, "Ethernet header does not fit in buffer");
  }
  std::copy(destination.begin(), destination.end(), out.begin());
  std::copy(source.begin(), source.end(), out.begin() + 6);
  std::size_t at = 12;
  if (vlanTci) {
    writeBe16(out, at, kEtherTypeVlan);
    writeBe16(out, at + 2, *vlanTci);
    at += 4;
  }
  writeBe16(out, at, etherType);
  return okStatus();
}

}  // namespace ecsim
