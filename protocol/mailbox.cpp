#include "protocol/mailbox.hpp"

#include <string>

namespace ecsim {

std::string_view toString(MailboxType type) {
  switch (type) {
    case MailboxType::kError:
      return "ERR";
    case MailboxType::kAoe:
      return "AoE";
    case MailboxType::kEoe:
      return "EoE";
    case MailboxType::kCoe:
      return "CoE";
    case MailboxType::kFoe:
      return "FoE";
    case MailboxType::kSoe:
      return "SoE";
    case MailboxType::kVoe:
      return "VoE";
  }
  return "unknown";
}

bool isKnownMailboxType(std::uint8_t raw) {
  return raw <= static_cast<std::uint8_t>(MailboxType::kSoe) ||
         raw == static_cast<std::uint8_t>(MailboxType::kVoe);
}

Result<MailboxHeader> MailboxHeader::decode(ConstBytes bytes) {
  if (bytes.size() < kMailboxHeaderSize) {
    return makeError(ErrorCode::kTruncated, "byte " + std::to_string(bytes.size()) +
                                                ": mailbox header needs 6 bytes, got " +
                                                std::to_string(bytes.size()));
  }
  MailboxHeader h;
  h.length = readLe16(bytes, 0);
  h.address = readLe16(bytes, 2);
  const std::uint8_t cp = readU8(bytes, 4);
  h.channel = static_cast<std::uint8_t>(cp & kMailboxChannelMax);
  h.priority = static_cast<std::uint8_t>(cp >> 6);
  const std::uint8_t tc = readU8(bytes, 5);
  h.type = static_cast<MailboxType>(tc & 0x0F);
  h.counter = static_cast<std::uint8_t>((tc >> 4) & kMailboxCounterMax);
  return h;
}

Result<std::size_t> MailboxHeader::encode(Bytes out) const {
  if (out.size() < kMailboxHeaderSize) {
    return makeError(ErrorCode::kTooLarge,
                     "mailbox header needs 6 bytes, buffer holds " + std::to_string(out.size()));
  }
  const auto rawType = static_cast<std::uint8_t>(type);
  if (channel > kMailboxChannelMax || priority > kMailboxPriorityMax ||
      counter > kMailboxCounterMax || rawType > 0x0F) {
    return makeError(ErrorCode::kInvalidArgument,
                     "mailbox header field out of range: channel " + std::to_string(channel) +
                         ", priority " + std::to_string(priority) + ", type " +
                         std::to_string(rawType) + ", counter " + std::to_string(counter));
  }
  writeLe16(out, 0, length);
  writeLe16(out, 2, address);
  writeU8(out, 4, static_cast<std::uint8_t>(channel | (priority << 6)));
  writeU8(out, 5, static_cast<std::uint8_t>(rawType | (counter << 4)));
  return kMailboxHeaderSize;
}

Result<MailboxMessage> decodeMailbox(ConstBytes buffer) {
  ECSIM_ASSIGN_OR_RETURN(MailboxHeader header, MailboxHeader::decode(buffer));
  const std::size_t available = buffer.size() - kMailboxHeaderSize;
  if (header.length > available) {
    return makeError(ErrorCode::kTruncated,
                     "byte 0: mailbox length " + std::to_string(header.length) +
                         " runs past the buffer (" + std::to_string(available) +
                         " bytes after the header)");
  }
  return MailboxMessage{header, buffer.subspan(kMailboxHeaderSize, header.length)};
}

Result<std::size_t> finishMailbox(Bytes out, MailboxHeader header, std::size_t payloadLength) {
  if (payloadLength > 0xFFFF) {
    return makeError(ErrorCode::kTooLarge, "mailbox payload of " + std::to_string(payloadLength) +
                                               " bytes exceeds the 16-bit length field");
  }
  if (out.size() < kMailboxHeaderSize + payloadLength) {
    return makeError(ErrorCode::kTooLarge,
                     "mailbox of " + std::to_string(kMailboxHeaderSize + payloadLength) +
                         " bytes does not fit a buffer of " + std::to_string(out.size()));
  }
  header.length = static_cast<std::uint16_t>(payloadLength);
  ECSIM_TRY(header.encode(out));
  return kMailboxHeaderSize + payloadLength;
}

std::string_view mailboxErrorText(std::uint16_t detail) {
  switch (static_cast<MailboxErrorCode>(detail)) {
    case MailboxErrorCode::kSyntax:
      return "syntax of the mailbox header is wrong";
    case MailboxErrorCode::kUnsupportedProtocol:
      return "mailbox protocol not supported";
    case MailboxErrorCode::kInvalidChannel:
      return "channel field is invalid";
    case MailboxErrorCode::kServiceNotSupported:
      return "service not supported by the protocol";
    case MailboxErrorCode::kInvalidHeader:
      return "protocol header is invalid";
    case MailboxErrorCode::kSizeTooShort:
      return "received data too short";
    case MailboxErrorCode::kNoMoreMemory:
      return "not enough memory to process the request";
    case MailboxErrorCode::kInvalidSize:
      return "data length is inconsistent";
  }
  return "unknown mailbox error";
}

Result<MailboxErrorReply> MailboxErrorReply::decode(ConstBytes payload) {
  if (payload.size() < kMailboxErrorSize) {
    return makeError(ErrorCode::kTruncated, "byte " + std::to_string(payload.size()) +
                                                ": mailbox error reply needs 4 bytes, got " +
                                                std::to_string(payload.size()));
  }
  const std::uint16_t service = readLe16(payload, 0);
  if (service != kMailboxErrorServiceType) {
    return makeError(ErrorCode::kMalformed,
                     "byte 0: mailbox error service type " + std::to_string(service) + " is not 1");
  }
  return MailboxErrorReply{readLe16(payload, 2)};
}

Result<std::size_t> MailboxErrorReply::encode(Bytes out) const {
  if (out.size() < kMailboxErrorSize) {
    return makeError(ErrorCode::kTooLarge, "mailbox error reply needs 4 bytes, buffer holds " +
                                               std::to_string(out.size()));
  }
  writeLe16(out, 0, kMailboxErrorServiceType);
  writeLe16(out, 2, detail);
  return kMailboxErrorSize;
}

Result<std::size_t> encodeMailboxError(Bytes out, MailboxErrorCode detail, MailboxHeader header) {
  if (out.size() < kMailboxHeaderSize + kMailboxErrorSize) {
    return makeError(ErrorCode::kTooLarge,
                     "mailbox error needs 10 bytes, buffer holds " + std::to_string(out.size()));
  }
  ECSIM_TRY(MailboxErrorReply{static_cast<std::uint16_t>(detail)}.encode(
      out.subspan(kMailboxHeaderSize)));
  header.type = MailboxType::kError;
  return finishMailbox(out, header, kMailboxErrorSize);
}

}  // namespace ecsim
