// The CoE object dictionary of a simulated slave (ETG.1000.6 §5.6.7, CiA 301 §7.4): objects
// (VAR, ARRAY, RECORD) made of entries (subindexes), each with its data type, bit length,
// name, access rights per state, PDO mappability, current value (little-endian bytes), default
// and optional limits.
//
// One dictionary is shared by the SDO server (mailbox side), the process-data binding (SM
// buffers) and the device model (typed get<T>/set<T>): all of them read and write the same
// bytes. Entry value buffers keep their size for the dictionary's lifetime, so the binding
// may hold pointers to them; replacing an object (insert() with an existing index) invalidates
// those pointers and requires a rebind.
//
// Built from an ESI <Dictionary> by od_from_esi.hpp, or programmatically with the add*()
// helpers here and in standard_objects.hpp.
#pragma once

#include <bit>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "protocol/al_status.hpp"
#include "protocol/bytes.hpp"
#include "protocol/result.hpp"
#include "protocol/sdo_info.hpp"
#include "slavesim/coe/data_types.hpp"

namespace ecsim::slavesim::coe {

// Access word, exactly the SDO-information "object access" layout (sdo_info.hpp kAccess*).
namespace access {
inline constexpr std::uint16_t kReadAll = kAccessReadPreOp | kAccessReadSafeOp | kAccessReadOp;
inline constexpr std::uint16_t kWriteAll = kAccessWritePreOp | kAccessWriteSafeOp | kAccessWriteOp;
inline constexpr std::uint16_t kReadOnly = kReadAll;
inline constexpr std::uint16_t kReadWrite = kReadAll | kWriteAll;
inline constexpr std::uint16_t kReadWritePreOp = kReadAll | kAccessWritePreOp;
inline constexpr std::uint16_t kWriteOnly = kWriteAll;
inline constexpr std::uint16_t kRxMappable = kAccessRxPdoMappable;
inline constexpr std::uint16_t kTxMappable = kAccessTxPdoMappable;
// The read (write) bit for one state; 0 for INIT and BOOT (no SDO access there).
std::uint16_t readBit(AlState state);
std::uint16_t writeBit(AlState state);
}  // namespace access

struct Entry {
  std::uint8_t subindex{0};
  std::uint16_t dataType{0};
  std::uint16_t bitLength{0};
  std::string name;
  std::uint16_t access{access::kReadOnly};
  std::vector<std::uint8_t> value;         // byteSize() bytes, little-endian
  std::vector<std::uint8_t> defaultValue;  // byteSize() bytes
  std::vector<std::uint8_t> minimum;       // empty: no lower limit, else byteSize() bytes
  std::vector<std::uint8_t> maximum;       // empty: no upper limit

  std::size_t byteSize() const { return (static_cast<std::size_t>(bitLength) + 7) / 8; }
  bool readable(AlState state) const { return (access & access::readBit(state)) != 0; }
  bool writable(AlState state) const { return (access & access::writeBit(state)) != 0; }
  bool readableSomewhere() const { return (access & access::kReadAll) != 0; }
  bool writableSomewhere() const { return (access & access::kWriteAll) != 0; }
  bool rxMappable() const { return (access & access::kRxMappable) != 0; }
  bool txMappable() const { return (access & access::kTxMappable) != 0; }
};

struct Object {
  std::uint16_t index{0};
  ObjectCode code{ObjectCode::kVar};
  // VAR: the entry's type; ARRAY: the element type; RECORD: a complex type (kIdentity,
  // kPdoMapping, kSyncManagerParameter, kRecord).
  std::uint16_t dataType{0};
  std::string name;
  std::vector<Entry> entries;  // ascending subindex, gaps allowed in records

  Entry* entry(std::uint8_t subindex);
  const Entry* entry(std::uint8_t subindex) const;
  // Highest subindex present (SDO information "max subindex").
  std::uint8_t maxSubindex() const;
};

// What the ESI says about a PDO beyond its mapping (used when an assignment is written).
struct PdoRules {
  bool fixed{false};
  bool mandatory{false};
  std::optional<std::uint8_t> defaultSm;  // Sm attribute: assigned to this SM by default
  std::vector<std::uint16_t> excludes;
};

// Value helpers: raw little-endian integer of up to 8 bytes, masked to `bits`.
std::uint64_t readRawValue(ConstBytes value, std::uint16_t bits);
void writeRawValue(Bytes value, std::uint64_t raw, std::uint16_t bits);
// Typed comparison of two values of `dataType` (signed, unsigned or real): <0, 0, >0.
int compareValues(std::uint16_t dataType, std::uint16_t bits, ConstBytes a, ConstBytes b);

class ObjectDictionary {
 public:
  // Adds an object, or replaces the one with the same index. Entries are sorted by subindex
  // and every value/default is sized to its entry's byteSize().
  Object& insert(Object object);
  bool erase(std::uint16_t index);

  Object* find(std::uint16_t index);
  const Object* find(std::uint16_t index) const;
  Entry* findEntry(std::uint16_t index, std::uint8_t subindex);
  const Entry* findEntry(std::uint16_t index, std::uint8_t subindex) const;
  bool contains(std::uint16_t index) const { return find(index) != nullptr; }
  std::size_t size() const { return objects_.size(); }
  const std::map<std::uint16_t, Object>& objects() const { return objects_; }

  // Current value bytes of an entry (empty span when absent).
  ConstBytes bytes(std::uint16_t index, std::uint8_t subindex) const;
  // Copies data into the value (zero-padded, truncated to the entry's size). kNotFound if absent.
  Status setBytes(std::uint16_t index, std::uint8_t subindex, ConstBytes data);

  // Typed access for device code: no access-right or range checks (the device owns its
  // objects). Integers read the value's bits (sign-extended for signed T); float/double read
  // a 4- or 8-byte value as REAL32/REAL64. kNotFound when the entry does not exist.
  template <typename T>
  Result<T> get(std::uint16_t index, std::uint8_t subindex) const;
  template <typename T>
  T getOr(std::uint16_t index, std::uint8_t subindex, T fallback) const {
    auto r = get<T>(index, subindex);
    return r.ok() ? r.value() : fallback;
  }
  template <typename T>
  Status set(std::uint16_t index, std::uint8_t subindex, T value);

  // Every value back to its default.
  void resetToDefaults();

  // Power-up values: what each entry holds when the device is switched on (ESI defaults plus
  // what the builder and the device model set up). capturePowerUpValues() takes the current
  // values as that image; restorePowerUpValues() writes it back (entries it does not cover,
  // added later, get their default), as a power cycle does to everything a device does not
  // keep in non-volatile memory. Objects and value sizes are left as they are.
  void capturePowerUpValues();
  void restorePowerUpValues();
  bool hasPowerUpValues() const { return !powerUp_.empty(); }
  // CiA 301 0x1010 "store parameters" / 0x1011 "restore default parameters" for the objects
  // first..last: the current values (storePowerUpValues) or the defaults
  // (defaultPowerUpValues) of their writable entries become their power-up values, effective
  // at the next power cycle. Read-only entries keep theirs.
  void storePowerUpValues(std::uint16_t first, std::uint16_t last);
  void defaultPowerUpValues(std::uint16_t first, std::uint16_t last);

  // ---- building -----------------------------------------------------------------------------
  // A VAR with its value at sub 0 (value zero, default zero).
  Object& addVar(std::uint16_t index, std::string name, std::uint16_t dataType,
                 std::uint16_t bitLength, std::uint16_t accessBits);
  // A VISIBLE_STRING VAR holding `text` (bit length 8 * size). An entry's bit length is 16 bits
  // wide (ETG.1000.6 entry description), so a longer text keeps its first 8191 bytes.
  Object& addString(std::uint16_t index, std::string name, std::string_view text,
                    std::uint16_t accessBits = access::kReadOnly);
  // An ARRAY: sub 0 (UNSIGNED8, = count) and `count` elements of one type.
  Object& addArray(std::uint16_t index, std::string name, std::uint16_t elementType,
                   std::uint16_t elementBits, std::uint8_t count, std::uint16_t elementAccess,
                   std::uint16_t sub0Access = access::kReadOnly);
  // A RECORD with sub 0 (UNSIGNED8) only; add entries with addEntry(). Sub 0's value is kept
  // at the highest subindex as entries are added.
  Object& addRecord(std::uint16_t index, std::string name, std::uint16_t recordType,
                    std::uint16_t sub0Access = access::kReadOnly);
  Entry& addEntry(std::uint16_t index, Entry entry);

  PdoRules& pdoRules(std::uint16_t pdoIndex) { return pdoRules_[pdoIndex]; }
  const PdoRules* findPdoRules(std::uint16_t pdoIndex) const;
  const std::map<std::uint16_t, PdoRules>& allPdoRules() const { return pdoRules_; }

 private:
  std::map<std::uint16_t, Object> objects_;
  std::map<std::uint16_t, PdoRules> pdoRules_;
  std::map<std::uint32_t, std::vector<std::uint8_t>> powerUp_;  // key: index << 8 | subindex
};

// ---- template definitions --------------------------------------------------------------------

template <typename T>
Result<T> ObjectDictionary::get(std::uint16_t index, std::uint8_t subindex) const {
  static_assert(std::is_arithmetic_v<T>, "get<T> needs an arithmetic T");
  const Entry* e = findEntry(index, subindex);
  if (e == nullptr) {
    return makeError(
        ErrorCode::kNotFound,
        "object dictionary has no entry " + std::to_string(index) + ":" + std::to_string(subindex));
  }
  ConstBytes v(e->value);
  if constexpr (std::is_same_v<T, bool>) {
    return readRawValue(v, e->bitLength) != 0;
  } else if constexpr (std::is_floating_point_v<T>) {
    if (v.size() == 4) return static_cast<T>(std::bit_cast<float>(readLe32(v, 0)));
    if (v.size() == 8) return static_cast<T>(std::bit_cast<double>(readLe64(v, 0)));
    return makeError(ErrorCode::kInvalidArgument, "entry is not a 4- or 8-byte real");
  } else {
    std::uint64_t raw = readRawValue(v, e->bitLength);
    const unsigned bits = e->bitLength > 64 ? 64u : e->bitLength;
    if constexpr (std::is_signed_v<T>) {
      if (bits > 0 && bits < 64 && ((raw >> (bits - 1)) & 1u) != 0) {
        raw |= ~std::uint64_t{0} << bits;  // sign-extend
      }
      return static_cast<T>(static_cast<std::int64_t>(raw));
    } else {
      return static_cast<T>(raw);
    }
  }
}

template <typename T>
Status ObjectDictionary::set(std::uint16_t index, std::uint8_t subindex, T value) {
  static_assert(std::is_arithmetic_v<T>, "set<T> needs an arithmetic T");
  Entry* e = findEntry(index, subindex);
  if (e == nullptr) {
    return makeError(
        ErrorCode::kNotFound,
        "object dictionary has no entry " + std::to_string(index) + ":" + std::to_string(subindex));
  }
  Bytes v(e->value);
  if constexpr (std::is_floating_point_v<T>) {
    if (v.size() == 4) {
      writeLe32(v, 0, std::bit_cast<std::uint32_t>(static_cast<float>(value)));
    } else if (v.size() == 8) {
      writeLe64(v, 0, std::bit_cast<std::uint64_t>(static_cast<double>(value)));
    } else {
      return makeError(ErrorCode::kInvalidArgument, "entry is not a 4- or 8-byte real");
    }
  } else {
    writeRawValue(v, static_cast<std::uint64_t>(value), e->bitLength);
  }
  return okStatus();
}

}  // namespace ecsim::slavesim::coe
