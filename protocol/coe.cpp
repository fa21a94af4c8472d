#include "protocol/coe.hpp"

#include <algorithm>
#include <string>

namespace ecsim {

std::string_view toString(CoeService service) {
  switch (service) {
    case CoeService::kEmergency:
      return "Emergency";
    case CoeService::kSdoRequest:
      return "SDO request";
    case CoeService::kSdoResponse:
      return "SDO response";
    case CoeService::kTxPdo:
      return "TxPDO";
    case CoeService::kRxPdo:
      return "RxPDO";
    case CoeService::kTxPdoRemoteRequest:
      return "TxPDO remote request";
    case CoeService::kRxPdoRemoteRequest:
      return "RxPDO remote request";
    case CoeService::kSdoInformation:
      return "SDO information";
  }
  return "unknown";
}

Result<CoeHeader> CoeHeader::decode(ConstBytes bytes) {
  if (bytes.size() < kCoeHeaderSize) {
    return makeError(ErrorCode::kTruncated, "byte " + std::to_string(bytes.size()) +
                                                ": CoE header needs 2 bytes, got " +
                                                std::to_string(bytes.size()));
  }
  return fromRaw(readLe16(bytes, 0));
}

Result<std::size_t> CoeHeader::encode(Bytes out) const {
  if (out.size() < kCoeHeaderSize) {
    return makeError(ErrorCode::kTooLarge,
                     "CoE header needs 2 bytes, buffer holds " + std::to_string(out.size()));
  }
  const auto rawService = static_cast<std::uint8_t>(service);
  if (number > kCoeNumberMax || rawService > 0x0F) {
    return makeError(ErrorCode::kInvalidArgument, "CoE header field out of range: number " +
                                                      std::to_string(number) + ", service " +
                                                      std::to_string(rawService));
  }
  writeLe16(out, 0, raw());
  return kCoeHeaderSize;
}

Result<CoeMessage> decodeCoeMailbox(ConstBytes buffer) {
  ECSIM_ASSIGN_OR_RETURN(MailboxMessage message, decodeMailbox(buffer));
  if (message.header.type != MailboxType::kCoe) {
    return makeError(ErrorCode::kMalformed,
                     "byte 5: mailbox type " +
                         std::to_string(static_cast<unsigned>(message.header.type)) +
                         " is not CoE (3)");
  }
  if (message.payload.size() < kCoeHeaderSize) {
    return makeError(ErrorCode::kTruncated, "byte 0: mailbox length " +
                                                std::to_string(message.header.length) +
                                                " leaves no room for the CoE header");
  }
  const CoeHeader coe = CoeHeader::fromRaw(readLe16(message.payload, 0));
  return CoeMessage{message.header, coe, message.payload.subspan(kCoeHeaderSize)};
}

Result<std::size_t> finishCoeMailbox(Bytes out, MailboxHeader mailbox, CoeHeader coe,
                                     std::size_t bodyLength) {
  if (out.size() < kCoeBodyOffset + bodyLength) {
    return makeError(ErrorCode::kTooLarge,
                     "CoE mailbox of " + std::to_string(kCoeBodyOffset + bodyLength) +
                         " bytes does not fit a buffer of " + std::to_string(out.size()));
  }
  ECSIM_TRY(coe.encode(out.subspan(kMailboxHeaderSize)));
  mailbox.type = MailboxType::kCoe;
  return finishMailbox(out, mailbox, kCoeHeaderSize + bodyLength);
}

Result<Emergency> Emergency::decode(ConstBytes body) {
  if (body.size() < kSize) {
    return makeError(ErrorCode::kTruncated, "byte " + std::to_string(body.size()) +
                                                ": emergency needs 8 bytes, got " +
                                                std::to_string(body.size()));
  }
  Emergency e;
  e.errorCode = readLe16(body, 0);
  e.errorRegister = readU8(body, 2);
  std::copy_n(body.begin() + 3, e.data.size(), e.data.begin());
  return e;
}

Result<std::size_t> Emergency::encode(Bytes out) const {
  if (out.size() < kSize) {
    return makeError(ErrorCode::kTooLarge,
                     "emergency needs 8 bytes, buffer holds " + std::to_string(out.size()));
  }
  writeLe16(out, 0, errorCode);
  writeU8(out, 2, errorRegister);
  std::copy(data.begin(), data.end(), out.begin() + 3);
  return kSize;
}

Result<std::size_t> encodeEmergencyMailbox(Bytes out, const Emergency& emergency,
                                           MailboxHeader mailbox) {
  if (out.size() < kCoeBodyOffset + Emergency::kSize) {
    return makeError(ErrorCode::kTooLarge, "emergency mailbox needs 16 bytes, buffer holds " +
                                               std::to_string(out.size()));
  }
  ECSIM_TRY(emergency.encode(out.subspan(kCoeBodyOffset)));
  return finishCoeMailbox(out, mailbox, CoeHeader{0, CoeService::kEmergency}, Emergency::kSize);
}

Result<Emergency> decodeEmergencyMailbox(ConstBytes buffer) {
  ECSIM_ASSIGN_OR_RETURN(CoeMessage message, decodeCoeMailbox(buffer));
  if (message.coe.service != CoeService::kEmergency) {
    return makeError(ErrorCode::kMalformed,
                     "byte 7: CoE service " +
                         std::to_string(static_cast<unsigned>(message.coe.service)) +
                         " is not emergency (1)");
  }
  if (message.body.size() < Emergency::kSize) {
    return makeError(ErrorCode::kTruncated,
                     "byte " + std::to_string(kCoeBodyOffset + message.body.size()) +
                         ": emergency needs 8 bytes after the CoE header");
  }
  return Emergency::decode(message.body);
}

}  // namespace ecsim
