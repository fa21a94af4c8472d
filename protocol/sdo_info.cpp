#include "protocol/sdo_info.hpp"

#include <algorithm>
#include <string>
#include <utility>

namespace ecsim {
namespace {

Error fault(ErrorCode code, std::size_t at, const std::string& what) {
  return makeError(code, "byte " + std::to_string(at) + ": " + what);
}

Status need(ConstBytes data, std::size_t size, std::string_view what) {
  if (data.size() < size) {
    return fault(ErrorCode::kTruncated, data.size(),
                 std::string(what) + " needs " + std::to_string(size) + " bytes, got " +
                     std::to_string(data.size()));
  }
  return okStatus();
}

Status room(Bytes out, std::size_t size, std::string_view what) {
  if (out.size() < size) {
    return makeError(ErrorCode::kTooLarge, std::string(what) + " needs " + std::to_string(size) +
                                               " bytes, buffer holds " +
                                               std::to_string(out.size()));
  }
  return okStatus();
}

std::string toText(ConstBytes bytes) {
  return std::string(bytes.begin(), bytes.end());
}

void writeText(Bytes out, std::size_t at, std::string_view text) {
  std::transform(text.begin(), text.end(), out.begin() + static_cast<std::ptrdiff_t>(at),
                 [](char c) { return static_cast<std::uint8_t>(c); });
}

Status checkValue(const std::vector<std::uint8_t>& value, std::size_t size, std::string_view what) {
  if (value.size() != size) {
    return makeError(ErrorCode::kInvalidArgument,
                     std::string(what) + " has " + std::to_string(value.size()) +
                         " bytes, the bit length asks for " + std::to_string(size));
  }
  return okStatus();
}

}  // namespace

std::string_view toString(SdoInfoOpcode opcode) {
  switch (opcode) {
    case SdoInfoOpcode::kGetOdListRequest:
      return "Get OD list request";
    case SdoInfoOpcode::kGetOdListResponse:
      return "Get OD list response";
    case SdoInfoOpcode::kGetObjectDescriptionRequest:
      return "Get object description request";
    case SdoInfoOpcode::kGetObjectDescriptionResponse:
      return "Get object description response";
    case SdoInfoOpcode::kGetEntryDescriptionRequest:
      return "Get entry description request";
    case SdoInfoOpcode::kGetEntryDescriptionResponse:
      return "Get entry description response";
    case SdoInfoOpcode::kError:
      return "SDO information error";
  }
  return "unknown";
}

Result<SdoInfoHeader> SdoInfoHeader::decode(ConstBytes body) {
  ECSIM_TRY(need(body, kSdoInfoHeaderSize, "SDO information header"));
  SdoInfoHeader h;
  h.opcode = static_cast<SdoInfoOpcode>(body[0] & kSdoInfoOpcodeMask);
  h.incomplete = (body[0] & kSdoInfoIncompleteFlag) != 0;
  h.fragmentsLeft = readLe16(body, 2);
  return h;
}

Result<std::size_t> SdoInfoHeader::encode(Bytes out) const {
  ECSIM_TRY(room(out, kSdoInfoHeaderSize, "SDO information header"));
  const auto raw = static_cast<std::uint8_t>(opcode);
  if (raw > kSdoInfoOpcodeMask) {
    return makeError(ErrorCode::kInvalidArgument,
                     "SDO information opcode " + std::to_string(raw) + " exceeds 7 bits");
  }
  writeU8(out, 0, static_cast<std::uint8_t>(raw | (incomplete ? kSdoInfoIncompleteFlag : 0)));
  writeU8(out, 1, 0);
  writeLe16(out, 2, fragmentsLeft);
  return kSdoInfoHeaderSize;
}

// --- service data ---------------------------------------------------------------------------

Result<OdListRequest> OdListRequest::decode(ConstBytes data) {
  ECSIM_TRY(need(data, 2, "Get OD list request"));
  return OdListRequest{readLe16(data, 0)};
}

Result<std::size_t> OdListRequest::encode(Bytes out) const {
  ECSIM_TRY(room(out, 2, "Get OD list request"));
  writeLe16(out, 0, listType);
  return 2;
}

Result<ObjectDescriptionRequest> ObjectDescriptionRequest::decode(ConstBytes data) {
  ECSIM_TRY(need(data, 2, "Get object description request"));
  return ObjectDescriptionRequest{readLe16(data, 0)};
}

Result<std::size_t> ObjectDescriptionRequest::encode(Bytes out) const {
  ECSIM_TRY(room(out, 2, "Get object description request"));
  writeLe16(out, 0, index);
  return 2;
}

Result<EntryDescriptionRequest> EntryDescriptionRequest::decode(ConstBytes data) {
  ECSIM_TRY(need(data, 4, "Get entry description request"));
  return EntryDescriptionRequest{readLe16(data, 0), data[2], data[3]};
}

Result<std::size_t> EntryDescriptionRequest::encode(Bytes out) const {
  ECSIM_TRY(room(out, 4, "Get entry description request"));
  writeLe16(out, 0, index);
  writeU8(out, 2, subindex);
  writeU8(out, 3, valueInfo);
  return 4;
}

Result<OdList> OdList::decode(ConstBytes data) {
  ECSIM_TRY(need(data, 2, "OD list"));
  if (data.size() % 2 != 0) {
    return fault(ErrorCode::kMalformed, data.size() - 1,
                 "OD list of " + std::to_string(data.size()) + " bytes ends in half an index");
  }
  OdList list;
  list.listType = readLe16(data, 0);
  list.indexes.reserve((data.size() - 2) / 2);
  for (std::size_t at = 2; at < data.size(); at += 2) list.indexes.push_back(readLe16(data, at));
  return list;
}

Result<std::size_t> OdList::encode(Bytes out) const {
  const std::size_t size = encodedSize();
  ECSIM_TRY(room(out, size, "OD list"));
  writeLe16(out, 0, listType);
  for (std::size_t i = 0; i < indexes.size(); ++i) writeLe16(out, 2 + 2 * i, indexes[i]);
  return size;
}

Result<ObjectDescription> ObjectDescription::decode(ConstBytes data) {
  ECSIM_TRY(need(data, 6, "object description"));
  ObjectDescription d;
  d.index = readLe16(data, 0);
  d.dataType = readLe16(data, 2);
  d.maxSubindex = data[4];
  d.objectCode = data[5];
  d.name = toText(data.subspan(6));
  return d;
}

Result<std::size_t> ObjectDescription::encode(Bytes out) const {
  const std::size_t size = encodedSize();
  ECSIM_TRY(room(out, size, "object description"));
  writeLe16(out, 0, index);
  writeLe16(out, 2, dataType);
  writeU8(out, 4, maxSubindex);
  writeU8(out, 5, objectCode);
  writeText(out, 6, name);
  return size;
}

std::size_t EntryDescription::encodedSize() const {
  std::size_t size = 10 + name.size();
  if (valueInfo & kValueInfoUnitType) size += 2;
  if (valueInfo & kValueInfoDefault) size += valueSize();
  if (valueInfo & kValueInfoMinimum) size += valueSize();
  if (valueInfo & kValueInfoMaximum) size += valueSize();
  return size;
}

Result<EntryDescription> EntryDescription::decode(ConstBytes data) {
  ECSIM_TRY(need(data, 10, "entry description"));
  EntryDescription d;
  d.index = readLe16(data, 0);
  d.subindex = data[2];
  d.valueInfo = data[3];
  d.dataType = readLe16(data, 4);
  d.bitLength = readLe16(data, 6);
  d.objectAccess = readLe16(data, 8);
  std::size_t at = 10;
  if (d.valueInfo & kValueInfoUnitType) {
    if (data.size() < at + 2) {
      return fault(ErrorCode::kTruncated, at, "entry description: unit type missing");
    }
    d.unitType = readLe16(data, at);
    at += 2;
  }
  const std::size_t valueSize = d.valueSize();
  struct Optional {
    std::uint8_t bit;
    std::vector<std::uint8_t>* value;
    const char* what;
  };
  const Optional optionals[] = {{kValueInfoDefault, &d.defaultValue, "default value"},
                                {kValueInfoMinimum, &d.minimumValue, "minimum value"},
                                {kValueInfoMaximum, &d.maximumValue, "maximum value"}};
  for (const auto& o : optionals) {
    if ((d.valueInfo & o.bit) == 0) continue;
    if (data.size() - at < valueSize) {
      return fault(ErrorCode::kTruncated, at,
                   std::string("entry description: ") + o.what + " of " +
                       std::to_string(valueSize) + " bytes runs past the data");
    }
    o.value->assign(data.begin() + static_cast<std::ptrdiff_t>(at),
                    data.begin() + static_cast<std::ptrdiff_t>(at + valueSize));
    at += valueSize;
  }
  d.name = toText(data.subspan(at));
  return d;
}

Result<std::size_t> EntryDescription::encode(Bytes out) const {
  const std::size_t vs = valueSize();
  if (valueInfo & kValueInfoDefault) ECSIM_TRY(checkValue(defaultValue, vs, "default value"));
  if (valueInfo & kValueInfoMinimum) ECSIM_TRY(checkValue(minimumValue, vs, "minimum value"));
  if (valueInfo & kValueInfoMaximum) ECSIM_TRY(checkValue(maximumValue, vs, "maximum value"));
  const std::size_t size = encodedSize();
  ECSIM_TRY(room(out, size, "entry description"));
  writeLe16(out, 0, index);
  writeU8(out, 2, subindex);
  writeU8(out, 3, valueInfo);
  writeLe16(out, 4, dataType);
  writeLe16(out, 6, bitLength);
  writeLe16(out, 8, objectAccess);
  std::size_t at = 10;
  if (valueInfo & kValueInfoUnitType) {
    writeLe16(out, at, unitType);
    at += 2;
  }
  const std::pair<std::uint8_t, const std::vector<std::uint8_t>*> values[] = {
      {kValueInfoDefault, &defaultValue},
      {kValueInfoMinimum, &minimumValue},
      {kValueInfoMaximum, &maximumValue}};
  for (const auto& [bit, value] : values) {
    if ((valueInfo & bit) == 0) continue;
    std::copy(value->begin(), value->end(), out.begin() + static_cast<std::ptrdiff_t>(at));
    at += vs;
  }
  writeText(out, at, name);
  return size;
}

Result<SdoInfoError> SdoInfoError::decode(ConstBytes data) {
  ECSIM_TRY(need(data, 4, "SDO information error"));
  return SdoInfoError{readLe32(data, 0)};
}

Result<std::size_t> SdoInfoError::encode(Bytes out) const {
  ECSIM_TRY(room(out, 4, "SDO information error"));
  writeLe32(out, 0, abortCode);
  return 4;
}

SdoInfoOpcode opcodeOf(const SdoInfoRequest& request) {
  constexpr SdoInfoOpcode kOpcodes[] = {SdoInfoOpcode::kGetOdListRequest,
                                        SdoInfoOpcode::kGetObjectDescriptionRequest,
                                        SdoInfoOpcode::kGetEntryDescriptionRequest};
  return kOpcodes[request.index()];
}

SdoInfoOpcode opcodeOf(const SdoInfoResponse& response) {
  constexpr SdoInfoOpcode kOpcodes[] = {
      SdoInfoOpcode::kGetOdListResponse, SdoInfoOpcode::kGetObjectDescriptionResponse,
      SdoInfoOpcode::kGetEntryDescriptionResponse, SdoInfoOpcode::kError};
  return kOpcodes[response.index()];
}

// --- mailboxes ----------------------------------------------------------------------------------

Result<SdoInfoMessage> decodeSdoInfoMailbox(ConstBytes buffer) {
  ECSIM_ASSIGN_OR_RETURN(CoeMessage m, decodeCoeMailbox(buffer));
  if (m.coe.service != CoeService::kSdoInformation) {
    return fault(ErrorCode::kMalformed, 7,
                 "CoE service " + std::to_string(static_cast<unsigned>(m.coe.service)) +
                     " is not SDO information (8)");
  }
  if (m.body.size() < kSdoInfoHeaderSize) {
    return fault(ErrorCode::kTruncated, kCoeBodyOffset + m.body.size(),
                 "SDO information header needs 4 bytes after the CoE header, mailbox length " +
                     std::to_string(m.mailbox.length) + " leaves " + std::to_string(m.body.size()));
  }
  ECSIM_ASSIGN_OR_RETURN(SdoInfoHeader header, SdoInfoHeader::decode(m.body));
  return SdoInfoMessage{m.mailbox, header, m.body.subspan(kSdoInfoHeaderSize)};
}

namespace {

// Re-bases a service-data error ("byte N: ...") onto the mailbox when decoding a message.
template <typename T, typename V>
Result<V> lift(Result<T> r) {
  if (!r) {
    Error e = r.takeError();
    e.context = "service data " + e.context;
    return e;
  }
  return V{std::move(r).value()};
}

}  // namespace

Result<SdoInfoRequest> decodeSdoInfoRequest(const SdoInfoMessage& message) {
  const ConstBytes data = message.data;
  switch (message.header.opcode) {
    case SdoInfoOpcode::kGetOdListRequest:
      return lift<OdListRequest, SdoInfoRequest>(OdListRequest::decode(data));
    case SdoInfoOpcode::kGetObjectDescriptionRequest:
      return lift<ObjectDescriptionRequest, SdoInfoRequest>(ObjectDescriptionRequest::decode(data));
    case SdoInfoOpcode::kGetEntryDescriptionRequest:
      return lift<EntryDescriptionRequest, SdoInfoRequest>(EntryDescriptionRequest::decode(data));
    default:
      return fault(ErrorCode::kUnsupported, kCoeBodyOffset,
                   "SDO information opcode " +
                       std::to_string(static_cast<unsigned>(message.header.opcode)) +
                       " is not a request");
  }
}

Result<SdoInfoResponse> decodeSdoInfoResponse(SdoInfoOpcode opcode, ConstBytes data) {
  switch (opcode) {
    case SdoInfoOpcode::kGetOdListResponse:
      return lift<OdList, SdoInfoResponse>(OdList::decode(data));
    case SdoInfoOpcode::kGetObjectDescriptionResponse:
      return lift<ObjectDescription, SdoInfoResponse>(ObjectDescription::decode(data));
    case SdoInfoOpcode::kGetEntryDescriptionResponse:
      return lift<EntryDescription, SdoInfoResponse>(EntryDescription::decode(data));
    case SdoInfoOpcode::kError:
      return lift<SdoInfoError, SdoInfoResponse>(SdoInfoError::decode(data));
    default:
      return fault(ErrorCode::kUnsupported, kCoeBodyOffset,
                   "SDO information opcode " + std::to_string(static_cast<unsigned>(opcode)) +
                       " is not a response");
  }
}

Result<SdoInfoResponse> decodeSdoInfoResponse(const SdoInfoMessage& message) {
  if (message.header.fragmentsLeft != 0 || message.header.incomplete) {
    return fault(ErrorCode::kInvalidArgument, kCoeBodyOffset + 2,
                 std::to_string(message.header.fragmentsLeft) +
                     " fragments left: reassemble the response first");
  }
  return decodeSdoInfoResponse(message.header.opcode, message.data);
}

namespace {

template <typename Variant>
Result<std::size_t> encodeSingle(Bytes out, SdoInfoOpcode opcode, const Variant& message,
                                 MailboxHeader mailbox) {
  ECSIM_TRY(room(out, kSdoInfoDataOffset, "SDO information mailbox"));
  ECSIM_ASSIGN_OR_RETURN(
      std::size_t size,
      std::visit([&](const auto& m) { return m.encode(out.subspan(kSdoInfoDataOffset)); },
                 message));
  const SdoInfoHeader header{opcode, false, 0};
  ECSIM_TRY(header.encode(out.subspan(kCoeBodyOffset)));
  return finishCoeMailbox(out, mailbox, CoeHeader{0, CoeService::kSdoInformation},
                          kSdoInfoHeaderSize + size);
}

}  // namespace

Result<std::size_t> encodeSdoInfoRequestMailbox(Bytes out, const SdoInfoRequest& request,
                                                MailboxHeader mailbox) {
  return encodeSingle(out, opcodeOf(request), request, mailbox);
}

Result<std::size_t> encodeSdoInfoResponseMailbox(Bytes out, const SdoInfoResponse& response,
                                                 MailboxHeader mailbox) {
  return encodeSingle(out, opcodeOf(response), response, mailbox);
}

// --- fragmentation ----------------------------------------------------------------------------

Result<SdoInfoFragmenter> SdoInfoFragmenter::create(SdoInfoOpcode opcode, ConstBytes serviceData,
                                                    std::size_t mailboxSize) {
  if (mailboxSize < kSdoInfoDataOffset + 2) {
    return makeError(ErrorCode::kInvalidArgument,
                     "mailbox of " + std::to_string(mailboxSize) +
                         " bytes cannot carry SDO information data (needs at least 14)");
  }
  // Even pieces: SOEM reads whole u16 indexes from every OD list fragment.
  const std::size_t capacity = std::min<std::size_t>(mailboxSize - kSdoInfoDataOffset,
                                                     0xFFFF - kCoeHeaderSize - kSdoInfoHeaderSize) &
                               ~std::size_t{1};
  const std::size_t count =
      serviceData.empty() ? 1 : (serviceData.size() + capacity - 1) / capacity;
  if (count > 0x10000) {
    return makeError(ErrorCode::kTooLarge, std::to_string(serviceData.size()) + " bytes need " +
                                               std::to_string(count) +
                                               " fragments, more than fragments-left can count");
  }
  return SdoInfoFragmenter(opcode, serviceData, capacity, count);
}

Result<std::size_t> SdoInfoFragmenter::encodeFragment(std::size_t fragment, Bytes out,
                                                      MailboxHeader mailbox) const {
  if (fragment >= count_) {
    return makeError(ErrorCode::kInvalidArgument,
                     "fragment " + std::to_string(fragment) + " of " + std::to_string(count_));
  }
  const std::size_t begin = fragment * capacity_;
  const std::size_t size = std::min(capacity_, data_.size() - begin);
  ECSIM_TRY(room(out, kSdoInfoDataOffset + size, "SDO information fragment"));
  const auto left = static_cast<std::uint16_t>(count_ - 1 - fragment);
  const SdoInfoHeader header{opcode_, left != 0, left};
  ECSIM_TRY(header.encode(out.subspan(kCoeBodyOffset)));
  const auto piece = data_.subspan(begin, size);
  std::copy(piece.begin(), piece.end(), out.begin() + kSdoInfoDataOffset);
  return finishCoeMailbox(out, mailbox, CoeHeader{0, CoeService::kSdoInformation},
                          kSdoInfoHeaderSize + size);
}

void SdoInfoReassembler::reset() {
  data_.clear();
  fragmentsLeft_ = 0;
  started_ = false;
  complete_ = false;
}

Status SdoInfoReassembler::add(const SdoInfoMessage& fragment) {
  const SdoInfoHeader& h = fragment.header;
  if (h.opcode == SdoInfoOpcode::kError) {  // an error replaces whatever came before
    reset();
    started_ = true;
    complete_ = true;
    opcode_ = h.opcode;
    data_.assign(fragment.data.begin(), fragment.data.end());
    return okStatus();
  }
  std::string problem;
  if (complete_) {
    problem = "fragment after the last one";
  } else if (started_ && h.opcode != opcode_) {
    problem = "opcode changed from " + std::to_string(static_cast<unsigned>(opcode_)) + " to " +
              std::to_string(static_cast<unsigned>(h.opcode));
  } else if (started_ && h.fragmentsLeft + 1 != fragmentsLeft_) {
    problem = "fragments left " + std::to_string(h.fragmentsLeft) + " does not follow " +
              std::to_string(fragmentsLeft_);
  }
  if (!problem.empty()) {
    reset();
    return fault(ErrorCode::kMalformed, kCoeBodyOffset, "SDO information " + problem);
  }
  started_ = true;
  opcode_ = h.opcode;
  fragmentsLeft_ = h.fragmentsLeft;
  data_.insert(data_.end(), fragment.data.begin(), fragment.data.end());
  complete_ = h.fragmentsLeft == 0;
  return okStatus();
}

}  // namespace ecsim
