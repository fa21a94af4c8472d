// Typed values on the command line of `ecmaster` (upload, download, reg): parsing "0x1018:02",
// numbers in hex or decimal, and conversion between text and little-endian bytes for the
// CoE basic types (names as in IgH's `ethercat` tool: bool, int8 ... uint64, float, double,
// string, octets).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "protocol/bytes.hpp"
#include "protocol/result.hpp"

namespace ecsim::tools::ecmaster {

enum class ValueType {
  kRaw,  // no type given: bytes as they are
  kBool,
  kInt8,
  kInt16,
  kInt32,
  kInt64,
  kUint8,
  kUint16,
  kUint32,
  kUint64,
  kFloat,
  kDouble,
  kString,
  kOctets,
};

Result<ValueType> parseValueType(std::string_view name);
// Size in bytes of a fixed-size type, 0 for string/octets/raw.
std::size_t valueSize(ValueType type);

// "0x1018:02", "0x1018:2", "4120:2", "0x1018" (subindex 0).
Result<std::pair<std::uint16_t, std::uint8_t>> parseObjectAddress(std::string_view text);
// "0x130", "#x130", "304".
Result<std::uint64_t> parseUnsigned(std::string_view text, std::uint64_t max);

// Text -> bytes for a download or a register write ("octets": hex digits, blanks allowed).
Result<std::vector<std::uint8_t>> encodeValue(ValueType type, std::string_view text);
// Bytes -> text: integers as "0x002A 42", strings as they are, raw/octets as hex bytes.
Result<std::string> formatValue(ValueType type, ConstBytes bytes);
Result<nlohmann::json> jsonValue(ValueType type, ConstBytes bytes);

std::string hexBytes(ConstBytes bytes);

}  // namespace ecsim::tools::ecmaster
