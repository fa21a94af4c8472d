#include "protocol/soe.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <optional>

namespace ecsim {
namespace {

constexpr std::uint8_t kOpcodeMask = 0x07;
constexpr std::uint8_t kIncompleteBit = 0x08;
constexpr std::uint8_t kErrorBit = 0x10;
constexpr unsigned kDriveShift = 5;

std::string byteText(std::size_t at) {
  return "byte " + std::to_string(at);
}

}  // namespace

std::string_view toString(SoeOpcode opcode) {
  switch (opcode) {
    case SoeOpcode::kReadRequest:
      return "read request";
    case SoeOpcode::kReadResponse:
      return "read response";
    case SoeOpcode::kWriteRequest:
      return "write request";
    case SoeOpcode::kWriteResponse:
      return "write response";
    case SoeOpcode::kNotification:
      return "notification";
    case SoeOpcode::kSlaveInfo:
      return "slave info";
  }
  return "reserved";
}

Result<SoeHeader> SoeHeader::decode(ConstBytes bytes) {
  if (bytes.size() < kSoeHeaderSize) {
    return makeError(
        ErrorCode::kTruncated,
        byteText(bytes.size()) + ": SoE header needs 4 bytes, got " + std::to_string(bytes.size()));
  }
  SoeHeader h;
  const std::uint8_t b0 = bytes[0];
  h.opcode = static_cast<SoeOpcode>(b0 & kOpcodeMask);
  h.incomplete = (b0 & kIncompleteBit) != 0;
  h.error = (b0 & kErrorBit) != 0;
  h.driveNo = static_cast<std::uint8_t>(b0 >> kDriveShift);
  h.elements = bytes[1];
  h.idn = readLe16(bytes, 2);
  return h;
}

Result<std::size_t> SoeHeader::encode(Bytes out) const {
  if (out.size() < kSoeHeaderSize) {
    return makeError(ErrorCode::kTooLarge,
                     "SoE header needs 4 bytes, buffer holds " + std::to_string(out.size()));
  }
  const auto op = static_cast<std::uint8_t>(opcode);
  if (driveNo > kSoeDriveMax || op > kOpcodeMask) {
    return makeError(ErrorCode::kInvalidArgument, "SoE header field out of range: drive " +
                                                      std::to_string(driveNo) + " (0-7), opcode " +
                                                      std::to_string(op) + " (0-7)");
  }
  out[0] = static_cast<std::uint8_t>(op | (incomplete ? kIncompleteBit : 0) |
                                     (error ? kErrorBit : 0) | (driveNo << kDriveShift));
  out[1] = elements;
  writeLe16(out, 2, idn);
  return kSoeHeaderSize;
}

Result<SoeMessage> decodeSoePayload(const MailboxMessage& message) {
  if (message.header.type != MailboxType::kSoe) {
    return makeError(ErrorCode::kMalformed,
                     "byte 5: mailbox type " +
                         std::to_string(static_cast<unsigned>(message.header.type)) +
                         " is not SoE (5)");
  }
  auto soe = SoeHeader::decode(message.payload);
  if (!soe.ok()) {
    return makeError(ErrorCode::kTruncated,
                     byteText(kMailboxHeaderSize + message.payload.size()) +
                         ": SoE header needs 4 bytes after the mailbox header, mailbox length is " +
                         std::to_string(message.payload.size()));
  }
  return SoeMessage{message.header, *soe, message.payload.subspan(kSoeHeaderSize)};
}

Result<SoeMessage> decodeSoeMailbox(ConstBytes buffer) {
  ECSIM_ASSIGN_OR_RETURN(MailboxMessage message, decodeMailbox(buffer));
  return decodeSoePayload(message);
}

Result<std::vector<std::uint8_t>> encodeSoeMailbox(const SoeHeader& soe, ConstBytes data,
                                                   MailboxHeader mailbox) {
  std::vector<std::uint8_t> out(kSoeDataOffset + data.size(), 0);
  ECSIM_TRY(soe.encode(Bytes(out).subspan(kMailboxHeaderSize)));
  std::copy(data.begin(), data.end(), out.begin() + kSoeDataOffset);
  mailbox.type = MailboxType::kSoe;
  ECSIM_TRY(finishMailbox(out, mailbox, kSoeHeaderSize + data.size()));
  return out;
}

Result<std::vector<std::uint8_t>> encodeSoeError(const SoeHeader& request, std::uint16_t code) {
  SoeHeader h = request;
  h.opcode = request.opcode == SoeOpcode::kWriteRequest ? SoeOpcode::kWriteResponse
                                                        : SoeOpcode::kReadResponse;
  h.error = true;
  h.incomplete = false;
  std::uint8_t data[kSoeErrorCodeSize];
  writeLe16(data, 0, code);
  return encodeSoeMailbox(h, data);
}

std::string formatIdn(std::uint16_t idn) {
  char text[16];
  std::snprintf(text, sizeof text, "%c-%u-%04u", (idn & kIdnProductSpecific) != 0 ? 'P' : 'S',
                static_cast<unsigned>((idn >> kIdnSetShift) & kIdnSetMask),
                static_cast<unsigned>(idn & kIdnBlockMask));
  return text;
}

Result<std::uint16_t> parseIdn(std::string_view text) {
  auto bad = [&](std::string why) {
    return makeError(ErrorCode::kInvalidArgument,
                     "IDN '" + std::string(text) + "': " + why +
                         " (write S-0-0016, P-0-0009 or a number such as 16 or 0x8009)");
  };
  auto number = [](std::string_view s, unsigned base,
                   unsigned long max) -> std::optional<unsigned long> {
    unsigned long v = 0;
    if (s.empty()) return std::nullopt;
    auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v, static_cast<int>(base));
    if (ec != std::errc{} || p != s.data() + s.size() || v > max) return std::nullopt;
    return v;
  };
  if (text.size() >= 2 && (text[0] == 'S' || text[0] == 's' || text[0] == 'P' || text[0] == 'p') &&
      text[1] == '-') {
    const std::size_t dash = text.find('-', 2);
    if (dash == std::string_view::npos) return bad("expected S-SET-BLOCK");
    auto set = number(text.substr(2, dash - 2), 10, kIdnSetMask);
    if (!set) return bad("parameter set must be 0-7");
    auto block = number(text.substr(dash + 1), 10, kIdnBlockMask);
    if (!block) return bad("data block must be 0-4095");
    const bool product = text[0] == 'P' || text[0] == 'p';
    return static_cast<std::uint16_t>((product ? kIdnProductSpecific : 0) | (*set << kIdnSetShift) |
                                      *block);
  }
  std::optional<unsigned long> v;
  if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
    v = number(text.substr(2), 16, 0xFFFF);
  } else {
    v = number(text, 10, 0xFFFF);
  }
  if (!v) return bad("not an IDN");
  return static_cast<std::uint16_t>(*v);
}

std::string SoeAttribute::describe() const {
  if (isProcedureCommand()) return "command";
  std::string out;
  switch (dataType()) {
    case SoeDataType::kText:
      return isList() ? "text" : "char";
    case SoeDataType::kIdn:
      out = "IDN";
      break;
    case SoeDataType::kSigned:
      out = "i" + std::to_string(elementSize() * 8);
      break;
    case SoeDataType::kFloat:
      out = "f" + std::to_string(elementSize() * 8);
      break;
    case SoeDataType::kHex:
      out = "x" + std::to_string(elementSize() * 8);
      break;
    case SoeDataType::kBinary:
      out = "b" + std::to_string(elementSize() * 8);
      break;
    default:
      out = "u" + std::to_string(elementSize() * 8);
      break;
  }
  return isList() ? out + " list" : out;
}

SoeAttribute SoeAttribute::make(std::size_t elementSize, bool list, bool command, SoeDataType type,
                                bool wpPreop, bool wpSafeop, bool wpOp) {
  std::uint32_t lengthCode = elementSize >= 8 ? 3 : elementSize >= 4 ? 2 : elementSize >= 2 ? 1 : 0;
  std::uint32_t raw = (lengthCode << 16) | (list ? 1u << 18 : 0) | (command ? 1u << 19 : 0) |
                      (static_cast<std::uint32_t>(type) << 20) | (wpPreop ? 1u << 28 : 0) |
                      (wpSafeop ? 1u << 29 : 0) | (wpOp ? 1u << 30 : 0);
  return SoeAttribute{raw};
}

std::int64_t soeNumber(ConstBytes element, bool isSigned) {
  std::uint64_t raw = 0;
  for (std::size_t i = 0; i < element.size() && i < 8; ++i) {
    raw |= static_cast<std::uint64_t>(element[i]) << (8 * i);
  }
  if (isSigned && element.size() < 8 && !element.empty() && (element.back() & 0x80) != 0) {
    raw |= ~std::uint64_t{0} << (8 * element.size());
  }
  return static_cast<std::int64_t>(raw);
}

std::string_view soeErrorText(std::uint16_t code) {
  switch (code) {
    case 0x0000:
      return "No error";
    case 0x1001:
      return "No IDN";
    case 0x1009:
      return "Invalid access to element 1";
    case 0x2001:
      return "No name";
    case 0x2002:
      return "Name transmission too short";
    case 0x2003:
      return "Name transmission too long";
    case 0x2004:
      return "Name cannot be changed (read only)";
    case 0x2005:
      return "Name is write-protected at this time";
    case 0x3002:
      return "Attribute transmission too short";
    case 0x3003:
      return "Attribute transmission too long";
    case 0x3004:
      return "Attribute cannot be changed (read only)";
    case 0x3005:
      return "Attribute is write-protected at this time";
    case 0x4001:
      return "No units";
    case 0x4002:
      return "Unit transmission too short";
    case 0x4003:
      return "Unit transmission too long";
    case 0x4004:
      return "Unit cannot be changed (read only)";
    case 0x4005:
      return "Unit is write-protected at this time";
    case 0x5001:
      return "No minimum input value";
    case 0x5002:
      return "Minimum input value transmission too short";
    case 0x5003:
      return "Minimum input value transmission too long";
    case 0x5004:
      return "Minimum input value cannot be changed (read only)";
    case 0x5005:
      return "Minimum input value is write-protected at this time";
    case 0x6001:
      return "No maximum input value";
    case 0x6002:
      return "Maximum input value transmission too short";
    case 0x6003:
      return "Maximum input value transmission too long";
    case 0x6004:
      return "Maximum input value cannot be changed (read only)";
    case 0x6005:
      return "Maximum input value is write-protected at this time";
    case 0x7002:
      return "Operation data transmission too short";
    case 0x7003:
      return "Operation data transmission too long";
    case 0x7004:
      return "Operation data cannot be changed (read only)";
    case 0x7005:
      return "Operation data is write-protected at this time (state)";
    case 0x7006:
      return "Operation data is smaller than the minimum input value";
    case 0x7007:
      return "Operation data is greater than the maximum input value";
    case 0x7008:
      return "Invalid operation data: configured IDN will not be supported";
    case 0x7009:
      return "Operation data write-protected by a password";
    case 0x700A:
      return "Operation data is write-protected, it is configured cyclically";
    case 0x700B:
      return "Invalid indirect addressing (data container, list handling)";
    case 0x700C:
      return "Operation data is write-protected due to other settings";
    case 0x7010:
      return "Procedure command already active";
    case 0x7011:
      return "Procedure command not interruptible";
    case 0x7012:
      return "Procedure command at this time not executable (state)";
    case 0x7013:
      return "Procedure command not executable (invalid or false parameters)";
    case 0x7014:
      return "No data state";
    case 0x8001:
      return "No default value";
    case 0x8002:
      return "Default value transmission too long";
    case 0x8004:
      return "Default value cannot be changed (read only)";
    case 0x800A:
      return "Invalid drive number";
    case 0x800B:
      return "General error";
    case 0x800C:
      return "No element addressed";
    default:
      return "unknown SoE error";
  }
}

std::vector<std::uint8_t> encodeSoeList(ConstBytes data, std::uint16_t maxLength) {
  std::vector<std::uint8_t> out(kSoeListHeaderSize + data.size());
  writeLe16(out, 0, static_cast<std::uint16_t>(data.size()));
  writeLe16(out, 2, std::max<std::uint16_t>(maxLength, static_cast<std::uint16_t>(data.size())));
  std::copy(data.begin(), data.end(), out.begin() + kSoeListHeaderSize);
  return out;
}

Result<SoeList> decodeSoeList(ConstBytes bytes) {
  if (bytes.size() < kSoeListHeaderSize) {
    return makeError(ErrorCode::kTruncated, byteText(bytes.size()) +
                                                ": a list needs its 4-byte length header, got " +
                                                std::to_string(bytes.size()) + " bytes");
  }
  SoeList list;
  list.currentLength = readLe16(bytes, 0);
  list.maxLength = readLe16(bytes, 2);
  if (kSoeListHeaderSize + list.currentLength > bytes.size()) {
    return makeError(ErrorCode::kTruncated,
                     "byte 0: list current length " + std::to_string(list.currentLength) +
                         " runs past the " + std::to_string(bytes.size() - kSoeListHeaderSize) +
                         " data bytes");
  }
  list.data = bytes.subspan(kSoeListHeaderSize, list.currentLength);
  return list;
}

Result<SoeElements> splitSoeElements(std::uint8_t elements, ConstBytes data,
                                     SoeAttribute attribute) {
  SoeElements out;
  out.attribute = attribute;
  std::size_t at = 0;
  auto need = [&](std::size_t n, std::string_view what) -> Status {
    if (at + n > data.size()) {
      return makeError(ErrorCode::kTruncated, byteText(at) + ": " + std::string(what) + " needs " +
                                                  std::to_string(n) + " bytes, " +
                                                  std::to_string(data.size() - at) + " left");
    }
    return {};
  };
  auto list = [&](std::string_view what) -> Result<std::vector<std::uint8_t>> {
    ECSIM_TRY(need(kSoeListHeaderSize, what));
    const std::size_t n = kSoeListHeaderSize + readLe16(data, at);
    ECSIM_TRY(need(n, what));
    const ConstBytes slice = data.subspan(at, n);
    std::vector<std::uint8_t> v(slice.begin(), slice.end());
    at += n;
    return v;
  };
  auto text = [&](std::string_view what) -> Result<std::string> {
    ECSIM_ASSIGN_OR_RETURN(auto v, list(what));
    return std::string(v.begin() + kSoeListHeaderSize, v.end());
  };
  auto value = [&](std::string_view what) -> Result<std::vector<std::uint8_t>> {
    if (out.attribute.isList()) return list(what);
    const std::size_t n = out.attribute.elementSize();
    ECSIM_TRY(need(n, what));
    const ConstBytes slice = data.subspan(at, n);
    std::vector<std::uint8_t> v(slice.begin(), slice.end());
    at += n;
    return v;
  };
  if (elements & soe_element::kDataState) {
    ECSIM_TRY(need(kSoeDataStateSize, "data state"));
    out.dataState = readLe16(data, at);
    at += kSoeDataStateSize;
  }
  if (elements & soe_element::kName) {
    ECSIM_ASSIGN_OR_RETURN(out.name, text("name"));
  }
  if (elements & soe_element::kAttribute) {
    ECSIM_TRY(need(kSoeAttributeSize, "attribute"));
    out.attribute.raw = readLe32(data, at);
    at += kSoeAttributeSize;
  }
  if (elements & soe_element::kUnit) {
    ECSIM_ASSIGN_OR_RETURN(out.unit, text("unit"));
  }
  if (elements & soe_element::kMinimum) {
    ECSIM_ASSIGN_OR_RETURN(out.minimum, value("minimum"));
  }
  if (elements & soe_element::kMaximum) {
    ECSIM_ASSIGN_OR_RETURN(out.maximum, value("maximum"));
  }
  if (elements & soe_element::kValue) {
    ECSIM_ASSIGN_OR_RETURN(out.value, value("value"));
  }
  if (elements & soe_element::kDefault) {
    ECSIM_ASSIGN_OR_RETURN(out.defaultValue, value("default"));
  }
  if (at != data.size()) {
    return makeError(ErrorCode::kMalformed, byteText(at) + ": " + std::to_string(data.size() - at) +
                                                " bytes after the elements asked for");
  }
  return out;
}

}  // namespace ecsim
