// SII image builder: an ESI device description -> the EEPROM contents a real device of that
// type would carry (ETG.2010), as SiiContents or as bytes.
//
// What comes from where:
//   config area      Eeprom/ConfigData when given, else defaults (see sii_builder.cpp)
//   identity         Vendor/Id, Type@ProductCode, Type@RevisionNo, options.serial
//   bootstrap mbx    Eeprom/BootStrap (4 words), else 0
//   standard mbx     the SMs of type MBoxOut (receive) and MBoxIn (send)
//   protocols        Mailbox/AoE, EoE, CoE, FoE, SoE, VoE
//   size             the smallest standard EEPROM size (1, 2, 4, ... Kbit) holding both
//                    Eeprom/ByteSize and the content; 2 Kbit when ByteSize is absent
//   STRINGS          1 device name (or type, see options), group type, type (order number),
//                    image name, DC op mode names, PDO and PDO entry names; deduplicated
//   GENERAL, FMMU, SYNCM, TXPDO/RXPDO (PDOs with an Sm attribute only), DC, and the vendor's
//   own Eeprom/Category entries kept raw.
// Eeprom/Data, when a vendor gives a whole image, is used as is (only parsed and checked).
#pragma once

#include <cstdint>
#include <vector>

#include "config/esi.hpp"
#include "protocol/result.hpp"
#include "protocol/sii.hpp"

namespace ecsim {

struct SiiBuildOptions {
  std::uint32_t serial{0};
  // String 1 is what SOEM shows as the slave name. true: the ESI <Name> (this project's
  // choice, so a master shows the descriptive name); false: the <Type> text, which is what
  // Beckhoff and SOES-generated images put first (e.g. "EK1100").
  bool deviceNameFirst{true};
  // TXPDO/RXPDO categories (SOEM uses them when CoE gives no mapping). Some generators leave
  // them out for CoE devices (SOES, STMBL images).
  bool pdoCategories{true};
  // Names of PDOs and entries in STRINGS (they can make an image outgrow its ByteSize).
  bool pdoNameStrings{true};
  bool padToEepromSize{true};
};

// CoE basic data type code (ETG.1000.6 / ETG.1020: BOOL 0x01, SINT 0x02, ... BIT8 0x37) for an
// ESI DataType name; 0 when unknown.
std::uint8_t coeDataTypeCode(std::string_view esiTypeName);

Result<SiiContents> makeSiiContents(const EsiDevice& device, std::uint32_t vendorId,
                                    const SiiBuildOptions& options = {});
Result<std::vector<std::uint8_t>> buildSiiImage(const EsiDevice& device, std::uint32_t vendorId,
                                                const SiiBuildOptions& options = {});

}  // namespace ecsim
