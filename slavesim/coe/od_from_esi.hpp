// Object dictionary of an ESI device (ETG.2000 <Profile><Dictionary>, <RxPdo>/<TxPdo>, <Sm>).
//
// Objects of the ESI dictionary become objects here:
//   - a plain or alias type (UDINT, STRING(10), an enum DataType with a BaseType) -> VAR;
//   - a DataType with SubItems -> RECORD, or ARRAY when it is "sub 0 + an array-typed SubItem
//     without SubIdx" (the Beckhoff/SSC layout of 0x1C12, 0x1C00...), the array expanded into
//     subindexes LBound..LBound+Elements-1;
//   - an array DataType of bytes used directly ("ARRAY [0..5] OF BYTE") -> one OCTET_STRING;
//   - Info/SubItem entries are matched to the entries by name, else by position; each gives
//     the entry's default (DefaultData in wire order, else DefaultValue, else DefaultString),
//     limits (MinValue/MaxValue) and may override its Flags;
//   - Flags/Access ro|rw|wo with ReadRestrictions/WriteRestrictions ("PreOP", "PreOP_SafeOP",
//     "SafeOP_OP", ...) give the per-state bits, PdoMapping R/T the mappability.
// Then the standard objects are completed (standard_objects.hpp): 0x1000, 0x1008, 0x1009,
// 0x100A and 0x1C32/0x1C33 when the ESI has none; 0x1018 always carries the given identity;
// 0x1C00 from the <Sm> list; a mapping object per <RxPdo>/<TxPdo> (read-only when Fixed,
// else writable in PREOP); 0x1C10+n per process-data SM holding the PDOs whose Sm attribute
// is n. ESI definitions of these objects are kept (their writes limited to PREOP); their defaults
// come from the device's own PDO description (Sm attributes, PDO entries) when the ESI leaves
// them empty or says otherwise (a shared dictionary naming PDOs the device does not have; the
// difference is noted), zero entries in an assignment count as absent. A modular device's
// module idents (EsiDevice::moduleIdents) fill 0xF030/0xF050. Objects that PDO entries map but the
// dictionary lacks (devices without a dictionary) are created, read-only for inputs and
// read-write for outputs, and every mapped entry is marked RX/TX mappable.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "config/esi.hpp"
#include "slavesim/coe/object_dictionary.hpp"

namespace ecsim::slavesim::coe {

struct OdBuildOptions {
  std::uint32_t vendorId{0};  // the ESI file's <Vendor><Id>
  std::uint32_t serial{0};
  // Mapping objects of non-fixed PDOs offer this many subindexes when the device allows PDO
  // configuration (<CoE PdoConfig="true">), so a master can map more entries.
  std::uint8_t configurableMappingCapacity{8};
};

// Things worth knowing that did not stop the build (unknown types, ESI defaults that disagree
// with the PDO list, ...), one line each.
struct OdBuildReport {
  std::vector<std::string> notes;
  // PDOs whose own entries could not be mapped, so the dictionary's default mapping was kept:
  // the SII PDO categories must say the same (makeSlaveFromEsi).
  std::vector<std::uint16_t> keptMappings;
};

ObjectDictionary buildObjectDictionary(const EsiDevice& device, const OdBuildOptions& options,
                                       OdBuildReport* report = nullptr);

// The CoE type code and bit size an ESI type name stands for in `dictionary` (basic names,
// STRING(n), BITn, aliases and enums through their BaseType, byte arrays as OCTET_STRING).
// `bitSizeHint` is the BitSize written next to the type (used when the name says nothing).
struct ResolvedType {
  std::uint16_t dataType{0};
  std::uint16_t bitLength{0};
};
ResolvedType resolveEsiType(const EsiDictionary& dictionary, std::string_view typeName,
                            std::uint32_t bitSizeHint);

// Access bits for ESI Flags (unspecified access -> read-only).
std::uint16_t accessFromEsiFlags(const EsiFlags& flags);

}  // namespace ecsim::slavesim::coe
