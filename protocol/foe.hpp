// File access over EtherCAT (FoE, ETG.1000.6 §5.7): the 6-byte FoE header that follows the
// mailbox header (type 4), its opcodes and error codes.
//
//   FoE header: u8 opcode, u8 reserved (0), u32 little-endian whose meaning depends on the
//   opcode, then the opcode's data up to the end of the mailbox:
//     1 RRQ   read request    u32 password       file name (no terminator)
//     2 WRQ   write request   u32 password       file name
//     3 DATA  data            u32 packet number  file data (1, 2, ...)
//     4 ACK   acknowledge     u32 packet number  -   (0 answers a WRQ)
//     5 ERR   error           u32 error code     error text (optional)
//     6 BUSY  busy            u16 done, u16 entire  busy text (optional)
//
//   mailbox: | mailbox header (6) | FoE header (6) | data ... |
//            0                    6                12
//
//   A DATA packet carries as much file data as the receiver's mailbox holds (its mailbox size
//   minus the 12 header bytes); a packet shorter than that ends the file, so a file whose size
//   is a multiple of it ends with an empty packet (SOEM's ecx_FOEwrite "dofinalzero").
// Opcodes and error codes as ETG.1000.6 Table 92 lists them and SOEM (ethercattype.h ec_foe
// opcodes) and SOES (esc.h FOE_OP_* / FOE_ERR_*) use them.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "protocol/bytes.hpp"
#include "protocol/mailbox.hpp"
#include "protocol/result.hpp"

namespace ecsim {

enum class FoeOpcode : std::uint8_t {
  kRead = 1,
  kWrite = 2,
  kData = 3,
  kAck = 4,
  kError = 5,
  kBusy = 6,
};

// "RRQ", "WRQ", "DATA", "ACK", "ERR", "BUSY"; "unknown" for other values.
std::string_view toString(FoeOpcode opcode);

enum class FoeErrorCode : std::uint32_t {
  kNotDefined = 0x8000,
  kNotFound = 0x8001,
  kAccessDenied = 0x8002,
  kDiskFull = 0x8003,
  kIllegal = 0x8004,
  kPacketNumberWrong = 0x8005,
  kAlreadyExists = 0x8006,
  kNoUser = 0x8007,
  kBootstrapOnly = 0x8008,
  kNotBootstrap = 0x8009,  // SOES: a boot-only file written outside BOOT
  kNoRights = 0x800A,      // SOES: wrong password
  kProgramError = 0x800B,
};

// "not found", "access denied", ...; "unknown FoE error" when not listed.
std::string_view foeErrorText(std::uint32_t code);
// "0x8001 (not found)"
std::string describeFoeError(std::uint32_t code);

constexpr std::size_t kFoeHeaderSize = 6;
constexpr std::size_t kFoeDataOffset = kMailboxHeaderSize + kFoeHeaderSize;  // 12

// File data one DATA packet carries through a mailbox of `mailboxSize` bytes (0 if none fit).
constexpr std::size_t foeDataPerPacket(std::size_t mailboxSize) {
  return mailboxSize > kFoeDataOffset ? mailboxSize - kFoeDataOffset : 0;
}

struct FoePacket {
  FoeOpcode opcode{FoeOpcode::kData};  // may hold any byte after decode
  // Password (RRQ/WRQ), packet number (DATA/ACK), error code (ERR), done | entire << 16 (BUSY).
  std::uint32_t value{0};
  ConstBytes data;  // file name, file data or text: a view into the decoded payload

  std::uint16_t busyDone() const { return static_cast<std::uint16_t>(value & 0xFFFF); }
  std::uint16_t busyEntire() const { return static_cast<std::uint16_t>(value >> 16); }
  std::string_view text() const {
    return {reinterpret_cast<const char*>(data.data()), data.size()};
  }
};

// Decodes the payload of an FoE mailbox (the bytes after the mailbox header). Fails when it is
// shorter than the FoE header; an unknown opcode is kept (the receiver answers it).
Result<FoePacket> decodeFoe(ConstBytes payload);

// A complete FoE mailbox (mailbox header with type FoE and counter 0, FoE header, data).
std::vector<std::uint8_t> encodeFoeMailbox(FoeOpcode opcode, std::uint32_t value,
                                           ConstBytes data = {});
inline std::vector<std::uint8_t> encodeFoeMailbox(FoeOpcode opcode, std::uint32_t value,
                                                  std::string_view text) {
  return encodeFoeMailbox(
      opcode, value, ConstBytes(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}
inline std::uint32_t foeBusyValue(std::uint16_t done, std::uint16_t entire) {
  return static_cast<std::uint32_t>(done) | (static_cast<std::uint32_t>(entire) << 16);
}

}  // namespace ecsim
