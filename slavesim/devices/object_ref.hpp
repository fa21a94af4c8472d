// A device's cached handle on one object dictionary entry. Device models look their objects up
// once (off the cyclic path) and then read and write values through the entry's bytes, with no
// map lookup and no allocation. Valid while the dictionary keeps the object (values may change;
// an object replaced by ObjectDictionary::insert() needs a new lookup, as for the PDO binding).
#pragma once

#include <cstdint>

#include "slavesim/coe/data_types.hpp"
#include "slavesim/coe/object_dictionary.hpp"

namespace ecsim::slavesim::devices {

class ObjectRef {
 public:
  ObjectRef() = default;
  ObjectRef(coe::ObjectDictionary& od, std::uint16_t index, std::uint8_t subindex)
      : entry_(od.findEntry(index, subindex)) {}

  bool present() const { return entry_ != nullptr; }
  explicit operator bool() const { return present(); }

  // The value as an integer (sign-extended for signed types); `fallback` when absent.
  std::int64_t get(std::int64_t fallback = 0) const {
    if (entry_ == nullptr) return fallback;
    std::uint64_t raw = coe::readRawValue(ConstBytes(entry_->value), entry_->bitLength);
    const unsigned bits = entry_->bitLength > 64 ? 64u : entry_->bitLength;
    if (coe::isSignedType(entry_->dataType) && bits > 0 && bits < 64 &&
        ((raw >> (bits - 1)) & 1u) != 0) {
      raw |= ~std::uint64_t{0} << bits;
    }
    return static_cast<std::int64_t>(raw);
  }
  // The raw unsigned bits (UDINT values above INT64_MAX do not occur in our objects).
  std::uint64_t getUnsigned(std::uint64_t fallback = 0) const {
    if (entry_ == nullptr) return fallback;
    return coe::readRawValue(ConstBytes(entry_->value), entry_->bitLength);
  }
  // Writes the low bits of v (two's complement); does nothing when absent.
  void set(std::int64_t v) {
    if (entry_ == nullptr) return;
    coe::writeRawValue(Bytes(entry_->value), static_cast<std::uint64_t>(v), entry_->bitLength);
  }

 private:
  coe::Entry* entry_{nullptr};
};

}  // namespace ecsim::slavesim::devices
