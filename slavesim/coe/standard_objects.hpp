// The communication-area objects every CoE slave carries (ETG.1000.6 §5.6.7.4, ETG.1020):
// device type 0x1000, name 0x1008, versions 0x1009/0x100A, identity 0x1018, PDO mapping
// objects 0x1600-0x17FF (RxPDO) and 0x1A00-0x1BFF (TxPDO), SM communication types 0x1C00,
// PDO assignment 0x1C10+n (0x1C12 = SM2, 0x1C13 = SM3) and SM synchronisation parameters
// 0x1C32 (outputs) / 0x1C33 (inputs). Used by the ESI builder and by our own devices.
#pragma once

#include <cstdint>
#include <iterator>
#include <span>
#include <string>
#include <vector>

#include "protocol/coe.hpp"
#include "slavesim/coe/object_dictionary.hpp"

namespace ecsim::slavesim::coe {

inline constexpr std::uint16_t kDeviceTypeIndex = 0x1000;
inline constexpr std::uint16_t kDeviceNameIndex = 0x1008;
inline constexpr std::uint16_t kHardwareVersionIndex = 0x1009;
inline constexpr std::uint16_t kSoftwareVersionIndex = 0x100A;
inline constexpr std::uint16_t kStoreParametersIndex = 0x1010;  // CiA 301 store parameters
inline constexpr std::uint16_t kRestoreDefaultsIndex = 0x1011;  // restore default parameters
inline constexpr std::uint16_t kIdentityIndex = 0x1018;
inline constexpr std::uint16_t kSmTypesIndex = 0x1C00;
inline constexpr std::uint16_t kPdoAssignBase = 0x1C10;  // + SM number
inline constexpr std::uint16_t kSmOutputParameterIndex = 0x1C32;
inline constexpr std::uint16_t kSmInputParameterIndex = 0x1C33;

// 0x1C00 values.
inline constexpr std::uint8_t kSmTypeUnused = 0;
inline constexpr std::uint8_t kSmTypeMailboxOut = 1;
inline constexpr std::uint8_t kSmTypeMailboxIn = 2;
inline constexpr std::uint8_t kSmTypeOutputs = 3;
inline constexpr std::uint8_t kSmTypeInputs = 4;

constexpr bool isRxPdoMappingIndex(std::uint16_t index) {
  return index >= 0x1600 && index <= 0x17FF;
}
constexpr bool isTxPdoMappingIndex(std::uint16_t index) {
  return index >= 0x1A00 && index <= 0x1BFF;
}
constexpr bool isPdoMappingIndex(std::uint16_t index) {
  return isRxPdoMappingIndex(index) || isTxPdoMappingIndex(index);
}
constexpr bool isPdoAssignIndex(std::uint16_t index) {
  return index >= kPdoAssignBase && index < kPdoAssignBase + 32;
}

// A PDO mapping entry value: index << 16 | subindex << 8 | bit length.
struct MappedObject {
  std::uint16_t index{0};  // 0: a gap of bitLength bits
  std::uint8_t subindex{0};
  std::uint8_t bitLength{0};

  // Padding rather than an object: a gap (index 0) or a dummy entry (dummyEntryBits).
  constexpr bool isPadding() const { return isPaddingEntry(index); }

  static constexpr MappedObject fromRaw(std::uint32_t raw) {
    return {static_cast<std::uint16_t>(raw >> 16), static_cast<std::uint8_t>(raw >> 8),
            static_cast<std::uint8_t>(raw)};
  }
  constexpr std::uint32_t raw() const {
    return (static_cast<std::uint32_t>(index) << 16) | (static_cast<std::uint32_t>(subindex) << 8) |
           bitLength;
  }
  bool operator==(const MappedObject&) const = default;
};

struct IdentityValues {
  std::uint32_t vendorId{0};
  std::uint32_t productCode{0};
  std::uint32_t revision{0};
  std::uint32_t serial{0};
};

// Adds 0x1018 (RECORD IDENTITY, subs 1-4 UNSIGNED32 read-only), or, when the object exists
// (from an ESI), writes the values into its subs 1-4 (value and default).
void addIdentityObject(ObjectDictionary& od, const IdentityValues& identity);

// 0x1C00: ARRAY of UNSIGNED8, one element per SM (types above), read-only.
void addSyncManagerTypes(ObjectDictionary& od, std::span<const std::uint8_t> types);

struct PdoMappingSpec {
  std::uint16_t index{0};  // 0x16xx or 0x1Axx
  std::string name;
  std::vector<MappedObject> entries;
  std::vector<std::string> entryNames;  // optional, one per entry
  // Subindexes offered (>= entries.size()); a fixed PDO offers exactly its entries.
  std::uint8_t capacity{0};
  bool fixed{false};  // read-only; otherwise sub 0..capacity writable in PREOP
};
// RECORD PDO_MAPPING: sub 0 UNSIGNED8 = number of mapped entries, subs 1..capacity UNSIGNED32.
void addPdoMapping(ObjectDictionary& od, const PdoMappingSpec& spec);

// 0x1C10+sm: ARRAY of UNSIGNED16 with `capacity` elements, the first pdos.size() holding the
// assigned PDO indexes and sub 0 = pdos.size(). Writable in PREOP when `writable`.
void addPdoAssignment(ObjectDictionary& od, unsigned sm, std::span<const std::uint16_t> pdos,
                      std::uint8_t capacity, bool writable);

// ETG.1020 SM synchronisation type values (0x1C32:01 / 0x1C33:01).
inline constexpr std::uint16_t kSyncFreeRun = 0x0000;
inline constexpr std::uint16_t kSyncSm = 0x0001;
inline constexpr std::uint16_t kSyncDcSync0 = 0x0002;
inline constexpr std::uint16_t kSyncDcSync1 = 0x0003;
inline constexpr std::uint16_t kSyncSm2Event = 0x0022;  // 0x1C33 only: synchronous with SM2
// 0x1C32:04 / 0x1C33:04 bits: free run, SM synchronous, DC SYNC0.
inline constexpr std::uint16_t kSupportsFreeRun = 0x0001;
inline constexpr std::uint16_t kSupportsSm = 0x0002;
inline constexpr std::uint16_t kSupportsDcSync0 = 0x0004;

struct SyncParameters {
  std::uint16_t syncType{kSyncFreeRun};
  std::uint32_t cycleTimeNs{0};
  std::uint16_t supported{kSupportsFreeRun | kSupportsSm};
  std::uint32_t minimumCycleTimeNs{100000};
};
// RECORD SM_SYNCHRONISATION with subs 1-12 (ETG.1020 names): sync type and cycle time
// writable in PREOP, the rest read-only.
void addSyncManagerParameters(ObjectDictionary& od, std::uint16_t index,
                              const SyncParameters& parameters);

// Reads an assignment / mapping as currently configured (sub 0 entries).
std::vector<std::uint16_t> assignedPdos(const ObjectDictionary& od, unsigned sm);
std::vector<MappedObject> mappedObjects(const ObjectDictionary& od, std::uint16_t pdoIndex);

}  // namespace ecsim::slavesim::coe
