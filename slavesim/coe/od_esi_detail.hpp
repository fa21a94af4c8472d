// Internal helpers shared by od_from_esi.cpp and od_esi_types.cpp (not a public API).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "config/esi.hpp"

namespace ecsim::slavesim::coe::esi_detail {

// Trimmed, upper-case ASCII copy.
std::string upperAscii(std::string_view s);
// The CoE type a bare bit size suggests (BOOL, BITn, UNSIGNEDn, else OCTET_STRING).
std::uint16_t typeForBits(std::uint32_t bits);
std::uint16_t clampBits(std::uint32_t bits);
// RX/TX mappable access bits of ESI Flags/PdoMapping.
std::uint16_t pdoBits(const EsiFlags& flags);

}  // namespace ecsim::slavesim::coe::esi_detail
