// CANopen over EtherCAT (ETG.1000.6 §5.6.2): the 2-byte CoE header that follows the mailbox
// header, and the emergency message (service 1). SDO and SDO information live in sdo.hpp and
// sdo_info.hpp.
//
//   CoE header, u16 little-endian: bits 0-8 number (PDO number, else 0), bits 9-11 reserved,
//   bits 12-15 service.
//   Emergency body: u16 error code, u8 error register, 5 bytes manufacturer-specific data.
//
//   mailbox: | mailbox header (6) | CoE header (2) | body ... |
//            0                    6                8
#pragma once

#include <array>
#include <cstdint>
#include <iterator>
#include <string_view>
#include <vector>

#include "protocol/bytes.hpp"
#include "protocol/mailbox.hpp"
#include "protocol/result.hpp"

namespace ecsim {

// The length in bits of a CiA 301 §7.4.8.3 dummy mapping entry: the index of a standard data
// type 0x0001-0x0007 (BOOLEAN ... UNSIGNED32), subindex 0, maps no object but pads the PDO by
// that type's length. 0 for any other index.
constexpr std::uint8_t dummyEntryBits(std::uint16_t index) {
  constexpr std::uint8_t kBits[] = {0, 1, 8, 16, 32, 8, 16, 32};
  return index < std::size(kBits) ? kBits[index] : 0;
}
// A mapping entry that maps no object: a gap (index 0) or a dummy entry.
constexpr bool isPaddingEntry(std::uint16_t index) {
  return index == 0 || dummyEntryBits(index) != 0;
}

enum class CoeService : std::uint8_t {
  kEmergency = 1,
  kSdoRequest = 2,
  kSdoResponse = 3,
  kTxPdo = 4,
  kRxPdo = 5,
  kTxPdoRemoteRequest = 6,
  kRxPdoRemoteRequest = 7,
  kSdoInformation = 8,
};

std::string_view toString(CoeService service);

constexpr std::size_t kCoeHeaderSize = 2;
constexpr std::size_t kCoeBodyOffset = kMailboxHeaderSize + kCoeHeaderSize;  // 8
constexpr std::uint16_t kCoeNumberMax = 0x01FF;

struct CoeHeader {
  std::uint16_t number{0};                      // 9 bits
  CoeService service{CoeService::kSdoRequest};  // may hold any 4-bit value after decode

  static CoeHeader fromRaw(std::uint16_t raw) {
    return {static_cast<std::uint16_t>(raw & kCoeNumberMax), static_cast<CoeService>(raw >> 12)};
  }
  std::uint16_t raw() const {
    return static_cast<std::uint16_t>((number & kCoeNumberMax) |
                                      (static_cast<std::uint16_t>(service) << 12));
  }
  static Result<CoeHeader> decode(ConstBytes bytes);
  // Fails if out is shorter than 2 bytes or number > 511 or service > 15.
  Result<std::size_t> encode(Bytes out) const;

  bool operator==(const CoeHeader&) const = default;
};

// A CoE mailbox: the mailbox header, the CoE header and the body (the mailbox payload after
// the CoE header, a view into the decoded buffer).
struct CoeMessage {
  MailboxHeader mailbox;
  CoeHeader coe;
  ConstBytes body;
};

// Decodes a mailbox buffer that must carry CoE (type 3) with at least the CoE header. Errors
// name the byte offset within `buffer`.
Result<CoeMessage> decodeCoeMailbox(ConstBytes buffer);
Result<CoeMessage> decodeCoeMailbox(std::vector<std::uint8_t>&&) = delete;  // would dangle

// Writes the mailbox header (type CoE, length 2 + bodyLength; other fields from `mailbox`) and
// the CoE header in front of a body the caller has placed at out[kCoeBodyOffset...]. Returns
// the total mailbox size.
Result<std::size_t> finishCoeMailbox(Bytes out, MailboxHeader mailbox, CoeHeader coe,
                                     std::size_t bodyLength);

// Emergency (CoE service 1).
struct Emergency {
  static constexpr std::size_t kSize = 8;

  std::uint16_t errorCode{0};
  std::uint8_t errorRegister{0};
  std::array<std::uint8_t, 5> data{};  // manufacturer-specific

  // Decodes a CoE body (after the CoE header); at least 8 bytes.
  static Result<Emergency> decode(ConstBytes body);
  Result<std::size_t> encode(Bytes out) const;

  bool operator==(const Emergency&) const = default;
};

// A complete emergency mailbox (mailbox header + CoE header + 8 bytes).
Result<std::size_t> encodeEmergencyMailbox(Bytes out, const Emergency& emergency,
                                           MailboxHeader mailbox = {});
// Decodes a complete mailbox that must be a CoE emergency.
Result<Emergency> decodeEmergencyMailbox(ConstBytes buffer);

}  // namespace ecsim
