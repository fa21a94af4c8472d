#include "slavesim/coe/standard_objects.hpp"

#include <algorithm>

namespace ecsim::slavesim::coe {
namespace {

Entry makeEntry(std::uint8_t sub, std::string name, std::uint16_t type, std::uint16_t bits,
                std::uint16_t accessBits, std::uint64_t value = 0) {
  Entry e;
  e.subindex = sub;
  e.name = std::move(name);
  e.dataType = type;
  e.bitLength = bits;
  e.access = accessBits;
  e.value.resize(e.byteSize(), 0);
  writeRawValue(e.value, value, bits);
  e.defaultValue = e.value;
  return e;
}

std::string subName(unsigned i) {
  std::string digits = std::to_string(i);
  return "SubIndex " + std::string(3 - std::min<std::size_t>(3, digits.size()), '0') + digits;
}

}  // namespace

void addIdentityObject(ObjectDictionary& od, const IdentityValues& id) {
  const std::uint32_t values[4] = {id.vendorId, id.productCode, id.revision, id.serial};
  static constexpr const char* kNames[4] = {"Vendor ID", "Product code", "Revision",
                                            "Serial number"};
  if (od.find(kIdentityIndex) == nullptr) {
    od.addRecord(kIdentityIndex, "Identity", data_type::kIdentity);
    for (std::uint8_t sub = 1; sub <= 4; ++sub) {
      od.addEntry(kIdentityIndex, makeEntry(sub, kNames[sub - 1], data_type::kUnsigned32, 32,
                                            access::kReadOnly, values[sub - 1]));
    }
    return;
  }
  // An ESI definition: keep its names and rights, put in the identity the SII carries.
  for (std::uint8_t sub = 1; sub <= 4; ++sub) {
    if (Entry* e = od.findEntry(kIdentityIndex, sub); e != nullptr) {
      writeRawValue(e->value, values[sub - 1], e->bitLength);
      e->defaultValue = e->value;
    }
  }
}

void addSyncManagerTypes(ObjectDictionary& od, std::span<const std::uint8_t> types) {
  const auto count = static_cast<std::uint8_t>(std::min<std::size_t>(types.size(), 32));
  od.addArray(kSmTypesIndex, "Sync manager type", data_type::kUnsigned8, 8, count,
              access::kReadOnly);
  Object* o = od.find(kSmTypesIndex);
  for (std::uint8_t i = 0; i < count; ++i) {
    Entry* e = o->entry(static_cast<std::uint8_t>(i + 1));
    e->name = "Communication type SM" + std::to_string(i);
    e->value[0] = types[i];
    e->defaultValue = e->value;
  }
}

void addPdoMapping(ObjectDictionary& od, const PdoMappingSpec& spec) {
  const auto count = static_cast<std::uint8_t>(std::min<std::size_t>(spec.entries.size(), 254));
  const std::uint8_t capacity = spec.fixed ? count : std::max(count, spec.capacity);
  const std::uint16_t rights = spec.fixed ? access::kReadOnly : access::kReadWritePreOp;
  od.addRecord(spec.index, spec.name, data_type::kPdoMapping, rights);
  for (std::uint8_t i = 1; i <= capacity; ++i) {
    const std::uint32_t raw = i <= count ? spec.entries[i - 1u].raw() : 0;
    std::string name = i <= spec.entryNames.size() && !spec.entryNames[i - 1u].empty()
                           ? spec.entryNames[i - 1u]
                           : subName(i);
    od.addEntry(spec.index, makeEntry(i, std::move(name), data_type::kUnsigned32, 32, rights, raw));
  }
  Entry* sub0 = od.findEntry(spec.index, 0);
  sub0->value[0] = count;
  sub0->defaultValue = sub0->value;
}

void addPdoAssignment(ObjectDictionary& od, unsigned sm, std::span<const std::uint16_t> pdos,
                      std::uint8_t capacity, bool writable) {
  const auto index = static_cast<std::uint16_t>(kPdoAssignBase + sm);
  const auto count = static_cast<std::uint8_t>(std::min<std::size_t>(pdos.size(), 254));
  capacity = std::max(capacity, count);
  const std::uint16_t rights = writable ? access::kReadWritePreOp : access::kReadOnly;
  od.addArray(index, "Sync manager " + std::to_string(sm) + " PDO assignment",
              data_type::kUnsigned16, 16, capacity, rights, rights);
  Object* o = od.find(index);
  for (std::uint8_t i = 1; i <= capacity; ++i) {
    Entry* e = o->entry(i);
    writeRawValue(e->value, i <= count ? pdos[i - 1u] : 0, 16);
    e->defaultValue = e->value;
  }
  Entry* sub0 = o->entry(0);
  sub0->value[0] = count;
  sub0->defaultValue = sub0->value;
}

void addSyncManagerParameters(ObjectDictionary& od, std::uint16_t index, const SyncParameters& p) {
  const bool outputs = index == kSmOutputParameterIndex;
  od.addRecord(index, outputs ? "SM output parameter" : "SM input parameter",
               data_type::kSyncManagerParameter);
  struct Sub {
    const char* name;
    std::uint16_t type;
    std::uint16_t bits;
    std::uint16_t rights;
    std::uint64_t value;
  };
  const Sub subs[] = {
      {"Sync mode", data_type::kUnsigned16, 16, access::kReadWritePreOp, p.syncType},
      {"Cycle time", data_type::kUnsigned32, 32, access::kReadWritePreOp, p.cycleTimeNs},
      {"Shift time", data_type::kUnsigned32, 32, access::kReadOnly, 0},
      {"Sync modes supported", data_type::kUnsigned16, 16, access::kReadOnly, p.supported},
      {"Minimum cycle time", data_type::kUnsigned32, 32, access::kReadOnly, p.minimumCycleTimeNs},
      {"Calc and copy time", data_type::kUnsigned32, 32, access::kReadOnly, 0},
      {"Minimum delay time", data_type::kUnsigned32, 32, access::kReadOnly, 0},
      {"Get cycle time", data_type::kUnsigned16, 16, access::kReadWritePreOp, 0},
      {"Delay time", data_type::kUnsigned32, 32, access::kReadOnly, 0},
      {"Sync0 cycle time", data_type::kUnsigned32, 32, access::kReadOnly, 0},
      {"SM event missed", data_type::kUnsigned16, 16, access::kReadOnly, 0},
      {"Cycle time too small", data_type::kUnsigned16, 16, access::kReadOnly, 0},
  };
  std::uint8_t sub = 1;
  for (const Sub& s : subs) {
    od.addEntry(index, makeEntry(sub++, s.name, s.type, s.bits, s.rights, s.value));
  }
}

std::vector<std::uint16_t> assignedPdos(const ObjectDictionary& od, unsigned sm) {
  std::vector<std::uint16_t> out;
  const Object* o = od.find(static_cast<std::uint16_t>(kPdoAssignBase + sm));
  if (o == nullptr) return out;
  const Entry* sub0 = o->entry(0);
  const std::uint8_t count = sub0 == nullptr || sub0->value.empty() ? 0 : sub0->value[0];
  for (std::uint8_t i = 1; i <= count && i != 0; ++i) {
    const Entry* e = o->entry(i);
    if (e == nullptr) break;
    // A zero entry assigns nothing and is skipped, as masters skip it (a dynamic-PDO device
    // with 0x1C12:03 = 0 in its ESI defaults; issue #15 item 11).
    if (const auto pdo = static_cast<std::uint16_t>(readRawValue(e->value, 16)); pdo != 0) {
      out.push_back(pdo);
    }
  }
  return out;
}

std::vector<MappedObject> mappedObjects(const ObjectDictionary& od, std::uint16_t pdoIndex) {
  std::vector<MappedObject> out;
  const Object* o = od.find(pdoIndex);
  if (o == nullptr) return out;
  const Entry* sub0 = o->entry(0);
  const std::uint8_t count = sub0 == nullptr || sub0->value.empty() ? 0 : sub0->value[0];
  for (std::uint8_t i = 1; i <= count && i != 0; ++i) {
    const Entry* e = o->entry(i);
    if (e == nullptr) break;
    out.push_back(MappedObject::fromRaw(static_cast<std::uint32_t>(readRawValue(e->value, 32))));
  }
  return out;
}

}  // namespace ecsim::slavesim::coe
