#include "slavesim/coe/od_from_esi.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <optional>
#include <set>

#include "config/sii_builder.hpp"
#include "slavesim/coe/od_esi_detail.hpp"
#include "slavesim/coe/standard_objects.hpp"

namespace ecsim::slavesim::coe {
namespace {

using esi_detail::clampBits;
using esi_detail::pdoBits;
using esi_detail::typeForBits;
using esi_detail::upperAscii;

std::string hex4(std::uint32_t v) {
  constexpr char kDigits[] = "0123456789ABCDEF";
  std::string s = "0x";
  for (int shift = 12; shift >= 0; shift -= 4) s += kDigits[(v >> shift) & 0xF];
  return s;
}

// A number (or text for strings) in the entry's wire format.
std::optional<std::vector<std::uint8_t>> numberBytes(std::string_view text, std::uint16_t type,
                                                     std::size_t size) {
  std::vector<std::uint8_t> out(size, 0);
  if (isStringType(type)) {
    std::copy_n(text.begin(), std::min(text.size(), size), out.begin());
    return out;
  }
  if (isRealType(type)) {
    const std::string s(trimEsiText(text));
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (s.empty() || end == s.c_str()) return std::nullopt;
    if (size == 4) writeLe32(out, 0, std::bit_cast<std::uint32_t>(static_cast<float>(v)));
    if (size == 8) writeLe64(out, 0, std::bit_cast<std::uint64_t>(v));
    return out;
  }
  auto v = parseEsiInteger(text);
  if (!v.ok()) return std::nullopt;
  writeRawValue(out, static_cast<std::uint64_t>(*v), 0);
  return out;
}

bool applyValueInfo(Entry& e, const EsiValueInfo& info) {
  const std::size_t size = e.byteSize();
  std::optional<std::vector<std::uint8_t>> value;
  if (!info.defaultData.empty()) {
    value = info.defaultData;
    value->resize(size, 0);
  } else if (info.defaultValue) {
    value = numberBytes(*info.defaultValue, e.dataType, size);
  } else if (info.defaultString) {
    value = numberBytes(*info.defaultString, data_type::kVisibleString, size);
  }
  if (value) {
    e.value = *value;
    e.defaultValue = *value;
  }
  if (!isStringType(e.dataType)) {
    if (info.minValue) {
      if (auto m = numberBytes(*info.minValue, e.dataType, size)) e.minimum = *m;
    }
    if (info.maxValue) {
      if (auto m = numberBytes(*info.maxValue, e.dataType, size)) e.maximum = *m;
    }
  }
  return value.has_value();
}

struct Slot {
  Entry entry;
  const EsiFlags* typeFlags{nullptr};
  bool fromArray{false};
};

Slot makeSlot(std::uint8_t sub, const ResolvedType& t, std::uint32_t bits, std::string name,
              const EsiFlags* flags, bool fromArray) {
  Slot s;
  s.entry.subindex = sub;
  s.entry.dataType = t.dataType;
  s.entry.bitLength = bits != 0 ? clampBits(bits) : t.bitLength;
  s.entry.name = std::move(name);
  s.typeFlags = flags;
  s.fromArray = fromArray;
  return s;
}

std::uint16_t recordTypeFor(std::uint16_t index) {
  if (index == kIdentityIndex) return data_type::kIdentity;
  if (isPdoMappingIndex(index)) return data_type::kPdoMapping;
  if (index == kSmOutputParameterIndex || index == kSmInputParameterIndex) {
    return data_type::kSyncManagerParameter;
  }
  return data_type::kRecord;
}

std::string paddedSubName(unsigned sub) {
  std::string digits = std::to_string(sub);
  return "SubIndex " + std::string(3 - std::min<std::size_t>(3, digits.size()), '0') + digits;
}

Object buildObject(const EsiObject& o, const EsiDictionary& dict) {
  Object object;
  object.index = static_cast<std::uint16_t>(o.index);
  object.name = o.name();
  std::vector<Slot> slots;
  const EsiDataType* dt = dict.findDataType(trimEsiText(o.type));
  bool expanded = false;
  std::uint16_t elementType = 0;
  auto expandArray = [&](const EsiDataType& array, std::uint32_t totalBits, std::uint32_t firstSub,
                         const std::string& name, const EsiFlags* flags) {
    const std::uint32_t n = array.arrays.front().elements;
    ResolvedType t = resolveEsiType(dict, array.baseType, 0);
    if (t.bitLength == 0 && n != 0) t.bitLength = clampBits(totalBits / n);
    for (std::uint32_t i = 0; i < n && firstSub + i <= 255; ++i) {
      slots.push_back(
          makeSlot(static_cast<std::uint8_t>(firstSub + i), t, t.bitLength, name, flags, true));
    }
    expanded = true;
    elementType = t.dataType;
  };
  if (dt != nullptr && dt->isRecord()) {
    for (std::size_t p = 0; p < dt->subItems.size(); ++p) {
      const EsiSubItemType& sit = dt->subItems[p];
      const EsiDataType* sdt = dict.findDataType(trimEsiText(sit.type));
      if (sdt != nullptr && sdt->isArray() && !sdt->isRecord() && p > 0 && sit.subIndex == 0) {
        // "Elements" without SubIdx: one subindex per element.
        const std::int64_t lbound = sdt->arrays.front().lowerBound;
        expandArray(*sdt, sit.bitSize, lbound >= 1 ? static_cast<std::uint32_t>(lbound) : 1,
                    sit.name, &sit.flags);
      } else {
        slots.push_back(makeSlot(sit.subIndex, resolveEsiType(dict, sit.type, sit.bitSize),
                                 sit.bitSize, sit.name, &sit.flags, false));
      }
    }
    object.code =
        expanded && !isPdoMappingIndex(object.index) ? ObjectCode::kArray : ObjectCode::kRecord;
    object.dataType = object.code == ObjectCode::kArray ? elementType : recordTypeFor(object.index);
  } else if (dt != nullptr && dt->isArray() && upperAscii(dt->baseType) != "BYTE" &&
             upperAscii(dt->baseType) != "USINT") {
    slots.push_back(
        makeSlot(0, {data_type::kUnsigned8, 8}, 8, "Number of entries", nullptr, false));
    expandArray(*dt, dt->bitSize, 1, object.name, nullptr);
    object.code = ObjectCode::kArray;
    object.dataType = elementType;
  } else {
    ResolvedType t = resolveEsiType(dict, o.type, o.bitSize);
    slots.push_back(makeSlot(0, t, o.bitSize, object.name, nullptr, false));
    object.code = ObjectCode::kVar;
    object.dataType = t.dataType;
  }
  // Info/SubItem: by name, else by position.
  const bool pdoObject = isPdoMappingIndex(object.index) || isPdoAssignIndex(object.index);
  bool countLater = false;
  std::vector<bool> used(slots.size(), false);
  std::vector<const EsiSubItemInfo*> info(slots.size(), nullptr);
  for (std::size_t k = 0; k < o.subItems.size(); ++k) {
    const EsiSubItemInfo& si = o.subItems[k];
    std::size_t pick = slots.size();
    for (std::size_t j = 0; j < slots.size(); ++j) {
      if (!used[j] && !slots[j].fromArray && slots[j].entry.name == si.name) {
        pick = j;
        break;
      }
    }
    if (pick == slots.size() && k < slots.size() && !used[k]) pick = k;
    if (pick == slots.size()) continue;
    used[pick] = true;
    info[pick] = &si;
  }
  for (std::size_t j = 0; j < slots.size(); ++j) {
    Slot& s = slots[j];
    Entry& e = s.entry;
    const EsiSubItemInfo* si = info[j];
    if (s.fromArray)
      e.name = si != nullptr && !si->name.empty() ? si->name : paddedSubName(e.subindex);
    // Flags: Info/SubItem overrides the DataType's SubItem, which overrides the object's.
    const EsiFlags* chosen = nullptr;
    for (const EsiFlags* f :
         {si != nullptr && si->flags ? &*si->flags : nullptr, s.typeFlags, &o.flags}) {
      if (f != nullptr && f->access != EsiAccess::kUnspecified) {
        chosen = f;
        break;
      }
    }
    e.access = chosen != nullptr ? accessFromEsiFlags(*chosen) : access::kReadOnly;
    for (const EsiFlags* f :
         {si != nullptr && si->flags ? &*si->flags : nullptr, s.typeFlags, &o.flags}) {
      if (f != nullptr && !f->pdoMapping.empty()) {
        e.access = static_cast<std::uint16_t>(
            (e.access & ~(access::kRxMappable | access::kTxMappable)) | pdoBits(*f));
        break;
      }
    }
    e.value.assign(e.byteSize(), 0);
    e.defaultValue = e.value;
    const bool given = applyValueInfo(
        e, object.code == ObjectCode::kVar ? o.info : (si != nullptr ? si->info : EsiValueInfo{}));
    if (!given && object.code != ObjectCode::kVar && e.subindex == 0 && e.value.size() == 1) {
      // No default given: sub 0 tells the highest subindex, or for PDO assignment and mapping
      // objects (filled below) how many entries are in use.
      std::uint8_t highest = 0;
      for (const Slot& other : slots) highest = std::max(highest, other.entry.subindex);
      e.value[0] = pdoObject ? 0 : highest;
      e.defaultValue = e.value;
      countLater = pdoObject;
    }
    object.entries.push_back(std::move(e));
  }
  if (countLater) {  // sub 0 = the leading entries with a value
    std::uint8_t n = 0;
    for (const Entry& e : object.entries) {
      if (e.subindex == 0) continue;
      if (e.subindex != n + 1 || readRawValue(e.value, e.bitLength) == 0) break;
      ++n;
    }
    object.entries.front().value[0] = n;
    object.entries.front().defaultValue = object.entries.front().value;
  }
  return object;
}

std::uint8_t smTypeOf(const EsiSyncManager& sm) {
  const std::string text = upperAscii(sm.text);
  if (text == "MBOXOUT") return kSmTypeMailboxOut;
  if (text == "MBOXIN") return kSmTypeMailboxIn;
  if (text == "OUTPUTS") return kSmTypeOutputs;
  if (text == "INPUTS") return kSmTypeInputs;
  if (sm.controlByte == 0) return kSmTypeUnused;
  const bool mailbox = (sm.controlByte & 0x03) == 0x02;
  const bool masterWrites = (sm.controlByte & 0x0C) == 0x04;
  if (mailbox) return masterWrites ? kSmTypeMailboxOut : kSmTypeMailboxIn;
  return masterWrites ? kSmTypeOutputs : kSmTypeInputs;
}

void limitWritesToPreOp(Object& o, bool readOnly) {
  for (auto& e : o.entries) {
    const auto keep = static_cast<std::uint16_t>(readOnly ? ~access::kWriteAll
                                                          : ~(kAccessWriteSafeOp | kAccessWriteOp));
    e.access = static_cast<std::uint16_t>(e.access & keep);
  }
}

// Entries of an ESI PDO as mapping values.
std::vector<MappedObject> mappingOf(const EsiPdo& pdo) {
  std::vector<MappedObject> out;
  for (const auto& e : pdo.entries) {
    out.push_back({e.index, e.subIndex,
                   static_cast<std::uint8_t>(std::min<std::uint16_t>(e.bitLength, 255))});
  }
  return out;
}

std::uint32_t key(const EsiPdoEntry& e) {
  return (static_cast<std::uint32_t>(e.index) << 8) | e.subIndex;
}

// Entries this builder creates for PDO entries the dictionary lacks (keys of key()).
void addMappedObjects(ObjectDictionary& od, const EsiPdo& pdo, bool rx,
                      std::set<std::uint32_t>& created) {
  const std::uint16_t mappable = rx ? access::kRxMappable : access::kTxMappable;
  for (const auto& pe : pdo.entries) {
    if (pe.index == 0) continue;
    if (Entry* e = od.findEntry(pe.index, pe.subIndex); e != nullptr) {
      e->access |= mappable;
      if (created.count(key(pe)) != 0 && e->bitLength < pe.bitLength) {
        // Alternative PDOs map the same object with 32 or 64 bits (EL1252 NextLatchTime):
        // the object we made up takes the longest.
        e->bitLength = pe.bitLength;
        e->value.resize(e->byteSize(), 0);
        e->defaultValue.resize(e->byteSize(), 0);
        if (e->dataType == data_type::kUnsigned32 && e->bitLength == 64) {
          e->dataType = data_type::kUnsigned64;
        }
      }
      continue;
    }
    created.insert(key(pe));
    std::uint16_t type = coeDataTypeCode(pe.dataType);
    if (type == 0 || (type == data_type::kBoolean && pe.bitLength > 1))
      type = typeForBits(pe.bitLength);
    const std::uint16_t rights =
        static_cast<std::uint16_t>((rx ? access::kReadWrite : access::kReadOnly) | mappable);
    if (pe.subIndex == 0 && od.find(pe.index) == nullptr) {
      od.addVar(pe.index, pe.name.empty() ? pdo.name() : pe.name, type, pe.bitLength, rights);
      continue;
    }
    if (od.find(pe.index) == nullptr) {
      od.addRecord(pe.index, pdo.name().empty() ? pe.name : pdo.name(), data_type::kRecord);
    }
    Entry e;
    e.subindex = pe.subIndex;
    e.dataType = type;
    e.bitLength = pe.bitLength;
    e.name = pe.name;
    e.access = rights;
    od.addEntry(pe.index, std::move(e));
  }
}

// The first of a PDO's entries that an object of the dictionary cannot take (the object
// exists, was not made up here, and holds fewer or more bits than the entry maps), as text.
std::optional<std::string> conflictingEntry(const ObjectDictionary& od, const EsiPdo& pdo,
                                            const std::set<std::uint32_t>& created) {
  for (const auto& pe : pdo.entries) {
    if (pe.index == 0 || created.count(key(pe)) != 0) continue;
    const Entry* e = od.findEntry(pe.index, pe.subIndex);
    if (e != nullptr && e->bitLength != pe.bitLength) {
      return hex4(pe.index) + ":" + std::to_string(pe.subIndex) + " (" +
             std::to_string(pe.bitLength) + " bits mapped, the object has " +
             std::to_string(e->bitLength) + ")";
    }
  }
  return std::nullopt;
}

// A mapping object's entries as an ESI PDO (no names or types: those come from the bits), so
// that addMappedObjects makes up what the dictionary lacks for it.
EsiPdo pdoOfMapping(const ObjectDictionary& od, const Object& mapping) {
  EsiPdo pdo;
  pdo.index = mapping.index;
  for (const MappedObject& m : mappedObjects(od, mapping.index)) {
    EsiPdoEntry e;
    e.index = m.index;
    e.subIndex = m.subindex;
    e.bitLength = m.bitLength;
    e.name = mapping.name;
    pdo.entries.push_back(std::move(e));
  }
  return pdo;
}

std::string hexList(const std::vector<std::uint16_t>& values) {
  std::string out;
  for (auto v : values) out += (out.empty() ? "" : ", ") + hex4(v);
  return out;
}

// Writes `values` (`bytes` wide) into subindexes 1.. of a list object (PDO assignment, PDO
// mapping, module list) and their count into sub 0, as defaults; a list with less room keeps
// what fits, noted.
template <typename Note>
void fillList(Object& list, const std::vector<std::uint32_t>& values, std::size_t bytes,
              Note& note) {
  std::size_t n = 0;
  for (; n < values.size() && n < 255; ++n) {
    Entry* e = list.entry(static_cast<std::uint8_t>(n + 1));
    if (e == nullptr || e->value.size() < bytes) break;
    writeRawValue(e->value, values[n], 0);
    e->defaultValue = e->value;
  }
  if (n < values.size()) {
    note(hex4(list.index) + " has room for " + std::to_string(n) + " of " +
         std::to_string(values.size()) + " entries");
  }
  if (Entry* sub0 = list.entry(0); sub0 != nullptr && !sub0->value.empty()) {
    sub0->value[0] = static_cast<std::uint8_t>(n);
    sub0->defaultValue = sub0->value;
  }
}

// Modular device profile (ETG.5001): 0xF030 Configured Module List (what the master downloads
// with DownloadModuleIdentList) and 0xF050 Detected Module List hold the module idents in slot
// order, sub 0 the number of modules; both agree, as on a station built as configured.
constexpr std::uint16_t kConfiguredModuleListIndex = 0xF030;
constexpr std::uint16_t kDetectedModuleListIndex = 0xF050;

template <typename Note>
void setModuleLists(ObjectDictionary& od, const std::vector<std::uint32_t>& idents, Note& note) {
  const auto count = static_cast<std::uint8_t>(std::min<std::size_t>(idents.size(), 255));
  for (const std::uint16_t index : {kConfiguredModuleListIndex, kDetectedModuleListIndex}) {
    if (!od.contains(index)) {
      od.addArray(
          index,
          index == kConfiguredModuleListIndex ? "Configured Module List" : "Detected Module List",
          data_type::kUnsigned32, 32, count,
          index == kConfiguredModuleListIndex ? access::kReadWrite : access::kReadOnly);
    }
    fillList(*od.find(index), idents, 4, note);
  }
}

}  // namespace

ObjectDictionary buildObjectDictionary(const EsiDevice& device, const OdBuildOptions& options,
                                       OdBuildReport* report) {
  auto note = [&](std::string text) {
    if (report != nullptr) report->notes.push_back(std::move(text));
  };
  ObjectDictionary od;
  for (const EsiObject& o : device.dictionary.objects) {
    if (o.index > 0xFFFF) {
      note("object index " + std::to_string(o.index) + " is not a CoE index: skipped");
      continue;
    }
    od.insert(buildObject(o, device.dictionary));
  }

  // Communication area.
  if (!od.contains(kDeviceTypeIndex)) {
    od.addVar(kDeviceTypeIndex, "Device type", data_type::kUnsigned32, 32, access::kReadOnly);
    (void)od.set<std::uint32_t>(kDeviceTypeIndex, 0, device.profileNo.value_or(0));
    od.findEntry(kDeviceTypeIndex, 0)->defaultValue = od.findEntry(kDeviceTypeIndex, 0)->value;
  }
  if (!od.contains(kDeviceNameIndex)) od.addString(kDeviceNameIndex, "Device name", device.name());
  if (!od.contains(kHardwareVersionIndex)) {
    od.addString(kHardwareVersionIndex, "Hardware version", std::to_string(device.revision >> 16));
  }
  if (!od.contains(kSoftwareVersionIndex)) {
    od.addString(kSoftwareVersionIndex, "Software version",
                 std::to_string(device.revision & 0xFFFF));
  }
  addIdentityObject(od, {options.vendorId, device.productCode, device.revision, options.serial});

  {
    std::vector<std::uint8_t> types;
    for (const auto& sm : device.syncManagers) types.push_back(smTypeOf(sm));
    // The PDOs assigned to a process-data SM say its direction when its text is wrong (the
    // SMC EX250 calls its input SM "Outputs"), as SOEM decides from the SII PDOs.
    for (std::size_t n = 0; n < types.size(); ++n) {
      if (types[n] != kSmTypeOutputs && types[n] != kSmTypeInputs) continue;
      auto assignedTo = [n](const std::vector<EsiPdo>& pdos) {
        return std::any_of(pdos.begin(), pdos.end(),
                           [n](const EsiPdo& p) { return p.sm && *p.sm == n; });
      };
      const bool rx = assignedTo(device.rxPdos);
      const bool tx = assignedTo(device.txPdos);
      if (rx != tx) types[n] = rx ? kSmTypeOutputs : kSmTypeInputs;
    }
    auto nonzero = [](const Entry& e) {
      return e.subindex > 0 &&
             std::any_of(e.value.begin(), e.value.end(), [](std::uint8_t b) { return b != 0; });
    };
    if (Object* existing = od.find(kSmTypesIndex); existing == nullptr) {
      addSyncManagerTypes(od, types);
    } else if (std::none_of(existing->entries.begin(), existing->entries.end(), nonzero)) {
      // The dictionary has 0x1C00 but no value for any SM (Copley's XE2 ESI: <Info/> only): a
      // device reports its SMs' types there (ETG.1000.6 0x1C00), so they come from its <Sm>.
      note("0x1C00 gives no SM types: taken from the device's <Sm> elements");
      fillList(*existing, {types.begin(), types.end()}, 1, note);
    }
  }

  // PDO mapping objects and their rules.
  std::set<std::uint32_t> created;
  const bool pdoConfig = device.mailbox.coeDetails.pdoConfig;
  for (int dir = 0; dir < 2; ++dir) {
    const bool rx = dir == 0;
    for (const EsiPdo& pdo : rx ? device.rxPdos : device.txPdos) {
      if (!pdo.inCoeRange()) {
        // EL1262 has a TxPdo 0x1C00, which would overwrite the SM types: such a PDO is left
        // out here and of the SII PDO categories (EsiPdo::inCoeRange).
        note("PDO " + hex4(pdo.index) + " is outside 0x1600-0x1BFF: left out");
        continue;
      }
      PdoRules& rules = od.pdoRules(pdo.index);
      rules.fixed = pdo.fixed;
      rules.mandatory = pdo.mandatory;
      rules.defaultSm = pdo.sm;
      rules.excludes = pdo.excludes;
      std::vector<MappedObject> entries = mappingOf(pdo);
      if (Object* existing = od.find(pdo.index); existing != nullptr) {
        limitWritesToPreOp(*existing, pdo.fixed);
        const std::vector<MappedObject> esiMapping = mappedObjects(od, pdo.index);
        if (auto conflict = conflictingEntry(od, pdo, created); conflict && !esiMapping.empty()) {
          // Beckhoff_EL3xxx.xml, EL3632: TxPdo 0x1A41 "Ch2 Sample" names 16 bits of 0x6000:02
          // (Ch1's 1-bit status), the dictionary's 0x1A41 maps 0x6012:01. A PDO that cannot
          // be bound is no description of the device: the dictionary's mapping stays.
          note(hex4(pdo.index) + ": the PDO's entries (line " + std::to_string(pdo.line) +
               ") cannot be mapped: " + *conflict + "; the dictionary's default mapping is kept");
          if (report != nullptr) report->keptMappings.push_back(pdo.index);
          continue;
        }
        addMappedObjects(od, pdo, rx, created);
        const bool same =
            std::equal(esiMapping.begin(), esiMapping.end(), entries.begin(), entries.end(),
                       [](const auto& a, const auto& b) { return a.raw() == b.raw(); });
        if (!entries.empty() && !same) {
          // As for the assignment: the PDO's own entries win over the dictionary's default.
          if (!esiMapping.empty()) {
            note(hex4(pdo.index) +
                 ": the dictionary's default mapping differs from the PDO's "
                 "entries (line " +
                 std::to_string(pdo.line) + "); the PDO's entries are used");
          }
          std::vector<std::uint32_t> raw;
          for (const auto& m : entries) raw.push_back(m.raw());
          fillList(*existing, raw, 4, note);
        }
        continue;
      }
      addMappedObjects(od, pdo, rx, created);
      PdoMappingSpec spec;
      spec.index = pdo.index;
      spec.name = pdo.name();
      spec.entries = std::move(entries);
      for (const auto& e : pdo.entries) spec.entryNames.push_back(e.name);
      spec.fixed = pdo.fixed;
      spec.capacity = pdoConfig && !pdo.fixed ? options.configurableMappingCapacity : 0;
      addPdoMapping(od, spec);
    }
  }

  // Mapping objects of the dictionary that no PDO of the device describes (the oversampling
  // PDOs 0x1A02..0x1A32 of an EL3632 with OSFac up to 50) may map objects the dictionary lacks:
  // made up from the mapping, so that a master that assigns them gets what it mapped.
  std::size_t madeUp = created.size();
  std::vector<const Object*> mappings;
  for (const auto& [index, object] : od.objects()) {
    if (isPdoMappingIndex(index)) mappings.push_back(&object);
  }
  for (const Object* mapping : mappings) {
    addMappedObjects(od, pdoOfMapping(od, *mapping), isRxPdoMappingIndex(mapping->index), created);
  }
  if (created.size() > madeUp) {
    note(std::to_string(created.size() - madeUp) +
         " entries mapped by the dictionary's PDO mapping objects are not in the dictionary: "
         "made up from the mappings");
  }

  // PDO assignment per process-data SM.
  const Object* types = od.find(kSmTypesIndex);
  for (const Entry& t : types->entries) {
    if (t.subindex == 0 || t.value.empty()) continue;
    const unsigned sm = t.subindex - 1u;
    const bool outputs = t.value[0] == kSmTypeOutputs;
    if (!outputs && t.value[0] != kSmTypeInputs) continue;
    std::vector<std::uint16_t> assigned;
    std::size_t candidates = 0;
    for (const EsiPdo& pdo : outputs ? device.rxPdos : device.txPdos) {
      if (!pdo.inCoeRange()) continue;
      if (pdo.sm && *pdo.sm == sm) assigned.push_back(pdo.index);
      if (!pdo.sm || *pdo.sm == sm) ++candidates;
    }
    const auto index = static_cast<std::uint16_t>(kPdoAssignBase + sm);
    if (Object* existing = od.find(index); existing != nullptr) {
      limitWritesToPreOp(*existing, false);
      const std::vector<std::uint16_t> esiValues = assignedPdos(od, sm);
      if (!assigned.empty() && esiValues != assigned) {
        // The device's own PDO description (the PDOs with Sm=n) wins over the dictionary's
        // default, as the SII PDO categories built from the same description say: shared
        // Beckhoff dictionaries name PDOs a terminal does not have (Beckhoff_AX2xxx.xml:
        // 0x1C12 default 0x1701, RxPdo Sm="2" 0x1702).
        if (!esiValues.empty()) {
          note(hex4(index) + ": the dictionary's default assignment (" + hexList(esiValues) +
               ") differs from the device's PDOs with Sm=" + std::to_string(sm) + " (" +
               hexList(assigned) + "); the device's PDOs are used");
        }
        fillList(*existing, {assigned.begin(), assigned.end()}, 2, note);
      }
      continue;
    }
    const bool writable = device.mailbox.coeDetails.pdoAssign || candidates > assigned.size();
    addPdoAssignment(
        od, sm, assigned,
        static_cast<std::uint8_t>(std::min<std::size_t>(std::max<std::size_t>(candidates, 1), 254)),
        writable);
  }

  bool dc = false;
  for (const auto& mode : device.dcOpModes) dc = dc || (mode.assignActivate & 0x0300) != 0;
  SyncParameters sync;
  if (dc) sync.supported |= kSupportsDcSync0;
  if (!od.contains(kSmOutputParameterIndex))
    addSyncManagerParameters(od, kSmOutputParameterIndex, sync);
  if (!od.contains(kSmInputParameterIndex))
    addSyncManagerParameters(od, kSmInputParameterIndex, sync);
  if (!device.moduleIdents.empty()) setModuleLists(od, device.moduleIdents, note);
  return od;
}

}  // namespace ecsim::slavesim::coe
