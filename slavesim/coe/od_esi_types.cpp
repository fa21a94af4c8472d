// ESI type names and Flags -> CoE data types and access bits (see od_from_esi.hpp).
#include <algorithm>
#include <cctype>

#include "config/sii_builder.hpp"
#include "slavesim/coe/od_esi_detail.hpp"
#include "slavesim/coe/od_from_esi.hpp"

namespace ecsim::slavesim::coe {
namespace esi_detail {

std::string upperAscii(std::string_view s) {
  std::string out(trimEsiText(s));
  for (auto& c : out) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

namespace {

std::uint16_t defaultBits(std::uint16_t code) {
  namespace dt = data_type;
  switch (code) {
    case dt::kBoolean:
      return 1;
    case dt::kInteger8:
    case dt::kUnsigned8:
    case dt::kByte:
      return 8;
    case dt::kInteger16:
    case dt::kUnsigned16:
    case dt::kWord:
      return 16;
    case dt::kInteger24:
    case dt::kUnsigned24:
      return 24;
    case dt::kInteger32:
    case dt::kUnsigned32:
    case dt::kReal32:
    case dt::kDword:
      return 32;
    case dt::kInteger64:
    case dt::kUnsigned64:
    case dt::kReal64:
      return 64;
    default:
      break;
  }
  if (code >= dt::kBit1 && code <= dt::kBit8)
    return static_cast<std::uint16_t>(code - dt::kBit1 + 1);
  return 0;
}

bool isIntegerCode(std::uint16_t code) {
  return defaultBits(code) > 0 && !isRealType(code);
}

}  // namespace

std::uint16_t typeForBits(std::uint32_t bits) {
  if (bits == 1) return data_type::kBoolean;
  if (bits > 1 && bits < 8) return data_type::bitType(bits);
  switch (bits) {
    case 8:
      return data_type::kUnsigned8;
    case 16:
      return data_type::kUnsigned16;
    case 24:
      return data_type::kUnsigned24;
    case 32:
      return data_type::kUnsigned32;
    case 64:
      return data_type::kUnsigned64;
    default:
      return data_type::kOctetString;
  }
}

std::uint16_t clampBits(std::uint32_t bits) {
  return static_cast<std::uint16_t>(std::min<std::uint32_t>(bits, 0xFFFF));
}

namespace {

ResolvedType resolve(const EsiDictionary& dict, std::string_view typeName, std::uint32_t hint,
                     int depth) {
  const std::string name = upperAscii(typeName);
  if (name.rfind("STRING", 0) == 0) {
    return {data_type::kVisibleString, clampBits(hint)};
  }
  if (std::uint16_t code = coeDataTypeCode(name); code != 0) {
    const std::uint16_t bits = hint != 0 ? clampBits(hint) : defaultBits(code);
    if (code == data_type::kBoolean && bits > 1) return {typeForBits(bits), bits};
    return {code, bits};
  }
  const EsiDataType* dt = depth < 8 ? dict.findDataType(trimEsiText(typeName)) : nullptr;
  if (dt != nullptr && !dt->isRecord()) {
    const std::uint32_t bits = dt->bitSize != 0 ? dt->bitSize : hint;
    if (dt->isArray()) return {data_type::kOctetString, clampBits(bits)};
    ResolvedType base = resolve(dict, dt->baseType, bits, depth + 1);
    if (bits > 0 && bits < 8 && isIntegerCode(base.dataType)) {
      return {typeForBits(bits), clampBits(bits)};
    }
    return {base.dataType, clampBits(bits != 0 ? bits : base.bitLength)};
  }
  // Vendor decorations such as "UINT_hex", "UDINT_hex".
  if (auto cut = name.find('_'); cut != std::string::npos && cut > 0) {
    if (std::uint16_t code = coeDataTypeCode(name.substr(0, cut)); code != 0) {
      return {code, hint != 0 ? clampBits(hint) : defaultBits(code)};
    }
  }
  return {typeForBits(hint), clampBits(hint)};
}

std::uint16_t stateBits(std::string_view restrictions, bool write) {
  const std::uint16_t pre = write ? kAccessWritePreOp : kAccessReadPreOp;
  const std::uint16_t safe = write ? kAccessWriteSafeOp : kAccessReadSafeOp;
  const std::uint16_t op = write ? kAccessWriteOp : kAccessReadOp;
  if (trimEsiText(restrictions).empty()) return static_cast<std::uint16_t>(pre | safe | op);
  std::uint16_t bits = 0;
  std::string token;
  const std::string text = upperAscii(restrictions) + "_";
  for (char c : text) {
    if (c == '_' || c == ',' || c == ' ') {
      if (token == "PREOP") bits |= pre;
      if (token == "SAFEOP") bits |= safe;
      if (token == "OP") bits |= op;
      token.clear();
    } else {
      token += c;
    }
  }
  return bits;
}

}  // namespace

std::uint16_t pdoBits(const EsiFlags& flags) {
  std::uint16_t bits = 0;
  if (flags.rxMappable()) bits |= access::kRxMappable;
  if (flags.txMappable()) bits |= access::kTxMappable;
  return bits;
}

}  // namespace esi_detail

using esi_detail::pdoBits;

ResolvedType resolveEsiType(const EsiDictionary& dictionary, std::string_view typeName,
                            std::uint32_t bitSizeHint) {
  return esi_detail::resolve(dictionary, typeName, bitSizeHint, 0);
}

std::uint16_t accessFromEsiFlags(const EsiFlags& flags) {
  std::uint16_t bits = 0;
  switch (flags.access) {
    case EsiAccess::kUnspecified:
    case EsiAccess::kReadOnly:
      bits = esi_detail::stateBits(flags.readRestrictions, false);
      break;
    case EsiAccess::kReadWrite:
      bits = static_cast<std::uint16_t>(esi_detail::stateBits(flags.readRestrictions, false) |
                                        esi_detail::stateBits(flags.writeRestrictions, true));
      break;
    case EsiAccess::kWriteOnly:
      bits = esi_detail::stateBits(flags.writeRestrictions, true);
      break;
  }
  return static_cast<std::uint16_t>(bits | pdoBits(flags));
}

}  // namespace ecsim::slavesim::coe
