#include "slavesim/coe/data_types.hpp"

namespace ecsim::slavesim::coe {

bool isStringType(std::uint16_t type) {
  return type == data_type::kVisibleString || type == data_type::kOctetString ||
         type == data_type::kUnicodeString || type == data_type::kDomain;
}

bool isSignedType(std::uint16_t type) {
  switch (type) {
    case data_type::kInteger8:
    case data_type::kInteger16:
    case data_type::kInteger24:
    case data_type::kInteger32:
    case data_type::kInteger40:
    case data_type::kInteger48:
    case data_type::kInteger56:
    case data_type::kInteger64:
      return true;
    default:
      return false;
  }
}

bool isRealType(std::uint16_t type) {
  return type == data_type::kReal32 || type == data_type::kReal64;
}

std::string_view dataTypeName(std::uint16_t type) {
  switch (type) {
    case data_type::kBoolean:
      return "BOOLEAN";
    case data_type::kInteger8:
      return "INTEGER8";
    case data_type::kInteger16:
      return "INTEGER16";
    case data_type::kInteger24:
      return "INTEGER24";
    case data_type::kInteger32:
      return "INTEGER32";
    case data_type::kInteger64:
      return "INTEGER64";
    case data_type::kUnsigned8:
      return "UNSIGNED8";
    case data_type::kUnsigned16:
      return "UNSIGNED16";
    case data_type::kUnsigned24:
      return "UNSIGNED24";
    case data_type::kUnsigned32:
      return "UNSIGNED32";
    case data_type::kUnsigned64:
      return "UNSIGNED64";
    case data_type::kReal32:
      return "REAL32";
    case data_type::kReal64:
      return "REAL64";
    case data_type::kVisibleString:
      return "VISIBLE_STRING";
    case data_type::kOctetString:
      return "OCTET_STRING";
    case data_type::kUnicodeString:
      return "UNICODE_STRING";
    case data_type::kDomain:
      return "DOMAIN";
    case data_type::kByte:
      return "BYTE";
    case data_type::kWord:
      return "WORD";
    case data_type::kDword:
      return "DWORD";
    case data_type::kPdoMapping:
      return "PDO_MAPPING";
    case data_type::kIdentity:
      return "IDENTITY";
    case data_type::kSyncManagerParameter:
      return "SM_SYNCHRONISATION";
    case data_type::kRecord:
      return "RECORD";
    default:
      break;
  }
  if (type >= data_type::kBit1 && type <= data_type::kBit8) {
    static constexpr std::string_view kBits[] = {"BIT1", "BIT2", "BIT3", "BIT4",
                                                 "BIT5", "BIT6", "BIT7", "BIT8"};
    return kBits[type - data_type::kBit1];
  }
  return "UNKNOWN";
}

}  // namespace ecsim::slavesim::coe
