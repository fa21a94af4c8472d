// Modules in the slots of a modular device (see esi_modules.hpp).
#include "config/esi_modules.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <map>
#include <set>

#include "config/sii_builder.hpp"
#include "protocol/closest_name.hpp"

namespace ecsim {
namespace {

// A module ident as ESI files write it: #x00091F84.
std::string hex8(std::uint32_t v) {
  return fmt::format("#x{:08X}", v);
}

bool isMappingIndex(std::uint32_t index) {
  return index >= 0x1600 && index <= 0x1BFF;
}

// Type names a module's dictionary shares with everyone (BOOL, UINT, STRING(25), BIT4):
// kept as they are; the module's own (DT6000, DT1A00, ...) are renamed per module.
bool isSharedTypeName(std::string_view name) {
  return coeDataTypeCode(name) != 0 || name.starts_with("STRING(") || name.starts_with("BIT");
}

std::string ownTypeName(const std::string& name, const EsiModule& module) {
  return name + "@" + hex8(module.moduleIdent);
}

bool admits(const EsiSlot& slot, const EsiModule& module) {
  return std::find(slot.moduleClasses.begin(), slot.moduleClasses.end(), module.moduleClass) !=
             slot.moduleClasses.end() ||
         std::find(slot.moduleIdents.begin(), slot.moduleIdents.end(), module.moduleIdent) !=
             slot.moduleIdents.end();
}

std::uint32_t capacity(const EsiSlot& slot) {
  return std::max<std::uint32_t>(slot.maxInstances, 1);
}

std::string label(const EsiModule& module) {
  return module.type + " (" + hex8(module.moduleIdent) + ")";
}

// The module's PDOs moved to slot instance k.
EsiPdo movedPdo(EsiPdo pdo, std::uint32_t k, const EsiSlot& slot) {
  if (pdo.dependOnSlot) {
    pdo.index = static_cast<std::uint16_t>(pdo.index + k * slot.pdoIncrement);
    for (auto& x : pdo.excludes) x = static_cast<std::uint16_t>(x + k * slot.pdoIncrement);
  }
  for (auto& e : pdo.entries) {
    if (e.dependOnSlot && e.index != 0) {
      e.index = static_cast<std::uint16_t>(e.index + k * slot.indexIncrement);
    }
  }
  return pdo;
}

}  // namespace

void EsiModuleCatalog::add(const EsiFile& file) {
  for (const auto& d : file.devices) add(d.modules);
  add(file.modules);
}

void EsiModuleCatalog::add(const std::vector<EsiModule>& modules) {
  for (const auto& m : modules) modules_.push_back(&m);
}

const EsiModule* EsiModuleCatalog::findByIdent(std::uint32_t ident) const {
  for (const EsiModule* m : modules_) {
    if (m->moduleIdent == ident) return m;
  }
  return nullptr;
}

const EsiModule* EsiModuleCatalog::findByType(std::string_view type) const {
  for (const EsiModule* m : modules_) {
    if (m->type == type) return m;
  }
  return nullptr;
}

std::vector<std::string_view> EsiModuleCatalog::typeNames() const {
  std::vector<std::string_view> names;
  for (const EsiModule* m : modules_) names.push_back(m->type);
  return names;
}

Result<std::vector<const EsiModule*>> defaultModules(const EsiDevice& device,
                                                     const EsiModuleCatalog& catalog) {
  std::vector<const EsiModule*> out;
  for (const EsiSlot& slot : device.slots) {
    if (!slot.defaultModuleIdent) continue;
    const EsiModule* module = catalog.findByIdent(*slot.defaultModuleIdent);
    if (module == nullptr) {
      return makeError(ErrorCode::kNotFound,
                       "device " + device.type + ": slot '" + slot.name + "' (line " +
                           std::to_string(slot.line) + ") names default module " +
                           hex8(*slot.defaultModuleIdent) + ", which no ESI file given has");
    }
    const std::uint32_t n = std::min(std::max<std::uint32_t>(slot.minInstances, 1), capacity(slot));
    out.insert(out.end(), n, module);
  }
  return out;
}

Result<EsiDevice> instantiateModules(const EsiDevice& device,
                                     const std::vector<const EsiModule*>& modules,
                                     std::vector<std::string>* notes) {
  EsiDevice out = device;
  if (modules.empty()) return out;
  if (device.slots.empty()) {
    return makeError(ErrorCode::kInvalidArgument,
                     "device " + device.type + " has no <Slots>: it takes no modules");
  }
  // Slot instance k -> the slot it is in: slots fill in order, a module goes to the first
  // slot from the current one that takes it and has room.
  std::vector<std::uint32_t> used(device.slots.size(), 0);
  std::size_t current = 0;
  std::set<std::string> knownTypes;
  for (const auto& t : out.dictionary.dataTypes) knownTypes.insert(t.name);
  std::set<std::uint32_t> knownObjects;
  for (const auto& o : out.dictionary.objects) knownObjects.insert(o.index);

  for (std::uint32_t k = 0; k < modules.size(); ++k) {
    const EsiModule& module = *modules[k];
    std::size_t s = current;
    while (s < device.slots.size() &&
           (!admits(device.slots[s], module) || used[s] >= capacity(device.slots[s]))) {
      ++s;
    }
    if (s == device.slots.size()) {
      std::string classes;
      for (const auto& slot : device.slots) {
        for (const auto& c : slot.moduleClasses) classes += (classes.empty() ? "" : ", ") + c;
      }
      return makeError(ErrorCode::kInvalidArgument,
                       "device " + device.type + ": module " + std::to_string(k) + " " +
                           label(module) + " of class '" + module.moduleClass +
                           "' fits no remaining slot (slots take: " + classes + "; " +
                           std::to_string(k) + " module(s) placed before it)");
    }
    current = s;
    ++used[s];
    const EsiSlot& slot = device.slots[s];
    out.moduleIdents.push_back(module.moduleIdent);

    for (const auto& p : module.rxPdos) out.rxPdos.push_back(movedPdo(p, k, slot));
    for (const auto& p : module.txPdos) out.txPdos.push_back(movedPdo(p, k, slot));

    // Data types: shared names once, the module's own under a per-module name.
    auto rename = [&](const std::string& name) {
      for (const auto& t : module.dictionary.dataTypes) {
        if (t.name == name && !isSharedTypeName(name)) return ownTypeName(name, module);
      }
      return name;
    };
    for (EsiDataType t : module.dictionary.dataTypes) {
      t.name = rename(t.name);
      t.baseType = rename(t.baseType);
      for (auto& sub : t.subItems) sub.type = rename(sub.type);
      if (knownTypes.insert(t.name).second) out.dictionary.dataTypes.push_back(std::move(t));
    }
    for (EsiObject o : module.dictionary.objects) {
      if (o.dependOnSlot) {
        o.index += k * (isMappingIndex(o.index) ? slot.pdoIncrement : slot.indexIncrement);
      }
      if (o.index > 0xFFFF) {
        return makeError(ErrorCode::kInvalidArgument,
                         "device " + device.type + ": module " + label(module) + " in slot " +
                             std::to_string(k) + " moves object line " + std::to_string(o.line) +
                             " beyond index 0xFFFF");
      }
      if (isMappingIndex(o.index)) {
        // Mapping defaults name the module's objects unmoved: the PDO list (moved) fills them.
        for (auto& sub : o.subItems) sub.info = {};
      }
      o.type = rename(o.type);
      if (!knownObjects.insert(o.index).second) {
        if (notes != nullptr) {
          notes->push_back("device " + device.type + ": module " + label(module) + " in slot " +
                           std::to_string(k) + " brings object " + hex8(o.index) +
                           ", which the device already has: the device's is kept");
        }
        continue;
      }
      out.dictionary.objects.push_back(std::move(o));
    }
  }
  for (std::size_t s = 0; s < device.slots.size(); ++s) {
    if (used[s] < device.slots[s].minInstances && notes != nullptr) {
      notes->push_back("device " + device.type + ": slot '" + device.slots[s].name + "' holds " +
                       std::to_string(used[s]) + " module(s), fewer than its MinInstances " +
                       std::to_string(device.slots[s].minInstances));
    }
  }
  // Process-data SM sizes as a configuration tool computes them: the PDOs assigned (Sm=n).
  std::map<std::size_t, std::uint32_t> bits;
  for (const auto* pdos : {&out.rxPdos, &out.txPdos}) {
    for (const auto& p : *pdos) {
      if (p.sm) bits[*p.sm] += p.bitLength();
    }
  }
  for (const auto& [sm, b] : bits) {
    if (sm < out.syncManagers.size()) {
      out.syncManagers[sm].defaultSize = static_cast<std::uint16_t>((b + 7) / 8);
    }
  }
  return out;
}

}  // namespace ecsim
