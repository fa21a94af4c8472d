#include "protocol/foe.hpp"

#include <algorithm>
#include <cstdio>
#include <string>

namespace ecsim {

std::string_view toString(FoeOpcode opcode) {
  switch (opcode) {
    case FoeOpcode::kRead:
      return "RRQ";
    case FoeOpcode::kWrite:
      return "WRQ";
    case FoeOpcode::kData:
      return "DATA";
    case FoeOpcode::kAck:
      return "ACK";
    case FoeOpcode::kError:
      return "ERR";
    case FoeOpcode::kBusy:
      return "BUSY";
  }
  return "unknown";
}

std::string_view foeErrorText(std::uint32_t code) {
  switch (static_cast<FoeErrorCode>(code)) {
    case FoeErrorCode::kNotDefined:
      return "not defined";
    case FoeErrorCode::kNotFound:
      return "not found";
    case FoeErrorCode::kAccessDenied:
      return "access denied";
    case FoeErrorCode::kDiskFull:
      return "disk full";
    case FoeErrorCode::kIllegal:
      return "illegal";
    case FoeErrorCode::kPacketNumberWrong:
      return "packet number wrong";
    case FoeErrorCode::kAlreadyExists:
      return "already exists";
    case FoeErrorCode::kNoUser:
      return "no user";
    case FoeErrorCode::kBootstrapOnly:
      return "bootstrap only";
    case FoeErrorCode::kNotBootstrap:
      return "not bootstrap";
    case FoeErrorCode::kNoRights:
      return "no rights";
    case FoeErrorCode::kProgramError:
      return "program error";
  }
  return "unknown FoE error";
}

std::string describeFoeError(std::uint32_t code) {
  char hex[16];
  std::snprintf(hex, sizeof hex, "0x%04X", static_cast<unsigned>(code));
  return std::string(hex) + " (" + std::string(foeErrorText(code)) + ")";
}

Result<FoePacket> decodeFoe(ConstBytes payload) {
  if (payload.size() < kFoeHeaderSize) {
    return makeError(ErrorCode::kTruncated, "FoE payload of " + std::to_string(payload.size()) +
                                                " bytes: the FoE header needs " +
                                                std::to_string(kFoeHeaderSize));
  }
  FoePacket p;
  p.opcode = static_cast<FoeOpcode>(readU8(payload, 0));
  p.value = readLe32(payload, 2);
  p.data = payload.subspan(kFoeHeaderSize);
  return p;
}

std::vector<std::uint8_t> encodeFoeMailbox(FoeOpcode opcode, std::uint32_t value,
                                           ConstBytes data) {
  std::vector<std::uint8_t> m(kFoeDataOffset + data.size(), 0);
  MailboxHeader h;
  h.type = MailboxType::kFoe;
  h.length = static_cast<std::uint16_t>(kFoeHeaderSize + data.size());
  (void)h.encode(m);
  writeU8(m, kMailboxHeaderSize, static_cast<std::uint8_t>(opcode));
  writeLe32(m, kMailboxHeaderSize + 2, value);
  std::copy(data.begin(), data.end(), m.begin() + kFoeDataOffset);
  return m;
}

}  // namespace ecsim
