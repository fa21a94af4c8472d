// ESI value syntax: integers, booleans, hex binary, text helpers.
#include <algorithm>
#include <cctype>
#include <limits>

#include "config/esi.hpp"
#include "protocol/sii.hpp"

namespace ecsim {
namespace {

int hexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

bool equalsIgnoreCase(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) ==
                  std::tolower(static_cast<unsigned char>(y));
         });
}

}  // namespace

std::string_view trimEsiText(std::string_view text) {
  auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  while (!text.empty() && blank(text.front())) text.remove_prefix(1);
  while (!text.empty() && blank(text.back())) text.remove_suffix(1);
  return text;
}

Result<std::int64_t> parseEsiInteger(std::string_view raw) {
  std::string_view text = trimEsiText(raw);
  const std::string quoted = "'" + std::string(raw) + "'";
  if (text.empty()) return makeError(ErrorCode::kParse, "empty number");
  bool negative = false;
  if (text.front() == '-' || text.front() == '+') {
    negative = text.front() == '-';
    text.remove_prefix(1);
  }
  int base = 10;
  if (text.size() >= 2 && text[0] == '#' && (text[1] == 'x' || text[1] == 'X')) {
    base = 16;
    text.remove_prefix(2);
  } else if (text.size() >= 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
    base = 16;
    text.remove_prefix(2);
  }
  if (base == 16 && text.size() >= 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
    text.remove_prefix(2);  // "#x0x6041"
  }
  if (text.empty()) return makeError(ErrorCode::kParse, "no digits in " + quoted);
  // Magnitudes up to 2^64-1 are accepted (a u64 written in hex) and folded into int64 two's
  // complement only when they fit; larger values are an error.
  std::uint64_t value = 0;
  for (char c : text) {
    const int digit = hexDigit(c);
    if (digit < 0 || digit >= base) {
      return makeError(ErrorCode::kParse, "not a number: " + quoted);
    }
    const auto b = static_cast<std::uint64_t>(base);
    if (value >
        (std::numeric_limits<std::uint64_t>::max() - static_cast<std::uint64_t>(digit)) / b) {
      return makeError(ErrorCode::kParse, "number too large: " + quoted);
    }
    value = value * b + static_cast<std::uint64_t>(digit);
  }
  constexpr auto kMax = static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());
  if (negative) {
    if (value > kMax + 1) return makeError(ErrorCode::kParse, "number too small: " + quoted);
    return value == kMax + 1 ? std::numeric_limits<std::int64_t>::min()
                             : -static_cast<std::int64_t>(value);
  }
  if (value > kMax) return makeError(ErrorCode::kParse, "number too large: " + quoted);
  return static_cast<std::int64_t>(value);
}

Result<bool> parseEsiBool(std::string_view raw) {
  const std::string_view text = trimEsiText(raw);
  if (text == "1" || equalsIgnoreCase(text, "true")) return true;
  if (text == "0" || equalsIgnoreCase(text, "false")) return false;
  return makeError(ErrorCode::kParse, "not a boolean: '" + std::string(raw) + "'");
}

Result<std::vector<std::uint8_t>> parseEsiHexBinary(std::string_view text) {
  std::vector<std::uint8_t> out;
  int high = -1;
  for (char c : text) {
    if (c == ' ' || c == '\t' || c == '\r' || c == '\n') continue;
    const int digit = hexDigit(c);
    if (digit < 0) {
      return makeError(ErrorCode::kParse, std::string("not a hex digit: '") + c + "'");
    }
    if (high < 0) {
      high = digit;
    } else {
      out.push_back(static_cast<std::uint8_t>((high << 4) | digit));
      high = -1;
    }
  }
  if (high >= 0) return makeError(ErrorCode::kParse, "odd number of hex digits");
  return out;
}

std::string latin1ToUtf8(std::string_view latin1) {
  std::string out;
  out.reserve(latin1.size());
  for (char ch : latin1) {
    const auto c = static_cast<unsigned char>(ch);
    if (c < 0x80) {
      out += ch;
    } else {
      out += static_cast<char>(0xC0 | (c >> 6));
      out += static_cast<char>(0x80 | (c & 0x3F));
    }
  }
  return out;
}

std::string_view pickLocalText(const std::vector<EsiLocalText>& texts, std::uint32_t lcid) {
  for (const auto& t : texts) {
    if (t.lcid == lcid) return t.text;
  }
  for (const auto& t : texts) {
    if (t.lcid == 0) return t.text;
  }
  for (const auto& t : texts) {
    if (t.lcid == 1033) return t.text;
  }
  return texts.empty() ? std::string_view{} : std::string_view(texts.front().text);
}

std::string EsiFile::display(std::string_view text) const {
  return encoding == EsiEncoding::kLatin1 ? latin1ToUtf8(text) : std::string(text);
}

const EsiGroup* EsiFile::findGroup(std::string_view type) const {
  for (const auto& g : groups) {
    if (g.type == type) return &g;
  }
  return nullptr;
}

std::uint32_t EsiPdo::bitLength() const {
  std::uint32_t bits = 0;
  for (const auto& e : entries) bits += e.bitLength;
  return bits;
}

std::uint16_t EsiMailbox::protocolMask() const {
  std::uint16_t mask = 0;
  if (aoe) mask |= SiiMailboxProtocol::kAoe;
  if (eoe) mask |= SiiMailboxProtocol::kEoe;
  if (coe) mask |= SiiMailboxProtocol::kCoe;
  if (foe) mask |= SiiMailboxProtocol::kFoe;
  if (soe) mask |= SiiMailboxProtocol::kSoe;
  if (voe) mask |= SiiMailboxProtocol::kVoe;
  return mask;
}

bool EsiFlags::rxMappable() const {
  return pdoMapping.find_first_of("Rr") != std::string::npos;
}

bool EsiFlags::txMappable() const {
  return pdoMapping.find_first_of("Tt") != std::string::npos;
}

const EsiObject* EsiDictionary::findObject(std::uint32_t index) const {
  for (const auto& o : objects) {
    if (o.index == index) return &o;
  }
  return nullptr;
}

const EsiDataType* EsiDictionary::findDataType(std::string_view name) const {
  for (const auto& d : dataTypes) {
    if (d.name == name) return &d;
  }
  return nullptr;
}

}  // namespace ecsim
