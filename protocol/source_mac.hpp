// The source MAC address of an EtherCAT frame as ESCs pass it on: every ESC sets the locally
// administered (U/L) bit of its first byte (Beckhoff ESC datasheet section I §3), so a master
// tells its frames apart by the other bits.
#pragma once

#include <cstddef>
#include <cstdint>

namespace ecsim {

inline constexpr std::size_t kSourceMacOffset = 6;             // after the 6-byte destination
inline constexpr std::uint8_t kLocallyAdministeredBit = 0x02;  // bit 1 of the first byte

}  // namespace ecsim
