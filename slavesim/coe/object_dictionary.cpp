#include "slavesim/coe/object_dictionary.hpp"

#include <algorithm>
#include <cstring>
#include <limits>

namespace ecsim::slavesim::coe {

// ---- access ----------------------------------------------------------------------------------

namespace access {
std::uint16_t readBit(AlState state) {
  switch (state) {
    case AlState::kPreOp:
      return kAccessReadPreOp;
    case AlState::kSafeOp:
      return kAccessReadSafeOp;
    case AlState::kOp:
      return kAccessReadOp;
    default:
      return 0;
  }
}
std::uint16_t writeBit(AlState state) {
  switch (state) {
    case AlState::kPreOp:
      return kAccessWritePreOp;
    case AlState::kSafeOp:
      return kAccessWriteSafeOp;
    case AlState::kOp:
      return kAccessWriteOp;
    default:
      return 0;
  }
}
}  // namespace access

// ---- values ----------------------------------------------------------------------------------

std::uint64_t readRawValue(ConstBytes value, std::uint16_t bits) {
  std::uint64_t raw = 0;
  const std::size_t n = std::min<std::size_t>(value.size(), 8);
  for (std::size_t i = 0; i < n; ++i) raw |= static_cast<std::uint64_t>(value[i]) << (8 * i);
  if (bits > 0 && bits < 64) raw &= (std::uint64_t{1} << bits) - 1;
  return raw;
}

void writeRawValue(Bytes value, std::uint64_t raw, std::uint16_t bits) {
  if (bits > 0 && bits < 64) raw &= (std::uint64_t{1} << bits) - 1;
  const std::size_t n = std::min<std::size_t>(value.size(), 8);
  for (std::size_t i = 0; i < n; ++i) value[i] = static_cast<std::uint8_t>(raw >> (8 * i));
}

int compareValues(std::uint16_t dataType, std::uint16_t bits, ConstBytes a, ConstBytes b) {
  if (dataType == data_type::kReal32 && a.size() >= 4 && b.size() >= 4) {
    const float x = std::bit_cast<float>(readLe32(a, 0));
    const float y = std::bit_cast<float>(readLe32(b, 0));
    return x < y ? -1 : (x > y ? 1 : 0);
  }
  if (dataType == data_type::kReal64 && a.size() >= 8 && b.size() >= 8) {
    const double x = std::bit_cast<double>(readLe64(a, 0));
    const double y = std::bit_cast<double>(readLe64(b, 0));
    return x < y ? -1 : (x > y ? 1 : 0);
  }
  std::uint64_t x = readRawValue(a, bits);
  std::uint64_t y = readRawValue(b, bits);
  if (isSignedType(dataType)) {
    const unsigned n = bits > 64 ? 64u : bits;
    auto extend = [n](std::uint64_t v) {
      if (n > 0 && n < 64 && ((v >> (n - 1)) & 1u) != 0) v |= ~std::uint64_t{0} << n;
      return static_cast<std::int64_t>(v);
    };
    const std::int64_t sx = extend(x);
    const std::int64_t sy = extend(y);
    return sx < sy ? -1 : (sx > sy ? 1 : 0);
  }
  return x < y ? -1 : (x > y ? 1 : 0);
}

// ---- objects ---------------------------------------------------------------------------------

Entry* Object::entry(std::uint8_t subindex) {
  for (auto& e : entries) {
    if (e.subindex == subindex) return &e;
  }
  return nullptr;
}

const Entry* Object::entry(std::uint8_t subindex) const {
  for (const auto& e : entries) {
    if (e.subindex == subindex) return &e;
  }
  return nullptr;
}

std::uint8_t Object::maxSubindex() const {
  std::uint8_t max = 0;
  for (const auto& e : entries) max = std::max(max, e.subindex);
  return max;
}

namespace {

void normalise(Entry& e) {
  const std::size_t n = e.byteSize();
  e.value.resize(n, 0);
  e.defaultValue.resize(n, 0);
  if (!e.minimum.empty()) e.minimum.resize(n, 0);
  if (!e.maximum.empty()) e.maximum.resize(n, 0);
}

std::string where(std::uint16_t index, std::uint8_t subindex) {
  constexpr char kDigits[] = "0123456789ABCDEF";
  std::string s = "0x";
  for (int shift = 12; shift >= 0; shift -= 4) s += kDigits[(index >> shift) & 0xF];
  s += ':';
  s += std::to_string(subindex);
  return s;
}

}  // namespace

Object& ObjectDictionary::insert(Object object) {
  std::stable_sort(object.entries.begin(), object.entries.end(),
                   [](const Entry& a, const Entry& b) { return a.subindex < b.subindex; });
  for (auto& e : object.entries) normalise(e);
  const std::uint16_t index = object.index;
  auto [it, inserted] = objects_.insert_or_assign(index, std::move(object));
  (void)inserted;
  return it->second;
}

bool ObjectDictionary::erase(std::uint16_t index) {
  return objects_.erase(index) > 0;
}

Object* ObjectDictionary::find(std::uint16_t index) {
  auto it = objects_.find(index);
  return it == objects_.end() ? nullptr : &it->second;
}

const Object* ObjectDictionary::find(std::uint16_t index) const {
  auto it = objects_.find(index);
  return it == objects_.end() ? nullptr : &it->second;
}

Entry* ObjectDictionary::findEntry(std::uint16_t index, std::uint8_t subindex) {
  Object* o = find(index);
  return o == nullptr ? nullptr : o->entry(subindex);
}

const Entry* ObjectDictionary::findEntry(std::uint16_t index, std::uint8_t subindex) const {
  const Object* o = find(index);
  return o == nullptr ? nullptr : o->entry(subindex);
}

ConstBytes ObjectDictionary::bytes(std::uint16_t index, std::uint8_t subindex) const {
  const Entry* e = findEntry(index, subindex);
  return e == nullptr ? ConstBytes{} : ConstBytes(e->value);
}

Status ObjectDictionary::setBytes(std::uint16_t index, std::uint8_t subindex, ConstBytes data) {
  Entry* e = findEntry(index, subindex);
  if (e == nullptr) {
    return makeError(ErrorCode::kNotFound,
                     "object dictionary has no entry " + where(index, subindex));
  }
  const std::size_t n = std::min(data.size(), e->value.size());
  std::copy_n(data.begin(), n, e->value.begin());
  std::fill(e->value.begin() + static_cast<std::ptrdiff_t>(n), e->value.end(), 0);
  return okStatus();
}

void ObjectDictionary::resetToDefaults() {
  for (auto& [index, object] : objects_) {
    for (auto& e : object.entries)
      std::copy(e.defaultValue.begin(), e.defaultValue.end(), e.value.begin());
  }
}

void ObjectDictionary::capturePowerUpValues() {
  powerUp_.clear();
  for (const auto& [index, object] : objects_) {
    for (const auto& e : object.entries) {
      powerUp_[(static_cast<std::uint32_t>(index) << 8) | e.subindex] = e.value;
    }
  }
}

void ObjectDictionary::storePowerUpValues(std::uint16_t first, std::uint16_t last) {
  if (!hasPowerUpValues()) capturePowerUpValues();
  for (auto it = objects_.lower_bound(first); it != objects_.end() && it->first <= last; ++it) {
    for (const auto& e : it->second.entries) {
      if (e.writableSomewhere()) {
        powerUp_[(static_cast<std::uint32_t>(it->first) << 8) | e.subindex] = e.value;
      }
    }
  }
}

void ObjectDictionary::defaultPowerUpValues(std::uint16_t first, std::uint16_t last) {
  if (!hasPowerUpValues()) capturePowerUpValues();
  for (auto it = objects_.lower_bound(first); it != objects_.end() && it->first <= last; ++it) {
    for (const auto& e : it->second.entries) {
      if (e.writableSomewhere()) {
        powerUp_[(static_cast<std::uint32_t>(it->first) << 8) | e.subindex] = e.defaultValue;
      }
    }
  }
}

void ObjectDictionary::restorePowerUpValues() {
  for (auto& [index, object] : objects_) {
    for (auto& e : object.entries) {
      auto it = powerUp_.find((static_cast<std::uint32_t>(index) << 8) | e.subindex);
      const std::vector<std::uint8_t>& image = it != powerUp_.end() ? it->second : e.defaultValue;
      // Sizes never change after insert(); copy what fits, zero the rest.
      const std::size_t n = std::min(image.size(), e.value.size());
      std::copy_n(image.begin(), n, e.value.begin());
      std::fill(e.value.begin() + static_cast<std::ptrdiff_t>(n), e.value.end(), 0);
    }
  }
}

Object& ObjectDictionary::addVar(std::uint16_t index, std::string name, std::uint16_t dataType,
                                 std::uint16_t bitLength, std::uint16_t accessBits) {
  Object o;
  o.index = index;
  o.code = ObjectCode::kVar;
  o.dataType = dataType;
  o.name = name;
  Entry e;
  e.subindex = 0;
  e.dataType = dataType;
  e.bitLength = bitLength;
  e.name = std::move(name);
  e.access = accessBits;
  o.entries.push_back(std::move(e));
  return insert(std::move(o));
}

Object& ObjectDictionary::addString(std::uint16_t index, std::string name, std::string_view text,
                                    std::uint16_t accessBits) {
  constexpr std::size_t kLongestText = std::numeric_limits<std::uint16_t>::max() / 8;
  text = text.substr(0, std::min(text.size(), kLongestText));
  Object& o = addVar(index, std::move(name), data_type::kVisibleString,
                     static_cast<std::uint16_t>(8 * text.size()), accessBits);
  Entry& e = o.entries.front();
  std::copy(text.begin(), text.end(), e.value.begin());
  e.defaultValue = e.value;
  return o;
}

Object& ObjectDictionary::addArray(std::uint16_t index, std::string name, std::uint16_t elementType,
                                   std::uint16_t elementBits, std::uint8_t count,
                                   std::uint16_t elementAccess, std::uint16_t sub0Access) {
  Object o;
  o.index = index;
  o.code = ObjectCode::kArray;
  o.dataType = elementType;
  o.name = std::move(name);
  Entry sub0;
  sub0.dataType = data_type::kUnsigned8;
  sub0.bitLength = 8;
  sub0.name = "Number of entries";
  sub0.access = sub0Access;
  sub0.value = {count};
  sub0.defaultValue = {count};
  o.entries.push_back(std::move(sub0));
  for (unsigned i = 1; i <= count; ++i) {
    Entry e;
    e.subindex = static_cast<std::uint8_t>(i);
    e.dataType = elementType;
    e.bitLength = elementBits;
    e.name = "SubIndex " + std::string(i < 100 ? (i < 10 ? "00" : "0") : "") + std::to_string(i);
    e.access = elementAccess;
    o.entries.push_back(std::move(e));
  }
  return insert(std::move(o));
}

Object& ObjectDictionary::addRecord(std::uint16_t index, std::string name, std::uint16_t recordType,
                                    std::uint16_t sub0Access) {
  Object o;
  o.index = index;
  o.code = ObjectCode::kRecord;
  o.dataType = recordType;
  o.name = std::move(name);
  Entry sub0;
  sub0.dataType = data_type::kUnsigned8;
  sub0.bitLength = 8;
  sub0.name = "Number of entries";
  sub0.access = sub0Access;
  o.entries.push_back(std::move(sub0));
  return insert(std::move(o));
}

Entry& ObjectDictionary::addEntry(std::uint16_t index, Entry entry) {
  Object* o = find(index);
  if (o == nullptr) o = &addRecord(index, "Object " + where(index, 0), data_type::kRecord);
  normalise(entry);
  const std::uint8_t sub = entry.subindex;
  if (Entry* existing = o->entry(sub); existing != nullptr) {
    *existing = std::move(entry);
  } else {
    auto pos = std::find_if(o->entries.begin(), o->entries.end(),
                            [sub](const Entry& e) { return e.subindex > sub; });
    o->entries.insert(pos, std::move(entry));
  }
  if (o->code != ObjectCode::kVar) {
    if (Entry* sub0 = o->entry(0); sub0 != nullptr && sub0->value.size() == 1) {
      sub0->value[0] = o->maxSubindex();
      sub0->defaultValue[0] = sub0->value[0];
    }
  }
  return *o->entry(sub);
}

const PdoRules* ObjectDictionary::findPdoRules(std::uint16_t pdoIndex) const {
  auto it = pdoRules_.find(pdoIndex);
  return it == pdoRules_.end() ? nullptr : &it->second;
}

}  // namespace ecsim::slavesim::coe
