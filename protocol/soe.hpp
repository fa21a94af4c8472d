// Servo drive profile over EtherCAT (SoE, ETG.1000.6 §5.9; IEC 61800-7-204 for the IDN model).
//
//   SoE header, 4 bytes after the mailbox header:
//     u8   bits 0-2 opcode (1 read request, 2 read response, 3 write request, 4 write response,
//          5 notification, 6 slave info, 7 reserved), bit 3 incomplete (more fragments follow),
//          bit 4 error, bits 5-7 drive number
//     u8   elements: bit 0 data state, 1 name, 2 attribute, 3 unit, 4 minimum, 5 maximum,
//          6 value (operation data), 7 default value
//     u16  the IDN, or, in a fragment with `incomplete` set, the number of fragments left
//   An error response carries the opcode of the service answered, the error bit and a u16
//   error code as its last two bytes (SOEM ethercatsoe.c reads it there; IgH fsm_soe.c too).
//
//   mailbox: | mailbox header (6) | SoE header (4) | data ... |
//
// IDN (u16): bit 15 S (0, standard) or P (1, product-specific), bits 12-14 parameter set,
// bits 0-11 data block number: "S-0-0016" = 0x0010, "P-0-0009" = 0x8009.
// Attribute (u32, element 3; SOEM ec_SoEattributet, IEC 61800-7-204 §6.2.2.3): bits 0-15
// conversion factor, 16-17 element length (1, 2, 4, 8 bytes), 18 variable length (a list),
// 19 procedure command, 20-22 data type and display (0 binary, 1 unsigned, 2 signed, 3 hex,
// 4 text, 5 IDN, 6 float, 7 parameter), 24-27 decimal places, 28/29/30 write-protected in
// CP2/CP3/CP4 (EtherCAT PREOP/SAFEOP/OP).
// Variable-length data (lists, texts, names, units) starts with u16 current length and u16
// maximum length, both in bytes, followed by the data (SOEM ec_SoElistt, ec_SoEnamet).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/bytes.hpp"
#include "protocol/mailbox.hpp"
#include "protocol/result.hpp"

namespace ecsim {

enum class SoeOpcode : std::uint8_t {
  kReadRequest = 1,
  kReadResponse = 2,
  kWriteRequest = 3,
  kWriteResponse = 4,
  kNotification = 5,
  kSlaveInfo = 6,
};
std::string_view toString(SoeOpcode opcode);

// Element flags (header byte 1).
namespace soe_element {
constexpr std::uint8_t kDataState = 0x01;
constexpr std::uint8_t kName = 0x02;
constexpr std::uint8_t kAttribute = 0x04;
constexpr std::uint8_t kUnit = 0x08;
constexpr std::uint8_t kMinimum = 0x10;
constexpr std::uint8_t kMaximum = 0x20;
constexpr std::uint8_t kValue = 0x40;
constexpr std::uint8_t kDefault = 0x80;
}  // namespace soe_element

constexpr std::size_t kSoeHeaderSize = 4;
constexpr std::size_t kSoeDataOffset = kMailboxHeaderSize + kSoeHeaderSize;  // 10
constexpr std::uint8_t kSoeDriveMax = 7;
constexpr std::size_t kSoeErrorCodeSize = 2;
// Variable-length data: u16 current length + u16 maximum length.
constexpr std::size_t kSoeListHeaderSize = 4;
constexpr std::size_t kSoeDataStateSize = 2;
constexpr std::size_t kSoeAttributeSize = 4;

struct SoeHeader {
  SoeOpcode opcode{SoeOpcode::kReadRequest};  // may hold any 3-bit value after decode
  bool incomplete{false};
  bool error{false};
  std::uint8_t driveNo{0};   // 3 bits
  std::uint8_t elements{0};  // soe_element flags
  std::uint16_t idn{0};      // or fragments left when incomplete

  static Result<SoeHeader> decode(ConstBytes bytes);
  // Fails if out holds fewer than 4 bytes or driveNo > 7.
  Result<std::size_t> encode(Bytes out) const;
  bool operator==(const SoeHeader&) const = default;
};

// A decoded SoE mailbox: headers and the data after the SoE header (a view into the buffer).
struct SoeMessage {
  MailboxHeader mailbox;
  SoeHeader soe;
  ConstBytes data;
};
Result<SoeMessage> decodeSoeMailbox(ConstBytes buffer);
Result<SoeMessage> decodeSoeMailbox(std::vector<std::uint8_t>&&) = delete;  // would dangle
// Decodes the payload of a mailbox already known to be SoE.
Result<SoeMessage> decodeSoePayload(const MailboxMessage& message);

// A complete SoE mailbox (header type SoE, length 4 + data; other mailbox fields from
// `mailbox`).
Result<std::vector<std::uint8_t>> encodeSoeMailbox(const SoeHeader& soe, ConstBytes data,
                                                   MailboxHeader mailbox = {});
// An error response to `request`: its opcode's response, the error bit, `code` as data.
Result<std::vector<std::uint8_t>> encodeSoeError(const SoeHeader& request, std::uint16_t code);

// IDN text: "S-0-0016", "P-0-0009" (parameter set 0-7, block number 0-4095).
std::string formatIdn(std::uint16_t idn);
// Reads "S-0-0016", "P-0-9", "s-0-16" or a plain number (decimal or 0x hex).
Result<std::uint16_t> parseIdn(std::string_view text);
constexpr std::uint16_t kIdnProductSpecific = 0x8000;
constexpr unsigned kIdnSetShift = 12;
constexpr std::uint16_t kIdnSetMask = 0x7;
constexpr std::uint16_t kIdnBlockMask = 0x0FFF;

enum class SoeDataType : std::uint8_t {
  kBinary = 0,
  kUnsigned = 1,
  kSigned = 2,
  kHex = 3,
  kText = 4,
  kIdn = 5,
  kFloat = 6,
  kParameter = 7,
};

struct SoeAttribute {
  std::uint32_t raw{0};

  std::uint16_t conversionFactor() const { return static_cast<std::uint16_t>(raw & 0xFFFF); }
  // Bytes per element: 1, 2, 4 or 8.
  std::size_t elementSize() const { return std::size_t{1} << ((raw >> 16) & 0x3); }
  bool isList() const { return ((raw >> 18) & 1) != 0; }
  bool isProcedureCommand() const { return ((raw >> 19) & 1) != 0; }
  SoeDataType dataType() const { return static_cast<SoeDataType>((raw >> 20) & 0x7); }
  unsigned decimals() const { return (raw >> 24) & 0xF; }
  // Communication phase 2, 3, 4 = EtherCAT PREOP, SAFEOP, OP (ETG.1000.6 §5.9).
  bool writeProtectedInPhase(unsigned phase) const {
    return phase >= 2 && phase <= 4 && ((raw >> (26 + phase)) & 1) != 0;
  }
  bool readOnly() const {
    return writeProtectedInPhase(2) && writeProtectedInPhase(3) && writeProtectedInPhase(4);
  }
  // "u16", "i32", "u16 list", "text", "IDN list", "command"
  std::string describe() const;
  static SoeAttribute make(std::size_t elementSize, bool list, bool command, SoeDataType type,
                           bool wpPreop, bool wpSafeop, bool wpOp);
};

// One element's value, little-endian, of 1 to 8 bytes, sign-extended when `isSigned` (the
// data types kSigned; every other type reads unsigned).
std::int64_t soeNumber(ConstBytes element, bool isSigned);

// Error codes (IEC 61800-7-204; SOEM ethercatprint.c and IgH soe_errors.c list the same).
namespace soe_error {
constexpr std::uint16_t kNoIdn = 0x1001;
constexpr std::uint16_t kInvalidAccessElement1 = 0x1009;
constexpr std::uint16_t kNoName = 0x2001;
constexpr std::uint16_t kNameReadOnly = 0x2004;
constexpr std::uint16_t kAttributeReadOnly = 0x3004;
constexpr std::uint16_t kNoUnit = 0x4001;
constexpr std::uint16_t kUnitReadOnly = 0x4004;
constexpr std::uint16_t kNoMinimum = 0x5001;
constexpr std::uint16_t kMinimumReadOnly = 0x5004;
constexpr std::uint16_t kNoMaximum = 0x6001;
constexpr std::uint16_t kMaximumReadOnly = 0x6004;
constexpr std::uint16_t kDataTooShort = 0x7002;
constexpr std::uint16_t kDataTooLong = 0x7003;
constexpr std::uint16_t kDataReadOnly = 0x7004;
constexpr std::uint16_t kDataWriteProtectedNow = 0x7005;
constexpr std::uint16_t kDataBelowMinimum = 0x7006;
constexpr std::uint16_t kDataAboveMaximum = 0x7007;
constexpr std::uint16_t kConfiguredIdnNotSupported = 0x7008;
constexpr std::uint16_t kCommandAlreadyActive = 0x7010;
constexpr std::uint16_t kCommandNotExecutableNow = 0x7012;
constexpr std::uint16_t kCommandInvalidParameters = 0x7013;
constexpr std::uint16_t kNoDataState = 0x7014;
constexpr std::uint16_t kNoDefault = 0x8001;
constexpr std::uint16_t kDefaultReadOnly = 0x8004;
constexpr std::uint16_t kInvalidDriveNumber = 0x800A;
constexpr std::uint16_t kGeneralError = 0x800B;
constexpr std::uint16_t kNoElementAddressed = 0x800C;
}  // namespace soe_error
// "No IDN", ...; "unknown SoE error" when not listed.
std::string_view soeErrorText(std::uint16_t code);

// Procedure command acknowledgement in the data state element (IEC 61800-7-204; Rexroth's
// IndraDrive manual, "command acknowledgement"): 0 cancelled, 0x3 executed correctly,
// 0x5 interrupted, 0x7 in progress, 0xF error (not executable). The command's value is
// what the master wrote: 0 cancel, 1 set, 3 set and enable.
namespace soe_command {
constexpr std::uint16_t kCancel = 0x0;
constexpr std::uint16_t kSet = 0x1;
constexpr std::uint16_t kSetAndEnable = 0x3;
constexpr std::uint16_t kStateCancelled = 0x0;
constexpr std::uint16_t kStateExecuted = 0x3;
constexpr std::uint16_t kStateInterrupted = 0x5;
constexpr std::uint16_t kStateInProgress = 0x7;
constexpr std::uint16_t kStateError = 0xF;
}  // namespace soe_command

// Variable-length data: header + bytes.
std::vector<std::uint8_t> encodeSoeList(ConstBytes data, std::uint16_t maxLength);
struct SoeList {
  std::uint16_t currentLength{0};
  std::uint16_t maxLength{0};
  ConstBytes data;  // currentLength bytes
};
// Fails when fewer than 4 bytes or currentLength runs past the bytes.
Result<SoeList> decodeSoeList(ConstBytes bytes);

// The elements of a read response, split by the flags that were asked, in element order
// (data state, name, attribute, unit, minimum, maximum, value, default). A fixed-length value
// (and its minimum, maximum, default) takes attribute.elementSize() bytes, so to split those
// the attribute must be known (asked in the same read, or given).
struct SoeElements {
  std::uint16_t dataState{0};
  std::string name;
  SoeAttribute attribute;
  std::string unit;
  std::vector<std::uint8_t> minimum;
  std::vector<std::uint8_t> maximum;
  std::vector<std::uint8_t> value;  // a list's value includes its 4-byte header
  std::vector<std::uint8_t> defaultValue;
};
Result<SoeElements> splitSoeElements(std::uint8_t elements, ConstBytes data,
                                     SoeAttribute attribute = {});

}  // namespace ecsim
