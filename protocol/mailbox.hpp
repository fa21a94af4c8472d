// EtherCAT mailbox header and mailbox error reply (ETG.1000.4 §5.6 / ETG.1000.6 §5.6).
//
//   Mailbox header, 6 bytes, little-endian:
//     u16 length    number of bytes after the header
//     u16 address   station address of the originator (0 when the master sends)
//     u8            bits 0-5 channel, bits 6-7 priority
//     u8            bits 0-3 type (0 error, 1 AoE, 2 EoE, 3 CoE, 4 FoE, 5 SoE, 15 VoE),
//                   bits 4-6 counter (1..7 in use, 0 = not counted), bit 7 reserved
//   Mailbox error reply (type 0): u16 service type (0x0001), u16 detail code.
//
// A mailbox lives in a SyncManager buffer that is usually longer than the message: decoding
// takes the whole buffer, honours `length` and ignores the bytes after it.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "protocol/bytes.hpp"
#include "protocol/result.hpp"

namespace ecsim {

enum class MailboxType : std::uint8_t {
  kError = 0,
  kAoe = 1,
  kEoe = 2,
  kCoe = 3,
  kFoe = 4,
  kSoe = 5,
  kVoe = 15,
};

// "ERR", "AoE", "EoE", "CoE", "FoE", "SoE", "VoE"; "unknown" for the reserved values.
std::string_view toString(MailboxType type);
bool isKnownMailboxType(std::uint8_t raw);

constexpr std::size_t kMailboxHeaderSize = 6;
constexpr std::uint8_t kMailboxChannelMax = 0x3F;
constexpr std::uint8_t kMailboxPriorityMax = 0x03;
constexpr std::uint8_t kMailboxCounterMax = 0x07;

struct MailboxHeader {
  std::uint16_t length{0};              // bytes after the header
  std::uint16_t address{0};             // originator's station address (0 from the master)
  std::uint8_t channel{0};              // 6 bits
  std::uint8_t priority{0};             // 2 bits
  MailboxType type{MailboxType::kCoe};  // may hold a reserved 4-bit value after decode
  std::uint8_t counter{0};              // 3 bits

  // Reads the 6 header bytes; fails only when fewer than 6 bytes are given. A reserved type
  // value is kept (a slave answers it with a mailbox error, not a decode failure).
  static Result<MailboxHeader> decode(ConstBytes bytes);
  // Writes 6 bytes at the start of out. Fails when out is shorter or a field does not fit
  // its bits (channel > 63, priority > 3, counter > 7, type > 15).
  Result<std::size_t> encode(Bytes out) const;

  bool operator==(const MailboxHeader&) const = default;
};

// The counter that follows `counter` in the 1..7 cycle masters and slaves use (0 -> 1, 7 -> 1).
constexpr std::uint8_t nextMailboxCounter(std::uint8_t counter) {
  return static_cast<std::uint8_t>(counter % kMailboxCounterMax + 1);
}

// A decoded mailbox: its header and exactly `header.length` payload bytes (a view into the
// buffer given to decodeMailbox).
struct MailboxMessage {
  MailboxHeader header;
  ConstBytes payload;
};

// Checks that the header fits and that `length` does not run past the buffer. Errors name the
// byte offset within `buffer`.
Result<MailboxMessage> decodeMailbox(ConstBytes buffer);
// The result views the buffer: decoding a temporary vector would leave it dangling.
Result<MailboxMessage> decodeMailbox(std::vector<std::uint8_t>&&) = delete;

// Writes `header` with its length set to payloadLength in front of a payload the caller has
// already placed at out[kMailboxHeaderSize...]. Returns the total size (header + payload).
Result<std::size_t> finishMailbox(Bytes out, MailboxHeader header, std::size_t payloadLength);

// Mailbox error reply (mailbox type 0).
constexpr std::uint16_t kMailboxErrorServiceType = 0x0001;
constexpr std::size_t kMailboxErrorSize = 4;

enum class MailboxErrorCode : std::uint16_t {
  kSyntax = 0x0001,
  kUnsupportedProtocol = 0x0002,
  kInvalidChannel = 0x0003,
  kServiceNotSupported = 0x0004,
  kInvalidHeader = 0x0005,
  kSizeTooShort = 0x0006,
  kNoMoreMemory = 0x0007,
  kInvalidSize = 0x0008,
};

// Description of a mailbox error detail code; "unknown mailbox error" if not listed.
std::string_view mailboxErrorText(std::uint16_t detail);
inline std::string_view mailboxErrorText(MailboxErrorCode detail) {
  return mailboxErrorText(static_cast<std::uint16_t>(detail));
}

struct MailboxErrorReply {
  std::uint16_t detail{0};  // a MailboxErrorCode value, kept raw

  // Decodes the payload of a type-0 mailbox (service type must be 0x0001).
  static Result<MailboxErrorReply> decode(ConstBytes payload);
  // Writes the 4 payload bytes.
  Result<std::size_t> encode(Bytes out) const;

  bool operator==(const MailboxErrorReply&) const = default;
};

// A complete type-0 mailbox (header + error reply). header.type and header.length are set by
// the function; the other header fields are taken from `header`.
Result<std::size_t> encodeMailboxError(Bytes out, MailboxErrorCode detail,
                                       MailboxHeader header = {});

}  // namespace ecsim
