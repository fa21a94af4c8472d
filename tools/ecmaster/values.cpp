#include "tools/ecmaster/values.hpp"

#include <fmt/core.h>

#include <bit>
#include <charconv>
#include <cstring>
#include <limits>

namespace ecsim::tools::ecmaster {
namespace {

struct TypeName {
  std::string_view name;
  ValueType type;
  std::size_t size;
};

constexpr TypeName kTypes[] = {
    {"bool", ValueType::kBool, 1},     {"int8", ValueType::kInt8, 1},
    {"int16", ValueType::kInt16, 2},   {"int32", ValueType::kInt32, 4},
    {"int64", ValueType::kInt64, 8},   {"uint8", ValueType::kUint8, 1},
    {"uint16", ValueType::kUint16, 2}, {"uint32", ValueType::kUint32, 4},
    {"uint64", ValueType::kUint64, 8}, {"float", ValueType::kFloat, 4},
    {"double", ValueType::kDouble, 8}, {"string", ValueType::kString, 0},
    {"octets", ValueType::kOctets, 0},
};

bool isSigned(ValueType t) {
  return t == ValueType::kInt8 || t == ValueType::kInt16 || t == ValueType::kInt32 ||
         t == ValueType::kInt64;
}

std::uint64_t readLe(ConstBytes b, std::size_t n) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < n; ++i) v |= static_cast<std::uint64_t>(b[i]) << (8 * i);
  return v;
}

std::int64_t signExtend(std::uint64_t v, std::size_t bytes) {
  if (bytes >= 8) return static_cast<std::int64_t>(v);
  const std::uint64_t sign = 1ull << (8 * bytes - 1);
  return static_cast<std::int64_t>((v ^ sign) - sign);
}

Result<std::int64_t> parseSigned(std::string_view text) {
  bool negative = !text.empty() && text.front() == '-';
  if (negative) text.remove_prefix(1);
  ECSIM_ASSIGN_OR_RETURN(
      std::uint64_t magnitude,
      parseUnsigned(text, static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()) +
                              (negative ? 1 : 0)));
  if (negative) return static_cast<std::int64_t>(0 - magnitude);
  return static_cast<std::int64_t>(magnitude);
}

// A value of a fixed-size type needs at least that many bytes.
Status checkLength(std::size_t size, ConstBytes bytes) {
  if (size != 0 && bytes.size() < size) {
    return makeError(ErrorCode::kTruncated,
                     fmt::format("{} bytes where the type needs {}", bytes.size(), size));
  }
  return {};
}

}  // namespace

Result<ValueType> parseValueType(std::string_view name) {
  for (const auto& t : kTypes) {
    if (t.name == name) return t.type;
  }
  std::string known;
  for (const auto& t : kTypes) known += (known.empty() ? "" : ", ") + std::string(t.name);
  return makeError(ErrorCode::kInvalidArgument,
                   "unknown type '" + std::string(name) + "' (known: " + known + ")");
}

std::size_t valueSize(ValueType type) {
  for (const auto& t : kTypes) {
    if (t.type == type) return t.size;
  }
  return 0;
}

Result<std::uint64_t> parseUnsigned(std::string_view text, std::uint64_t max) {
  int base = 10;
  if (text.starts_with("0x") || text.starts_with("0X") || text.starts_with("#x")) {
    text.remove_prefix(2);
    base = 16;
  }
  std::uint64_t value = 0;
  auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value, base);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size()) {
    return makeError(ErrorCode::kInvalidArgument, "'" + std::string(text) + "' is not a number");
  }
  if (value > max) {
    return makeError(ErrorCode::kInvalidArgument,
                     "'" + std::string(text) + "' is larger than " + std::to_string(max));
  }
  return value;
}

Result<std::pair<std::uint16_t, std::uint8_t>> parseObjectAddress(std::string_view text) {
  const auto colon = text.find(':');
  ECSIM_ASSIGN_OR_RETURN(std::uint64_t index, parseUnsigned(text.substr(0, colon), 0xFFFF));
  std::uint64_t sub = 0;
  if (colon != std::string_view::npos) {
    std::string_view s = text.substr(colon + 1);
    // "0x1018:02": a subindex written next to a hex index is hex, as in "0x6000:11".
    if (text.starts_with("0x") && !s.starts_with("0x")) {
      ECSIM_ASSIGN_OR_RETURN(sub, parseUnsigned("0x" + std::string(s), 0xFF));
    } else {
      ECSIM_ASSIGN_OR_RETURN(sub, parseUnsigned(s, 0xFF));
    }
  }
  return std::pair{static_cast<std::uint16_t>(index), static_cast<std::uint8_t>(sub)};
}

Result<std::vector<std::uint8_t>> encodeValue(ValueType type, std::string_view text) {
  std::vector<std::uint8_t> out;
  const std::size_t size = valueSize(type);
  switch (type) {
    case ValueType::kString:
      return std::vector<std::uint8_t>(text.begin(), text.end());
    case ValueType::kRaw:
    case ValueType::kOctets: {
      std::string digits;
      for (char c : text) {
        if (c != ' ' && c != ':') digits += c;
      }
      if (digits.starts_with("0x")) digits.erase(0, 2);
      if (digits.empty() || digits.size() % 2 != 0) {
        return makeError(ErrorCode::kInvalidArgument, "octets want an even number of hex digits");
      }
      for (std::size_t i = 0; i < digits.size(); i += 2) {
        ECSIM_ASSIGN_OR_RETURN(std::uint64_t b, parseUnsigned("0x" + digits.substr(i, 2), 0xFF));
        out.push_back(static_cast<std::uint8_t>(b));
      }
      return out;
    }
    case ValueType::kBool: {
      if (text == "true" || text == "1") return std::vector<std::uint8_t>{1};
      if (text == "false" || text == "0") return std::vector<std::uint8_t>{0};
      return makeError(ErrorCode::kInvalidArgument, "bool wants true/false/1/0");
    }
    case ValueType::kFloat:
    case ValueType::kDouble: {
      double v = 0;
      try {
        v = std::stod(std::string(text));
      } catch (const std::exception&) {
        return makeError(ErrorCode::kInvalidArgument,
                         "'" + std::string(text) + "' is not a number");
      }
      out.resize(size);
      if (type == ValueType::kFloat) {
        writeLe32(out, 0, std::bit_cast<std::uint32_t>(static_cast<float>(v)));
      } else {
        writeLe64(out, 0, std::bit_cast<std::uint64_t>(v));
      }
      return out;
    }
    default:
      break;
  }
  std::uint64_t raw = 0;
  if (isSigned(type)) {
    ECSIM_ASSIGN_OR_RETURN(std::int64_t v, parseSigned(text));
    const std::int64_t limit = size >= 8 ? std::numeric_limits<std::int64_t>::max()
                                         : (std::int64_t{1} << (8 * size - 1)) - 1;
    if (v > limit || v < -limit - 1) {
      return makeError(ErrorCode::kInvalidArgument, "'" + std::string(text) + "' does not fit " +
                                                        std::to_string(size) + " bytes");
    }
    raw = static_cast<std::uint64_t>(v);
  } else {
    const std::uint64_t max = size >= 8 ? ~0ull : (1ull << (8 * size)) - 1;
    ECSIM_ASSIGN_OR_RETURN(raw, parseUnsigned(text, max));
  }
  out.resize(size);
  for (std::size_t i = 0; i < size; ++i) out[i] = static_cast<std::uint8_t>(raw >> (8 * i));
  return out;
}

std::string hexBytes(ConstBytes bytes) {
  std::string s;
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    s += fmt::format("{}{:02x}", i == 0 ? "" : " ", bytes[i]);
  }
  return s;
}

Result<std::string> formatValue(ValueType type, ConstBytes bytes) {
  const std::size_t size = valueSize(type);
  ECSIM_TRY(checkLength(size, bytes));
  switch (type) {
    case ValueType::kRaw:
    case ValueType::kOctets:
      return hexBytes(bytes);
    case ValueType::kString:
      return std::string(bytes.begin(), bytes.end());
    case ValueType::kBool:
      return std::string(bytes[0] != 0 ? "true" : "false");
    case ValueType::kFloat:
      return fmt::format("{}", std::bit_cast<float>(readLe32(bytes, 0)));
    case ValueType::kDouble:
      return fmt::format("{}", std::bit_cast<double>(readLe64(bytes, 0)));
    default:
      break;
  }
  const std::uint64_t raw = readLe(bytes, size);
  if (isSigned(type)) {
    return fmt::format("0x{:0{}x} {}", raw, 2 * size, signExtend(raw, size));
  }
  return fmt::format("0x{:0{}x} {}", raw, 2 * size, raw);
}

Result<nlohmann::json> jsonValue(ValueType type, ConstBytes bytes) {
  const std::size_t size = valueSize(type);
  ECSIM_TRY(checkLength(size, bytes));
  switch (type) {
    case ValueType::kRaw:
    case ValueType::kOctets:
      return nlohmann::json(hexBytes(bytes));
    case ValueType::kString:
      return nlohmann::json(std::string(bytes.begin(), bytes.end()));
    case ValueType::kBool:
      return nlohmann::json(bytes[0] != 0);
    case ValueType::kFloat:
      return nlohmann::json(std::bit_cast<float>(readLe32(bytes, 0)));
    case ValueType::kDouble:
      return nlohmann::json(std::bit_cast<double>(readLe64(bytes, 0)));
    default:
      break;
  }
  const std::uint64_t raw = readLe(bytes, size);
  if (isSigned(type)) return nlohmann::json(signExtend(raw, size));
  return nlohmann::json(raw);
}

}  // namespace ecsim::tools::ecmaster
