// MII management interface bits (ESC registers 0x0510-0x0517, ESC datasheet section II) and
// the clause-22 PHY registers behind it (IEEE 802.3 clause 22.2.4). Register addresses are in
// registers.hpp (kMiiControlStatus ... kMiiPdiAccessState).
#pragma once

#include <cstdint>

namespace ecsim::reg {

namespace mii {  // 0x0510-0x0517 MII management (ESC datasheet section II)
inline constexpr std::uint16_t kWriteEnable = 0x0001;
inline constexpr std::uint16_t kPhyOffsetShift = 3;  // bits 7:3: PHY address of port 0
inline constexpr std::uint16_t kPhyOffsetMask = 0x00F8;
inline constexpr std::uint16_t kCommandMask = 0x0300;
inline constexpr std::uint16_t kCommandNop = 0x0000;  // idle; clears the error bits
inline constexpr std::uint16_t kCommandRead = 0x0100;
inline constexpr std::uint16_t kCommandWrite = 0x0200;
inline constexpr std::uint16_t kReadError = 0x2000;     // PHY or register not available
inline constexpr std::uint16_t kCommandError = 0x4000;  // invalid command / write not enabled
inline constexpr std::uint16_t kErrorBits = kReadError | kCommandError;
inline constexpr std::uint16_t kBusy = 0x8000;
inline constexpr std::uint8_t kAddressMask = 0x1F;       // 0x0512 and 0x0513 bits 4:0
inline constexpr std::uint8_t kEcatExclusive = 0x01;     // 0x0516 bit 0
inline constexpr std::uint8_t kPdiHasAccess = 0x01;      // 0x0517 bit 0
}  // namespace mii

// PHY registers behind the MII management interface (IEEE 802.3 clause 22.2.4).
namespace phy {
inline constexpr std::uint8_t kControl = 0;          // basic control
inline constexpr std::uint8_t kStatus = 1;           // basic status
inline constexpr std::uint8_t kId1 = 2;              // PHY identifier, OUI bits 3-18
inline constexpr std::uint8_t kId2 = 3;              // OUI bits 19-24, model, revision
inline constexpr std::uint8_t kAdvertisement = 4;    // auto-negotiation advertisement
inline constexpr std::uint8_t kLinkPartner = 5;      // auto-negotiation link partner ability
inline constexpr std::uint16_t kControlReset = 0x8000;       // self-clearing
inline constexpr std::uint16_t kControlSpeed100 = 0x2000;
inline constexpr std::uint16_t kControlAutoNegEnable = 0x1000;
inline constexpr std::uint16_t kControlFullDuplex = 0x0100;
inline constexpr std::uint16_t kStatusLinkUp = 0x0004;          // bit 2
inline constexpr std::uint16_t kStatusAutoNegComplete = 0x0020;  // bit 5
inline constexpr std::uint16_t kAcknowledge = 0x4000;           // register 5 bit 14
}  // namespace phy

}  // namespace ecsim::reg
