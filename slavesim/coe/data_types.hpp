// CoE data type codes (ETG.1000.6 §5.6.7.4 / CiA 301 §7.4.7) as carried in SDO information
// and SII PDO entries, with the properties the object dictionary and the SDO server need:
// size class, signedness, string-ness, and a printable name (the spelling SOEM's slaveinfo
// prints).
#pragma once

#include <cstdint>
#include <string_view>

namespace ecsim::slavesim::coe {

namespace data_type {
inline constexpr std::uint16_t kBoolean = 0x0001;
inline constexpr std::uint16_t kInteger8 = 0x0002;
inline constexpr std::uint16_t kInteger16 = 0x0003;
inline constexpr std::uint16_t kInteger32 = 0x0004;
inline constexpr std::uint16_t kUnsigned8 = 0x0005;
inline constexpr std::uint16_t kUnsigned16 = 0x0006;
inline constexpr std::uint16_t kUnsigned32 = 0x0007;
inline constexpr std::uint16_t kReal32 = 0x0008;
inline constexpr std::uint16_t kVisibleString = 0x0009;
inline constexpr std::uint16_t kOctetString = 0x000A;
inline constexpr std::uint16_t kUnicodeString = 0x000B;
inline constexpr std::uint16_t kTimeOfDay = 0x000C;
inline constexpr std::uint16_t kTimeDifference = 0x000D;
inline constexpr std::uint16_t kDomain = 0x000F;
inline constexpr std::uint16_t kInteger24 = 0x0010;
inline constexpr std::uint16_t kReal64 = 0x0011;
inline constexpr std::uint16_t kInteger40 = 0x0012;
inline constexpr std::uint16_t kInteger48 = 0x0013;
inline constexpr std::uint16_t kInteger56 = 0x0014;
inline constexpr std::uint16_t kInteger64 = 0x0015;
inline constexpr std::uint16_t kUnsigned24 = 0x0016;
inline constexpr std::uint16_t kUnsigned40 = 0x0018;
inline constexpr std::uint16_t kUnsigned48 = 0x0019;
inline constexpr std::uint16_t kUnsigned56 = 0x001A;
inline constexpr std::uint16_t kUnsigned64 = 0x001B;
inline constexpr std::uint16_t kByte = 0x001E;
inline constexpr std::uint16_t kWord = 0x001F;
inline constexpr std::uint16_t kDword = 0x0020;
// Complex types named in object descriptions of records.
inline constexpr std::uint16_t kPdoMapping = 0x0021;
inline constexpr std::uint16_t kIdentity = 0x0023;
inline constexpr std::uint16_t kSyncManagerParameter = 0x0029;
inline constexpr std::uint16_t kRecord = 0x002A;
// BIT1..BIT8: 0x0030 + (bits - 1).
inline constexpr std::uint16_t kBit1 = 0x0030;
inline constexpr std::uint16_t kBit8 = 0x0037;
constexpr std::uint16_t bitType(unsigned bits) {
  return static_cast<std::uint16_t>(kBit1 + (bits - 1));
}
}  // namespace data_type

// VISIBLE_STRING, OCTET_STRING, UNICODE_STRING, DOMAIN: a download may be shorter than the
// object; everything else must have exactly the object's size.
bool isStringType(std::uint16_t type);
bool isSignedType(std::uint16_t type);
bool isRealType(std::uint16_t type);
// "UNSIGNED16", "VISIBLE_STRING", "BIT3", ...; "UNKNOWN" for other codes.
std::string_view dataTypeName(std::uint16_t type);

}  // namespace ecsim::slavesim::coe
