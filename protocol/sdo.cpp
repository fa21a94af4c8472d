#include "protocol/sdo.hpp"

#include <algorithm>
#include <iterator>
#include <string>
#include <utility>

namespace ecsim {
namespace {

// Command specifiers (bits 5-7 of the command byte).
constexpr std::uint8_t kCcsDownloadSegment = 0;
constexpr std::uint8_t kCcsInitiateDownload = 1;
constexpr std::uint8_t kCcsInitiateUpload = 2;
constexpr std::uint8_t kCcsUploadSegment = 3;
constexpr std::uint8_t kScsUploadSegment = 0;
constexpr std::uint8_t kScsDownloadSegment = 1;
constexpr std::uint8_t kScsInitiateUpload = 2;
constexpr std::uint8_t kScsInitiateDownload = 3;
constexpr std::uint8_t kCsAbort = 4;
constexpr std::uint8_t kCsBlockUpload = 5;    // CiA 301 block transfers: not used by CoE
constexpr std::uint8_t kCsBlockDownload = 6;  //
constexpr unsigned kCsShift = 5;

constexpr std::uint8_t kBitSizeIndicated = 0x01;
constexpr std::uint8_t kBitExpedited = 0x02;
constexpr std::uint8_t kBitCompleteAccess = 0x10;
constexpr std::uint8_t kBitLast = 0x01;
constexpr std::uint8_t kBitToggle = 0x10;
constexpr unsigned kExpeditedUnusedShift = 2;  // bits 2-3
constexpr unsigned kSegmentUnusedShift = 1;    // bits 1-3

Error fault(ErrorCode code, std::size_t at, const std::string& what) {
  return makeError(code, "byte " + std::to_string(at) + ": " + what);
}

std::uint8_t command(std::uint8_t cs, std::uint8_t bits) {
  return static_cast<std::uint8_t>((cs << kCsShift) | bits);
}

std::string hex8(std::uint8_t v) {
  constexpr char kDigits[] = "0123456789ABCDEF";
  return std::string("0x") + kDigits[v >> 4] + kDigits[v & 0x0F];
}

bool sameBytes(ConstBytes a, ConstBytes b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end());
}

Error tooSmall(std::string_view what, std::size_t need, std::size_t have) {
  return makeError(ErrorCode::kTooLarge, std::string(what) + " needs " + std::to_string(need) +
                                             " bytes, buffer holds " + std::to_string(have));
}

// Zeroes the 8-byte minimum body and writes command, index and subindex.
Result<std::size_t> writeFixed(Bytes out, std::string_view what, std::uint8_t cmd,
                               std::uint16_t index, std::uint8_t subindex) {
  if (out.size() < kSdoMinBodySize) return tooSmall(what, kSdoMinBodySize, out.size());
  std::fill_n(out.begin(), kSdoMinBodySize, std::uint8_t{0});
  writeU8(out, 0, cmd);
  writeLe16(out, 1, index);
  writeU8(out, 3, subindex);
  return kSdoMinBodySize;
}

// --- shared layouts ------------------------------------------------------------------------

struct Initiate {
  std::uint16_t index{0};
  std::uint8_t subindex{0};
  bool completeAccess{false};
  bool expedited{false};
  bool sizeIndicated{true};
  std::uint32_t completeSize{0};
  ConstBytes data{};
};

Result<std::size_t> encodeInitiate(Bytes out, std::uint8_t cs, const Initiate& m) {
  std::uint8_t bits = m.completeAccess ? kBitCompleteAccess : 0;
  if (m.sizeIndicated) bits |= kBitSizeIndicated;
  if (m.expedited) {
    const std::size_t limit = m.sizeIndicated ? kSdoExpeditedMaxData : 4;
    if (m.data.empty() || m.data.size() > limit || (!m.sizeIndicated && m.data.size() != 4)) {
      return makeError(ErrorCode::kInvalidArgument,
                       "expedited SDO carries 1-4 data bytes (4 without size indicator), got " +
                           std::to_string(m.data.size()));
    }
    bits |= kBitExpedited;
    if (m.sizeIndicated) {
      bits |= static_cast<std::uint8_t>((kSdoExpeditedMaxData - m.data.size())
                                        << kExpeditedUnusedShift);
    }
    ECSIM_TRY(writeFixed(out, "expedited SDO", command(cs, bits), m.index, m.subindex));
    std::copy(m.data.begin(), m.data.end(), out.begin() + 4);
    return kSdoMinBodySize;
  }
  if (m.sizeIndicated && m.completeSize < m.data.size()) {
    return makeError(ErrorCode::kInvalidArgument,
                     "complete size " + std::to_string(m.completeSize) + " is smaller than the " +
                         std::to_string(m.data.size()) + " data bytes of the message");
  }
  const std::size_t need = kSdoNormalHeaderSize + m.data.size();
  if (out.size() < need) return tooSmall("normal SDO", need, out.size());
  ECSIM_TRY(writeFixed(out, "normal SDO", command(cs, bits), m.index, m.subindex));
  writeLe32(out, 4, m.completeSize);
  std::copy(m.data.begin(), m.data.end(), out.begin() + kSdoNormalHeaderSize);
  return need;
}

Result<Initiate> decodeInitiate(ConstBytes body, std::size_t base) {
  const std::uint8_t cmd = body[0];
  Initiate m;
  m.index = readLe16(body, 1);
  m.subindex = body[3];
  m.completeAccess = (cmd & kBitCompleteAccess) != 0;
  m.expedited = (cmd & kBitExpedited) != 0;
  m.sizeIndicated = (cmd & kBitSizeIndicated) != 0;
  const auto unused = static_cast<std::uint8_t>((cmd >> kExpeditedUnusedShift) & 0x03);
  if (unused != 0 && !(m.expedited && m.sizeIndicated)) {
    return fault(ErrorCode::kMalformed, base,
                 "size indicator: " + std::to_string(unused) +
                     " unused bytes given without expedited + size-indicated bits (command " +
                     hex8(cmd) + ")");
  }
  if (m.expedited) {
    const std::size_t size = kSdoExpeditedMaxData - unused;
    m.data = body.subspan(4, size);
    m.completeSize = static_cast<std::uint32_t>(size);
    return m;
  }
  m.completeSize = readLe32(body, 4);
  m.data = body.subspan(kSdoNormalHeaderSize);
  if (m.sizeIndicated && m.completeSize < m.data.size()) {
    return fault(ErrorCode::kMalformed, base + 4,
                 "complete size " + std::to_string(m.completeSize) + " is smaller than the " +
                     std::to_string(m.data.size()) + " data bytes that follow");
  }
  return m;
}

struct Segment {
  bool toggle{false};
  bool last{false};
  ConstBytes data{};
};

Result<std::size_t> encodeSegment(Bytes out, std::uint8_t cs, const Segment& s) {
  std::uint8_t bits = s.toggle ? kBitToggle : 0;
  if (s.last) bits |= kBitLast;
  std::size_t need = 1 + s.data.size();
  if (s.data.size() < kSdoSegmentPaddedData) {
    need = kSdoMinBodySize;
    bits |=
        static_cast<std::uint8_t>((kSdoSegmentPaddedData - s.data.size()) << kSegmentUnusedShift);
  }
  if (out.size() < need) {
    return tooSmall("SDO segment of " + std::to_string(s.data.size()) + " data bytes", need,
                    out.size());
  }
  std::fill_n(out.begin(), need, std::uint8_t{0});
  writeU8(out, 0, command(cs, bits));
  std::copy(s.data.begin(), s.data.end(), out.begin() + 1);
  return need;
}

Result<Segment> decodeSegment(ConstBytes body, std::size_t base) {
  const std::uint8_t cmd = body[0];
  Segment s;
  s.toggle = (cmd & kBitToggle) != 0;
  s.last = (cmd & kBitLast) != 0;
  const auto unused = static_cast<std::uint8_t>((cmd >> kSegmentUnusedShift) & 0x07);
  const std::size_t carried = body.size() - 1;
  if (carried == kSdoSegmentPaddedData) {
    s.data = body.subspan(1, kSdoSegmentPaddedData - unused);
  } else if (unused != 0) {
    return fault(ErrorCode::kMalformed, base,
                 "segment of " + std::to_string(carried) + " bytes gives " +
                     std::to_string(unused) + " unused bytes (allowed only with 7)");
  } else {
    s.data = body.subspan(1);
  }
  return s;
}

Result<std::size_t> encodeToggleOnly(Bytes out, std::uint8_t cs, bool toggle) {
  return writeFixed(out, "SDO segment", command(cs, toggle ? kBitToggle : 0), 0, 0);
}

SdoAbort decodeAbort(ConstBytes body) {
  return SdoAbort{readLe16(body, 1), body[3], readLe32(body, 4)};
}

Status checkBody(ConstBytes body, std::size_t base) {
  if (body.size() < kSdoMinBodySize) {
    return fault(
        ErrorCode::kTruncated, base + body.size(),
        "SDO needs at least 8 bytes after the CoE header, got " + std::to_string(body.size()));
  }
  return okStatus();
}

Error badSpecifier(std::uint8_t cs, bool request, std::size_t base) {
  if (cs == kCsBlockUpload || cs == kCsBlockDownload) {
    return fault(
        ErrorCode::kUnsupported, base,
        "SDO block transfer (command specifier " + std::to_string(cs) + ") is not used by CoE");
  }
  return fault(ErrorCode::kMalformed, base,
               std::string(request ? "client" : "server") + " command specifier " +
                   std::to_string(cs) + " is not valid");
}

Status expectService(const CoeMessage& message, CoeService expected) {
  if (message.coe.service != expected) {
    return fault(ErrorCode::kMalformed, 7,
                 "CoE service " + std::to_string(static_cast<unsigned>(message.coe.service)) +
                     " (" + std::string(toString(message.coe.service)) + ") is not " +
                     std::string(toString(expected)));
  }
  return okStatus();
}

}  // namespace

// --- message structs ------------------------------------------------------------------------

Result<std::size_t> SdoInitiateDownloadRequest::encode(Bytes out) const {
  return encodeInitiate(
      out, kCcsInitiateDownload,
      {index, subindex, completeAccess, expedited, sizeIndicated, completeSize, data});
}
bool SdoInitiateDownloadRequest::operator==(const SdoInitiateDownloadRequest& o) const {
  return index == o.index && subindex == o.subindex && completeAccess == o.completeAccess &&
         expedited == o.expedited && sizeIndicated == o.sizeIndicated &&
         completeSize == o.completeSize && sameBytes(data, o.data);
}

Result<std::size_t> SdoInitiateUploadResponse::encode(Bytes out) const {
  return encodeInitiate(
      out, kScsInitiateUpload,
      {index, subindex, completeAccess, expedited, sizeIndicated, completeSize, data});
}
bool SdoInitiateUploadResponse::operator==(const SdoInitiateUploadResponse& o) const {
  return index == o.index && subindex == o.subindex && completeAccess == o.completeAccess &&
         expedited == o.expedited && sizeIndicated == o.sizeIndicated &&
         completeSize == o.completeSize && sameBytes(data, o.data);
}

Result<std::size_t> SdoDownloadSegmentRequest::encode(Bytes out) const {
  return encodeSegment(out, kCcsDownloadSegment, {toggle, last, data});
}
bool SdoDownloadSegmentRequest::operator==(const SdoDownloadSegmentRequest& o) const {
  return toggle == o.toggle && last == o.last && sameBytes(data, o.data);
}

Result<std::size_t> SdoUploadSegmentResponse::encode(Bytes out) const {
  return encodeSegment(out, kScsUploadSegment, {toggle, last, data});
}
bool SdoUploadSegmentResponse::operator==(const SdoUploadSegmentResponse& o) const {
  return toggle == o.toggle && last == o.last && sameBytes(data, o.data);
}

Result<std::size_t> SdoInitiateUploadRequest::encode(Bytes out) const {
  return writeFixed(out, "SDO upload request",
                    command(kCcsInitiateUpload, completeAccess ? kBitCompleteAccess : 0), index,
                    subindex);
}

Result<std::size_t> SdoInitiateDownloadResponse::encode(Bytes out) const {
  return writeFixed(out, "SDO download response",
                    command(kScsInitiateDownload, completeAccess ? kBitCompleteAccess : 0), index,
                    subindex);
}

Result<std::size_t> SdoUploadSegmentRequest::encode(Bytes out) const {
  return encodeToggleOnly(out, kCcsUploadSegment, toggle);
}

Result<std::size_t> SdoDownloadSegmentResponse::encode(Bytes out) const {
  return encodeToggleOnly(out, kScsDownloadSegment, toggle);
}

Result<std::size_t> SdoAbort::encode(Bytes out) const {
  ECSIM_TRY(writeFixed(out, "SDO abort", command(kCsAbort, 0), index, subindex));
  writeLe32(out, 4, abortCode);
  return kSdoMinBodySize;
}

// --- body codecs ----------------------------------------------------------------------------

Result<std::size_t> encodeSdoRequest(Bytes out, const SdoRequest& request) {
  return std::visit([out](const auto& m) { return m.encode(out); }, request);
}

Result<std::size_t> encodeSdoResponse(Bytes out, const SdoResponse& response) {
  return std::visit([out](const auto& m) { return m.encode(out); }, response);
}

namespace {

Result<SdoRequest> decodeRequestAt(ConstBytes body, std::size_t base) {
  ECSIM_TRY(checkBody(body, base));
  const auto cs = static_cast<std::uint8_t>(body[0] >> kCsShift);
  switch (cs) {
    case kCcsInitiateDownload: {
      ECSIM_ASSIGN_OR_RETURN(Initiate m, decodeInitiate(body, base));
      return SdoRequest{SdoInitiateDownloadRequest{m.index, m.subindex, m.completeAccess,
                                                   m.expedited, m.sizeIndicated, m.completeSize,
                                                   m.data}};
    }
    case kCcsDownloadSegment: {
      ECSIM_ASSIGN_OR_RETURN(Segment s, decodeSegment(body, base));
      return SdoRequest{SdoDownloadSegmentRequest{s.toggle, s.last, s.data}};
    }
    case kCcsInitiateUpload:
      return SdoRequest{SdoInitiateUploadRequest{readLe16(body, 1), body[3],
                                                 (body[0] & kBitCompleteAccess) != 0}};
    case kCcsUploadSegment:
      return SdoRequest{SdoUploadSegmentRequest{(body[0] & kBitToggle) != 0}};
    case kCsAbort:
      return SdoRequest{decodeAbort(body)};
    default:
      return badSpecifier(cs, true, base);
  }
}

Result<SdoResponse> decodeResponseAt(ConstBytes body, std::size_t base) {
  ECSIM_TRY(checkBody(body, base));
  const auto cs = static_cast<std::uint8_t>(body[0] >> kCsShift);
  switch (cs) {
    case kScsInitiateUpload: {
      ECSIM_ASSIGN_OR_RETURN(Initiate m, decodeInitiate(body, base));
      return SdoResponse{SdoInitiateUploadResponse{m.index, m.subindex, m.completeAccess,
                                                   m.expedited, m.sizeIndicated, m.completeSize,
                                                   m.data}};
    }
    case kScsUploadSegment: {
      ECSIM_ASSIGN_OR_RETURN(Segment s, decodeSegment(body, base));
      return SdoResponse{SdoUploadSegmentResponse{s.toggle, s.last, s.data}};
    }
    case kScsInitiateDownload:
      return SdoResponse{SdoInitiateDownloadResponse{readLe16(body, 1), body[3],
                                                     (body[0] & kBitCompleteAccess) != 0}};
    case kScsDownloadSegment:
      return SdoResponse{SdoDownloadSegmentResponse{(body[0] & kBitToggle) != 0}};
    case kCsAbort:
      return SdoResponse{decodeAbort(body)};
    default:
      return badSpecifier(cs, false, base);
  }
}

}  // namespace

Result<SdoRequest> decodeSdoRequest(ConstBytes body) {
  return decodeRequestAt(body, 0);
}

Result<SdoResponse> decodeSdoResponse(ConstBytes body) {
  return decodeResponseAt(body, 0);
}

// --- whole mailboxes --------------------------------------------------------------------------

Result<std::size_t> encodeSdoRequestMailbox(Bytes out, const SdoRequest& request,
                                            MailboxHeader mailbox) {
  if (out.size() < kCoeBodyOffset) return tooSmall("SDO mailbox", kCoeBodyOffset, out.size());
  ECSIM_ASSIGN_OR_RETURN(std::size_t body, encodeSdoRequest(out.subspan(kCoeBodyOffset), request));
  return finishCoeMailbox(out, mailbox, CoeHeader{0, CoeService::kSdoRequest}, body);
}

Result<std::size_t> encodeSdoResponseMailbox(Bytes out, const SdoResponse& response,
                                             MailboxHeader mailbox) {
  if (out.size() < kCoeBodyOffset) return tooSmall("SDO mailbox", kCoeBodyOffset, out.size());
  ECSIM_ASSIGN_OR_RETURN(std::size_t body,
                         encodeSdoResponse(out.subspan(kCoeBodyOffset), response));
  // Abort SDO Transfer is an SDO request in either direction (ETG.1000.6 table of CoE
  // services; SOES esc_coe.c SDO_abort() writes COE_SDOREQUEST): a slave's abort carries
  // service 2. SOEM takes a service-3 answer with the right index as success and never sees
  // the abort code (ethercatcoe.c / ec_coe.c ecx_SDOwrite, ecx_SDOread).
  const CoeService service = std::holds_alternative<SdoAbort>(response) ? CoeService::kSdoRequest
                                                                       : CoeService::kSdoResponse;
  return finishCoeMailbox(out, mailbox, CoeHeader{0, service}, body);
}

Result<SdoRequestMessage> decodeSdoRequestMailbox(ConstBytes buffer) {
  ECSIM_ASSIGN_OR_RETURN(CoeMessage m, decodeCoeMailbox(buffer));
  ECSIM_TRY(expectService(m, CoeService::kSdoRequest));
  ECSIM_ASSIGN_OR_RETURN(SdoRequest sdo, decodeRequestAt(m.body, kCoeBodyOffset));
  return SdoRequestMessage{m.mailbox, m.coe, sdo};
}

Result<SdoResponseMessage> decodeSdoResponseMailbox(ConstBytes buffer) {
  ECSIM_ASSIGN_OR_RETURN(CoeMessage m, decodeCoeMailbox(buffer));
  // A slave's abort comes as service 2 (as ETG.1000.6 and SOES send it) or, from some slaves
  // in the field, as service 3: both are the slave's answer.
  if (m.coe.service == CoeService::kSdoRequest && !m.body.empty() &&
      (m.body[0] >> kCsShift) == kCsAbort) {
    ECSIM_TRY(checkBody(m.body, kCoeBodyOffset));
    return SdoResponseMessage{m.mailbox, m.coe, SdoResponse{decodeAbort(m.body)}};
  }
  ECSIM_TRY(expectService(m, CoeService::kSdoResponse));
  ECSIM_ASSIGN_OR_RETURN(SdoResponse sdo, decodeResponseAt(m.body, kCoeBodyOffset));
  return SdoResponseMessage{m.mailbox, m.coe, sdo};
}

// --- abort codes ----------------------------------------------------------------------------

namespace {

using A = SdoAbortCode;

// Sorted by code, for binary search.
constexpr std::pair<SdoAbortCode, std::string_view> kAbortTexts[] = {
    {A::kToggleBitNotAlternated, "toggle bit did not alternate"},
    {A::kProtocolTimeout, "SDO protocol timed out"},
    {A::kInvalidCommandSpecifier, "client/server command specifier is invalid or unknown"},
    {A::kOutOfMemory, "out of memory"},
    {A::kUnsupportedAccess, "access to the object is not supported"},
    {A::kReadOfWriteOnly, "attempt to read a write-only object"},
    {A::kWriteOfReadOnly, "attempt to write a read-only object"},
    {A::kSubindexCannotBeWritten,
     "subindex cannot be written; subindex 0 must be 0 for write access"},
    {A::kCompleteAccessNotSupported,
     "complete access is not supported for objects of variable length"},
    {A::kObjectLengthExceedsMailbox, "object is longer than the mailbox"},
    {A::kObjectMappedToRxPdo, "object is mapped to an RxPDO; SDO download is blocked"},
    {A::kObjectDoesNotExist, "object does not exist in the object dictionary"},
    {A::kObjectCannotBeMapped, "object cannot be mapped to a PDO"},
    {A::kPdoLengthExceeded, "number or length of the mapped objects exceeds the PDO length"},
    {A::kGeneralParameterIncompatibility, "general parameter incompatibility"},
    {A::kGeneralInternalIncompatibility, "general internal incompatibility in the device"},
    {A::kHardwareError, "access failed because of a hardware error"},
    {A::kDataTypeMismatch, "data type or length of the service parameter does not match"},
    {A::kDataTypeLengthTooHigh, "data type does not match: service parameter too long"},
    {A::kDataTypeLengthTooLow, "data type does not match: service parameter too short"},
    {A::kSubindexDoesNotExist, "subindex does not exist"},
    {A::kValueRangeExceeded, "value range of the parameter exceeded (download only)"},
    {A::kValueTooHigh, "value of the parameter written is too high"},
    {A::kValueTooLow, "value of the parameter written is too low"},
    {A::kModuleIdentListMismatch, "detected and configured module ident lists do not match"},
    {A::kMaximumLessThanMinimum, "maximum value is less than minimum value"},
    {A::kGeneralError, "general error"},
    {A::kDataCannotBeTransferred, "data cannot be transferred or stored"},
    {A::kDataCannotBeTransferredLocalControl,
     "data cannot be transferred or stored because of local control"},
    {A::kDataCannotBeTransferredDeviceState,
     "data cannot be transferred or stored in the present device state"},
    {A::kNoObjectDictionary, "object dictionary cannot be generated dynamically or is not present"},
};

static_assert(
    [] {
      for (std::size_t i = 1; i < std::size(kAbortTexts); ++i) {
        if (kAbortTexts[i - 1].first >= kAbortTexts[i].first) return false;
      }
      return true;
    }(),
    "SDO abort code table must be sorted and unique");

const std::pair<SdoAbortCode, std::string_view>* findAbort(std::uint32_t code) {
  const auto* end = std::end(kAbortTexts);
  const auto* it =
      std::lower_bound(std::begin(kAbortTexts), end, code, [](const auto& entry, std::uint32_t c) {
        return static_cast<std::uint32_t>(entry.first) < c;
      });
  if (it == end || static_cast<std::uint32_t>(it->first) != code) return nullptr;
  return it;
}

}  // namespace

std::string_view sdoAbortText(std::uint32_t code) {
  const auto* entry = findAbort(code);
  return entry ? entry->second : "unknown SDO abort code";
}

bool isKnownSdoAbortCode(std::uint32_t code) {
  return findAbort(code) != nullptr;
}

}  // namespace ecsim
