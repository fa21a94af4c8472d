// SDO transfers over CoE (CiA 301 §7.2.4.3 as carried by ETG.1000.6 §5.6.2): requests
// (CoE service 2, master -> slave) and responses (service 3), plus the SDO abort codes.
// Abort SDO Transfer is a request in either direction: a slave's abort travels as CoE
// service 2 (ETG.1000.6 table of CoE services; SOES SDO_abort() sends COE_SDOREQUEST).
//
// SDO body (everything after the CoE header), at least 8 bytes:
//   byte 0      command: bits 5-7 command specifier, bits 0-4 depend on it (below)
//   bytes 1-2   index, byte 3 subindex        (initiate and abort messages)
//   bytes 4-7   expedited data | complete size (normal) | abort code | reserved
//   bytes 8...  data of a normal (non-expedited) initiate message
//
//   initiate download request (ccs 1), initiate upload response (scs 2):
//     bit 0 size indicated, bit 1 expedited, bits 2-3 bytes of 4 not used (expedited + size
//     indicated), bit 4 complete access (CoE)
//   initiate upload request (ccs 2), initiate download response (scs 3): bit 4 complete access
//   download segment request (ccs 0), upload segment response (scs 0):
//     bit 0 last segment, bits 1-3 bytes of 7 not used, bit 4 toggle; data from byte 1. A
//     segment shorter than 7 bytes is padded to 7; a longer one fills the mailbox.
//   upload segment request (ccs 3), download segment response (scs 1): bit 4 toggle
//   abort (cs 4) in either direction: index, subindex, u32 abort code
//
// The message structs hold their data as a view (ConstBytes) into the buffer they were decoded
// from, or that the caller provides for encoding: no allocation.
#pragma once

#include <cstdint>
#include <string_view>
#include <variant>
#include <vector>

#include "protocol/bytes.hpp"
#include "protocol/coe.hpp"
#include "protocol/mailbox.hpp"
#include "protocol/result.hpp"

namespace ecsim {

constexpr std::size_t kSdoMinBodySize = 8;        // command + 7 bytes
constexpr std::size_t kSdoExpeditedMaxData = 4;   // data carried in the command itself
constexpr std::size_t kSdoNormalHeaderSize = 8;   // command, index, subindex, complete size
constexpr std::size_t kSdoSegmentPaddedData = 7;  // a short segment is padded to 7 bytes

// Largest data of a normal initiate message / of one segment in a mailbox of `mailboxSize`
// bytes (mailbox header included, i.e. the SyncManager length).
constexpr std::size_t sdoNormalDataCapacity(std::size_t mailboxSize) {
  return mailboxSize > kCoeBodyOffset + kSdoNormalHeaderSize
             ? mailboxSize - kCoeBodyOffset - kSdoNormalHeaderSize
             : 0;
}
constexpr std::size_t sdoSegmentDataCapacity(std::size_t mailboxSize) {
  return mailboxSize > kCoeBodyOffset + 1 ? mailboxSize - kCoeBodyOffset - 1 : 0;
}

// --- messages -----------------------------------------------------------------------------

// Initiate download request and initiate upload response share one layout.
//   expedited: data holds 1-4 bytes (exactly 4 when !sizeIndicated); completeSize is set to
//              data.size() by decode and ignored by encode.
//   normal:    completeSize is the size of the whole object data; data is the part carried in
//              this message (the rest follows in segments).
struct SdoInitiateDownloadRequest {
  std::uint16_t index{0};
  std::uint8_t subindex{0};
  bool completeAccess{false};
  bool expedited{false};
  bool sizeIndicated{true};
  std::uint32_t completeSize{0};
  ConstBytes data{};

  Result<std::size_t> encode(Bytes out) const;
  bool operator==(const SdoInitiateDownloadRequest& o) const;
};

struct SdoInitiateUploadResponse {
  std::uint16_t index{0};
  std::uint8_t subindex{0};
  bool completeAccess{false};
  bool expedited{false};
  bool sizeIndicated{true};
  std::uint32_t completeSize{0};
  ConstBytes data{};

  Result<std::size_t> encode(Bytes out) const;
  bool operator==(const SdoInitiateUploadResponse& o) const;
};

// Download segment request and upload segment response share one layout.
struct SdoDownloadSegmentRequest {
  bool toggle{false};
  bool last{false};
  ConstBytes data{};

  Result<std::size_t> encode(Bytes out) const;
  bool operator==(const SdoDownloadSegmentRequest& o) const;
};

struct SdoUploadSegmentResponse {
  bool toggle{false};
  bool last{false};
  ConstBytes data{};

  Result<std::size_t> encode(Bytes out) const;
  bool operator==(const SdoUploadSegmentResponse& o) const;
};

struct SdoInitiateUploadRequest {
  std::uint16_t index{0};
  std::uint8_t subindex{0};
  bool completeAccess{false};

  Result<std::size_t> encode(Bytes out) const;
  bool operator==(const SdoInitiateUploadRequest&) const = default;
};

struct SdoInitiateDownloadResponse {
  std::uint16_t index{0};
  std::uint8_t subindex{0};
  bool completeAccess{false};

  Result<std::size_t> encode(Bytes out) const;
  bool operator==(const SdoInitiateDownloadResponse&) const = default;
};

struct SdoUploadSegmentRequest {
  bool toggle{false};

  Result<std::size_t> encode(Bytes out) const;
  bool operator==(const SdoUploadSegmentRequest&) const = default;
};

struct SdoDownloadSegmentResponse {
  bool toggle{false};

  Result<std::size_t> encode(Bytes out) const;
  bool operator==(const SdoDownloadSegmentResponse&) const = default;
};

// Abort transfer (command 0x80), sent by either side.
struct SdoAbort {
  std::uint16_t index{0};
  std::uint8_t subindex{0};
  std::uint32_t abortCode{0};

  Result<std::size_t> encode(Bytes out) const;
  bool operator==(const SdoAbort&) const = default;
};

using SdoRequest = std::variant<SdoInitiateDownloadRequest, SdoDownloadSegmentRequest,
                                SdoInitiateUploadRequest, SdoUploadSegmentRequest, SdoAbort>;
using SdoResponse = std::variant<SdoInitiateUploadResponse, SdoUploadSegmentResponse,
                                 SdoInitiateDownloadResponse, SdoDownloadSegmentResponse, SdoAbort>;

// --- body codecs (the bytes after the CoE header) -------------------------------------------

// encode: writes the SDO body into out and returns its size; fails with kTooLarge rather than
// write past out, with kInvalidArgument for values the wire cannot carry (expedited data of 0
// or more than 4 bytes, complete size smaller than the data). Short segments are padded.
// decode: `body` is exactly the CoE body (mailbox length - 2 bytes). Errors name the byte
// offset within `body` (command byte = byte 0).
Result<std::size_t> encodeSdoRequest(Bytes out, const SdoRequest& request);
Result<std::size_t> encodeSdoResponse(Bytes out, const SdoResponse& response);
Result<SdoRequest> decodeSdoRequest(ConstBytes body);
Result<SdoResponse> decodeSdoResponse(ConstBytes body);

// --- whole mailboxes: mailbox header + CoE header + SDO -------------------------------------

struct SdoRequestMessage {
  MailboxHeader mailbox;
  CoeHeader coe;
  SdoRequest sdo;
};
struct SdoResponseMessage {
  MailboxHeader mailbox;
  CoeHeader coe;
  SdoResponse sdo;
};

// Writes a complete mailbox (type CoE, CoE service 2 for a request, 3 for a response, number
// 0) into out, typically the SyncManager buffer; returns the bytes written (6 + mailbox
// length). A slave's SdoAbort is written with service 2, as real slaves send it. Address,
// channel, priority and counter come from `mailbox`. Bytes of out after the message are not
// touched.
Result<std::size_t> encodeSdoRequestMailbox(Bytes out, const SdoRequest& request,
                                            MailboxHeader mailbox = {});
Result<std::size_t> encodeSdoResponseMailbox(Bytes out, const SdoResponse& response,
                                             MailboxHeader mailbox = {});
// Decodes a mailbox buffer (bytes after the mailbox length are ignored) that must carry a CoE
// SDO request (service 2) / response (service 3). A response may also be an abort under
// service 2 (the standard form) or 3 (sent by some slaves in the field): both decode to
// SdoAbort. Errors name the byte offset within `buffer`.
Result<SdoRequestMessage> decodeSdoRequestMailbox(ConstBytes buffer);
Result<SdoResponseMessage> decodeSdoResponseMailbox(ConstBytes buffer);
// The results view the buffer: decoding a temporary vector would leave them dangling.
Result<SdoRequestMessage> decodeSdoRequestMailbox(std::vector<std::uint8_t>&&) = delete;
Result<SdoResponseMessage> decodeSdoResponseMailbox(std::vector<std::uint8_t>&&) = delete;
Result<SdoRequest> decodeSdoRequest(std::vector<std::uint8_t>&&) = delete;
Result<SdoResponse> decodeSdoResponse(std::vector<std::uint8_t>&&) = delete;

// --- abort codes (CiA 301 §7.2.4.3.17, ETG.1000.6 Table 41) -----------------------------------

enum class SdoAbortCode : std::uint32_t {
  kToggleBitNotAlternated = 0x05030000,
  kProtocolTimeout = 0x05040000,
  kInvalidCommandSpecifier = 0x05040001,
  kOutOfMemory = 0x05040005,
  kUnsupportedAccess = 0x06010000,
  kReadOfWriteOnly = 0x06010001,
  kWriteOfReadOnly = 0x06010002,
  kSubindexCannotBeWritten = 0x06010003,
  kCompleteAccessNotSupported = 0x06010004,
  kObjectLengthExceedsMailbox = 0x06010005,
  kObjectMappedToRxPdo = 0x06010006,
  kObjectDoesNotExist = 0x06020000,
  kObjectCannotBeMapped = 0x06040041,
  kPdoLengthExceeded = 0x06040042,
  kGeneralParameterIncompatibility = 0x06040043,
  kGeneralInternalIncompatibility = 0x06040047,
  kHardwareError = 0x06060000,
  kDataTypeMismatch = 0x06070010,
  kDataTypeLengthTooHigh = 0x06070012,
  kDataTypeLengthTooLow = 0x06070013,
  kSubindexDoesNotExist = 0x06090011,
  kValueRangeExceeded = 0x06090030,
  kValueTooHigh = 0x06090031,
  kValueTooLow = 0x06090032,
  kModuleIdentListMismatch = 0x06090033,
  kMaximumLessThanMinimum = 0x06090036,
  kGeneralError = 0x08000000,
  kDataCannotBeTransferred = 0x08000020,
  kDataCannotBeTransferredLocalControl = 0x08000021,
  kDataCannotBeTransferredDeviceState = 0x08000022,
  kNoObjectDictionary = 0x08000023,
};

// A short English description; "unknown SDO abort code" for codes not in the table.
std::string_view sdoAbortText(std::uint32_t code);
inline std::string_view sdoAbortText(SdoAbortCode code) {
  return sdoAbortText(static_cast<std::uint32_t>(code));
}
bool isKnownSdoAbortCode(std::uint32_t code);

}  // namespace ecsim
