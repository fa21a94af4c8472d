// SDO information service (CoE service 8, ETG.1000.6 §5.6.3): object dictionary lists, object
// and entry descriptions. What SOEM parses is summarised in ../shared/notes/soem-interop.md §3.5.
//
//   CoE body: u8 opcode (bits 0-6; bit 7 = incomplete, more fragments follow), u8 reserved,
//             u16 fragments left, then the service data.
//   0x01 Get OD list request            u16 list type
//   0x02 Get OD list response           u16 list type, u16 index... (fragmented)
//   0x03 Get object description request  u16 index
//   0x04 Get object description response u16 index, u16 data type, u8 max subindex,
//                                        u8 object code (7 VAR, 8 ARRAY, 9 RECORD), name
//   0x05 Get entry description request  u16 index, u8 subindex, u8 value info
//   0x06 Get entry description response u16 index, u8 subindex, u8 value info, u16 data type,
//                                        u16 bit length, u16 object access, [u16 unit type]
//                                        [default] [minimum] [maximum], name
//        (the bracketed fields are present when value-info bits 3/4/5/6 are set; each value has
//        (bit length + 7) / 8 bytes — the layout Wireshark's dissector and Beckhoff's SSC use)
//   0x07 SDO information error          u32 abort code
//
// A long response is one byte stream split across mailboxes: every fragment carries the 4-byte
// header, the first has the largest `fragments left`, the last has 0 and the incomplete bit
// clear. SdoInfoFragmenter splits (into even-sized pieces, as SOEM reads whole u16 indexes per
// fragment) and SdoInfoReassembler joins.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "protocol/bytes.hpp"
#include "protocol/coe.hpp"
#include "protocol/mailbox.hpp"
#include "protocol/result.hpp"

namespace ecsim {

enum class SdoInfoOpcode : std::uint8_t {
  kGetOdListRequest = 0x01,
  kGetOdListResponse = 0x02,
  kGetObjectDescriptionRequest = 0x03,
  kGetObjectDescriptionResponse = 0x04,
  kGetEntryDescriptionRequest = 0x05,
  kGetEntryDescriptionResponse = 0x06,
  kError = 0x07,
};

std::string_view toString(SdoInfoOpcode opcode);

constexpr std::size_t kSdoInfoHeaderSize = 4;
constexpr std::uint8_t kSdoInfoOpcodeMask = 0x7F;
constexpr std::uint8_t kSdoInfoIncompleteFlag = 0x80;
// Mailbox bytes before the service data: mailbox header, CoE header, SDO-info header.
constexpr std::size_t kSdoInfoDataOffset = kCoeBodyOffset + kSdoInfoHeaderSize;  // 12

struct SdoInfoHeader {
  SdoInfoOpcode opcode{SdoInfoOpcode::kGetOdListRequest};  // may hold any 7-bit value
  bool incomplete{false};
  std::uint16_t fragmentsLeft{0};

  static Result<SdoInfoHeader> decode(ConstBytes body);
  Result<std::size_t> encode(Bytes out) const;
  bool operator==(const SdoInfoHeader&) const = default;
};

// OD list types (Get OD list request / response).
enum class OdListType : std::uint16_t {
  kLengths = 0,  // response: five u16 counts, one per list type 1..5
  kAll = 1,
  kRxPdoMappable = 2,
  kTxPdoMappable = 3,
  kBackup = 4,
  kSettings = 5,
};

// Object codes (Get object description response).
enum class ObjectCode : std::uint8_t { kVar = 7, kArray = 8, kRecord = 9 };

// Value-info bits (Get entry description request / response).
constexpr std::uint8_t kValueInfoUnitType = 0x08;
constexpr std::uint8_t kValueInfoDefault = 0x10;
constexpr std::uint8_t kValueInfoMinimum = 0x20;
constexpr std::uint8_t kValueInfoMaximum = 0x40;

// Object access bits (Get entry description response).
constexpr std::uint16_t kAccessReadPreOp = 0x0001;
constexpr std::uint16_t kAccessReadSafeOp = 0x0002;
constexpr std::uint16_t kAccessReadOp = 0x0004;
constexpr std::uint16_t kAccessWritePreOp = 0x0008;
constexpr std::uint16_t kAccessWriteSafeOp = 0x0010;
constexpr std::uint16_t kAccessWriteOp = 0x0020;
constexpr std::uint16_t kAccessRxPdoMappable = 0x0040;
constexpr std::uint16_t kAccessTxPdoMappable = 0x0080;
constexpr std::uint16_t kAccessBackup = 0x0100;
constexpr std::uint16_t kAccessSettings = 0x0200;

// --- service data ---------------------------------------------------------------------------
// encode() writes the service data (after the SDO-info header) and fails with kTooLarge rather
// than overflow out; decode() reads it and names byte offsets within the service data.

struct OdListRequest {
  std::uint16_t listType{static_cast<std::uint16_t>(OdListType::kAll)};
  static Result<OdListRequest> decode(ConstBytes data);
  Result<std::size_t> encode(Bytes out) const;
  bool operator==(const OdListRequest&) const = default;
};

struct ObjectDescriptionRequest {
  std::uint16_t index{0};
  static Result<ObjectDescriptionRequest> decode(ConstBytes data);
  Result<std::size_t> encode(Bytes out) const;
  bool operator==(const ObjectDescriptionRequest&) const = default;
};

struct EntryDescriptionRequest {
  std::uint16_t index{0};
  std::uint8_t subindex{0};
  std::uint8_t valueInfo{0};
  static Result<EntryDescriptionRequest> decode(ConstBytes data);
  Result<std::size_t> encode(Bytes out) const;
  bool operator==(const EntryDescriptionRequest&) const = default;
};

// The complete (reassembled) OD list response.
struct OdList {
  std::uint16_t listType{static_cast<std::uint16_t>(OdListType::kAll)};
  std::vector<std::uint16_t> indexes;

  std::size_t encodedSize() const { return 2 + 2 * indexes.size(); }
  static Result<OdList> decode(ConstBytes data);
  Result<std::size_t> encode(Bytes out) const;
  bool operator==(const OdList&) const = default;
};

struct ObjectDescription {
  std::uint16_t index{0};
  std::uint16_t dataType{0};
  std::uint8_t maxSubindex{0};
  std::uint8_t objectCode{static_cast<std::uint8_t>(ObjectCode::kVar)};
  std::string name;

  std::size_t encodedSize() const { return 6 + name.size(); }
  static Result<ObjectDescription> decode(ConstBytes data);
  Result<std::size_t> encode(Bytes out) const;
  bool operator==(const ObjectDescription&) const = default;
};

struct EntryDescription {
  std::uint16_t index{0};
  std::uint8_t subindex{0};
  std::uint8_t valueInfo{0};  // selects the optional fields below
  std::uint16_t dataType{0};
  std::uint16_t bitLength{0};
  std::uint16_t objectAccess{0};
  std::uint16_t unitType{0};               // present with kValueInfoUnitType
  std::vector<std::uint8_t> defaultValue;  // kValueInfoDefault, (bitLength + 7) / 8 bytes
  std::vector<std::uint8_t> minimumValue;  // kValueInfoMinimum, same size
  std::vector<std::uint8_t> maximumValue;  // kValueInfoMaximum, same size
  std::string name;

  std::size_t valueSize() const { return (static_cast<std::size_t>(bitLength) + 7) / 8; }
  std::size_t encodedSize() const;
  static Result<EntryDescription> decode(ConstBytes data);
  // Fails with kInvalidArgument when a value selected by valueInfo does not have valueSize()
  // bytes.
  Result<std::size_t> encode(Bytes out) const;
  bool operator==(const EntryDescription&) const = default;
};

struct SdoInfoError {
  std::uint32_t abortCode{0};
  static Result<SdoInfoError> decode(ConstBytes data);
  Result<std::size_t> encode(Bytes out) const;
  bool operator==(const SdoInfoError&) const = default;
};

using SdoInfoRequest =
    std::variant<OdListRequest, ObjectDescriptionRequest, EntryDescriptionRequest>;
using SdoInfoResponse = std::variant<OdList, ObjectDescription, EntryDescription, SdoInfoError>;

SdoInfoOpcode opcodeOf(const SdoInfoRequest& request);
SdoInfoOpcode opcodeOf(const SdoInfoResponse& response);

// --- mailboxes ----------------------------------------------------------------------------------

// One SDO-info mailbox: headers and the service data of this fragment (a view into the buffer).
struct SdoInfoMessage {
  MailboxHeader mailbox;
  SdoInfoHeader header;
  ConstBytes data;
};

// Decodes a mailbox that must carry CoE service 8 with the 4-byte SDO-info header. Errors name
// the byte offset within `buffer`.
Result<SdoInfoMessage> decodeSdoInfoMailbox(ConstBytes buffer);
Result<SdoInfoMessage> decodeSdoInfoMailbox(std::vector<std::uint8_t>&&) = delete;  // dangles

// A request as the slave sees it: the single-fragment service data of a decoded message.
Result<SdoInfoRequest> decodeSdoInfoRequest(const SdoInfoMessage& message);
// A single-fragment response (fragments left 0, incomplete clear). Use SdoInfoReassembler first
// for fragmented responses and decodeSdoInfoResponse(opcode, data) on its result.
Result<SdoInfoResponse> decodeSdoInfoResponse(const SdoInfoMessage& message);
Result<SdoInfoResponse> decodeSdoInfoResponse(SdoInfoOpcode opcode, ConstBytes data);

// Complete single-fragment mailboxes. Fail with kTooLarge if the message does not fit out.
Result<std::size_t> encodeSdoInfoRequestMailbox(Bytes out, const SdoInfoRequest& request,
                                                MailboxHeader mailbox = {});
Result<std::size_t> encodeSdoInfoResponseMailbox(Bytes out, const SdoInfoResponse& response,
                                                 MailboxHeader mailbox = {});

// Splits the service data of one response over mailboxes of `mailboxSize` bytes (the slave's
// send mailbox, SyncManager 1 length, headers included). Each fragment carries up to
// fragmentCapacity() bytes, an even number. Views serviceData: keep it alive.
class SdoInfoFragmenter {
 public:
  // Fails when the mailbox cannot carry 2 bytes of service data (mailboxSize < 14) or the
  // data would need more than 65536 fragments.
  static Result<SdoInfoFragmenter> create(SdoInfoOpcode opcode, ConstBytes serviceData,
                                          std::size_t mailboxSize);

  std::size_t fragmentCapacity() const { return capacity_; }
  std::size_t fragmentCount() const { return count_; }
  // Writes fragment `fragment` (0 = first) as a complete mailbox.
  Result<std::size_t> encodeFragment(std::size_t fragment, Bytes out,
                                     MailboxHeader mailbox = {}) const;

 private:
  SdoInfoFragmenter(SdoInfoOpcode opcode, ConstBytes data, std::size_t capacity, std::size_t count)
      : opcode_(opcode), data_(data), capacity_(capacity), count_(count) {}
  SdoInfoOpcode opcode_;
  ConstBytes data_;
  std::size_t capacity_;
  std::size_t count_;
};

// Joins the fragments of one response in arrival order. An SDO-info error (opcode 7) ends the
// sequence at once. add() fails, and the reassembler resets, when a fragment does not follow
// its predecessor (opcode change, fragments-left not one less, fragment after the last).
class SdoInfoReassembler {
 public:
  Status add(const SdoInfoMessage& fragment);
  bool complete() const { return complete_; }
  bool started() const { return started_; }
  SdoInfoOpcode opcode() const { return opcode_; }
  ConstBytes data() const { return data_; }
  void reset();

 private:
  std::vector<std::uint8_t> data_;
  SdoInfoOpcode opcode_{SdoInfoOpcode::kGetOdListResponse};
  std::uint16_t fragmentsLeft_{0};
  bool started_{false};
  bool complete_{false};
};

}  // namespace ecsim
