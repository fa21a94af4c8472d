#include "topology/network_builder.hpp"

#include <fmt/core.h>

#include <fstream>

#include <algorithm>

#include "config/esi_modules.hpp"
#include "protocol/closest_name.hpp"
#include "protocol/read_file.hpp"
#include "protocol/sii.hpp"
#include "slavesim/coe/od_from_esi.hpp"
#include "slavesim/devices/device_params.hpp"
#include "slavesim/esi_slave.hpp"
#include "slavesim/generic_slave.hpp"

namespace ecsim::topology {

const CableRef* Network::findCable(std::string_view name) const {
  for (const auto& c : cables) {
    if (c.name == name) return &c;
  }
  return nullptr;
}

namespace {

Error at(const TopologySlave& entry, std::string message) {
  return makeError(ErrorCode::kInvalidArgument,
                   "line " + std::to_string(entry.line) + ": " + std::move(message));
}

// A device known only by its SII EEPROM dump (a real terminal's, for replaying captures): the
// ESC with that image, its standard mailbox as the SII gives it, no application behind it.
Result<std::unique_ptr<slavesim::Slave>> makeFromEeprom(const TopologySlave& entry,
                                                        const slavesim::EscType& esc) {
  auto file = readRegularFile(entry.eepromFile, kMaxEepromFileBytes);
  if (!file.ok()) return at(entry, "EEPROM image " + file.error().context);
  std::vector<std::uint8_t> image(file->begin(), file->end());
  auto contents = SiiImage::parseLenient(image);
  slavesim::SlaveProfile profile;
  if (contents.ok() && contents->contents().standardMailbox.receiveSize > 0) {
    const auto& m = contents->contents().standardMailbox;
    profile.mailbox =
        slavesim::SlaveProfile::Mailbox{m.receiveOffset, m.receiveSize, m.sendOffset, m.sendSize};
  }
  return std::make_unique<slavesim::Slave>(entry.name, esc, std::move(image), std::move(profile));
}

}  // namespace

Result<std::unique_ptr<slavesim::Slave>> SlaveFactory::make(const TopologySlave& entry) {
  std::optional<slavesim::EscType> esc;
  if (!entry.esc.empty()) {
    esc = slavesim::escTypeByName(entry.esc);
    if (!esc) return at(entry, "unknown ESC type '" + entry.esc + "' (ET1100, ET1200, LAN9252)");
  }
  if (entry.builtin == "generic") {
    return slavesim::makeGenericSlave(entry.name, static_cast<std::uint32_t>(entry.line),
                                      esc.value_or(slavesim::kEt1100));
  }
  if (!entry.builtin.empty()) return at(entry, "unknown built-in device '" + entry.builtin + "'");
  if (!entry.eepromFile.empty()) return makeFromEeprom(entry, esc.value_or(slavesim::kEt1100));
  ECSIM_ASSIGN_OR_RETURN(const EsiFile* loaded, esiFile(entry.esiFile));
  const EsiFile& file = *loaded;
  const EsiDevice* device = nullptr;
  for (const auto& d : file.devices) {
    if (!d.hasProductCode || d.productCode != *entry.productCode) continue;
    if (entry.revision ? d.revision == *entry.revision
                       : (device == nullptr || d.revision > device->revision)) {
      device = &d;
    }
  }
  if (device == nullptr) {
    return at(entry,
              "no device with product code " + std::to_string(*entry.productCode) +
                  (entry.revision ? " and revision " + std::to_string(*entry.revision) : "") +
                  " in " + entry.esiFile.string());
  }
  slavesim::EsiSlaveOptions options;
  options.escType = esc;
  options.serial = static_cast<std::uint32_t>(entry.line);
  options.stateFile = entry.stateFile;
  if (!entry.model.empty()) {
    options.model = slavesim::devices::deviceModelByName(entry.model);
    if (!options.model) return at(entry, "unknown model '" + entry.model + "'");
  }
  if (!entry.params.empty()) {
    const bool driveObjects = device->dictionary.findObject(slavesim::devices::cia402::obj::
                                                                kControlword) != nullptr &&
                              device->dictionary.findObject(
                                  slavesim::devices::cia402::obj::kStatusword) != nullptr;
    // A device with counter values in its TxPDOs gets the encoder profile (esi_slave.cpp); that
    // needs its dictionary as built (2006-era files have none of their own).
    const auto counters = [&] {
      return !slavesim::devices::counterValueChannels(
                  slavesim::coe::buildObjectDictionary(*device, {file.vendor.id}))
                  .empty();
    };
    if (options.model.value_or(slavesim::devices::deviceModelFor(
            file.vendor.id, *entry.productCode, device->profileNo, driveObjects)) ==
            slavesim::devices::DeviceModelKind::kNone &&
        (options.model || !counters())) {
      return at(entry, "Param given, but this device has no model of ecsim with parameters" +
                           std::string(entry.model == "none" ? " (model=\"none\")" : ""));
    }
    std::vector<slavesim::devices::DeviceParam> params;
    for (const auto& p : entry.params) params.push_back({p.name, p.value, p.line});
    if (auto s = slavesim::devices::applyDeviceParams(options.models, params, entry.folder);
        !s.ok()) {
      return s.takeError();
    }
  }
  ECSIM_ASSIGN_OR_RETURN(const EsiDevice configured, withModules(entry, file, *device));
  std::vector<std::string> notes;
  options.warnings = &notes;
  auto slave = slavesim::makeSlaveFromEsi(file, configured, entry.name, options);
  if (!slave.ok()) {
    Error e = slave.takeError();
    e.context = "line " + std::to_string(entry.line) + ": " + e.context;
    return e;
  }
  for (auto& n : notes) {
    warnings_.push_back("slave '" + entry.name + "' (" + entry.esiFile.string() + "): " +
                        std::move(n));
  }
  if (auto* od = slavesim::objectDictionaryOf(**slave)) {
    for (const auto& input : entry.inputs) {
      const auto* e = od->findEntry(input.index, input.subIndex);
      if (e == nullptr) {
        return at(entry, "input " + std::to_string(input.index) + ":" +
                             std::to_string(input.subIndex) + " is not in the device's dictionary");
      }
      std::array<std::uint8_t, 8> raw{};
      writeLe64(raw, 0, static_cast<std::uint64_t>(input.value));
      ECSIM_TRY(od->setBytes(input.index, input.subIndex, ConstBytes(raw.data(), e->byteSize())));
    }
  } else if (!entry.inputs.empty()) {
    return at(entry, "this device has no objects to set inputs on");
  }
  return slave;
}

Result<const EsiFile*> SlaveFactory::esiFile(const std::filesystem::path& path) {
  auto found = esiFiles_.find(path);
  if (found == esiFiles_.end()) {
    auto file = loadEsiFile(path);
    if (!file.ok()) return file.takeError();
    found = esiFiles_.emplace(path, std::move(file).value()).first;
    warnings_.insert(warnings_.end(), found->second.warnings.begin(),
                     found->second.warnings.end());
  }
  return &found->second;
}

Result<EsiDevice> SlaveFactory::withModules(const TopologySlave& entry, const EsiFile& file,
                                            const EsiDevice& device) {
  if (device.slots.empty()) {
    if (!entry.modules.empty()) return at(entry, "device " + device.type + " has no slots");
    return device;
  }
  EsiModuleCatalog catalog;
  catalog.add(device.modules);
  catalog.add(file);
  std::vector<std::filesystem::path> others;
  if (!entry.moduleFile.empty()) others.push_back(entry.moduleFile);
  std::error_code ec;
  std::vector<std::filesystem::path> folder;
  for (const auto& f : std::filesystem::directory_iterator(entry.esiFile.parent_path(), ec)) {
    if (f.path().extension() == ".xml" && f.path() != entry.esiFile) folder.push_back(f.path());
  }
  std::sort(folder.begin(), folder.end());
  for (const auto& path : others) {
    ECSIM_ASSIGN_OR_RETURN(const EsiFile* modules, esiFile(path));
    catalog.add(*modules);
  }
  // The folder is searched only for modules not found so far (a real folder holds many ESI
  // files; an unreadable one there is not this device's business).
  auto findAll = [&]() -> bool {
    for (const auto& m : entry.modules) {
      if (m.ident ? catalog.findByIdent(*m.ident) == nullptr
                  : catalog.findByType(m.type) == nullptr) {
        return false;
      }
    }
    return entry.modules.empty() ? defaultModules(device, catalog).ok() : true;
  };
  for (const auto& path : folder) {
    if (findAll()) break;
    if (std::find(others.begin(), others.end(), path) != others.end()) continue;
    auto modules = esiFile(path);
    if (modules.ok()) catalog.add(**modules);
  }
  std::vector<const EsiModule*> chosen;
  if (entry.modules.empty()) {
    auto defaults = defaultModules(device, catalog);
    if (!defaults.ok()) return at(entry, defaults.error().context);
    chosen = std::move(defaults).value();
  }
  for (const auto& m : entry.modules) {
    const EsiModule* module = m.ident ? catalog.findByIdent(*m.ident) : catalog.findByType(m.type);
    if (module == nullptr) {
      const std::string what =
          m.ident ? fmt::format("no module with ModuleIdent #x{:08X} in the ESI files", *m.ident)
                  : unknownNameText("module type", m.type, catalog.typeNames());
      return makeError(ErrorCode::kInvalidArgument,
                       "line " + std::to_string(m.line) + ": " + what);
    }
    chosen.push_back(module);
  }
  std::vector<std::string> notes;
  auto configured = instantiateModules(device, chosen, &notes);
  if (!configured.ok()) return at(entry, configured.error().context);
  for (auto& n : notes) warnings_.push_back("slave '" + entry.name + "': " + std::move(n));
  return configured;
}

Result<Network> buildNetwork(const TopologyConfig& config) {
  if (config.slaves.size() > kMaxSlaves) {
    return makeError(ErrorCode::kInvalidArgument,
                     fmt::format("{}: {} slaves, more than {} (the address space of a segment)",
                                 config.file.string(), config.slaves.size(), kMaxSlaves));
  }
  SlaveFactory factory;
  Network net;
  net.segment = std::make_unique<Segment>();
  Segment& seg = *net.segment;
  for (const auto& entry : config.slaves) {
    auto slave = factory.make(entry);
    if (!slave.ok()) {
      Error e = slave.takeError();
      e.context = config.file.string() + ", slave '" + entry.name + "': " + e.context;
      return e;
    }
    auto& made = *slave.value();
    made.esc().setDcUnit(entry.dc == "none"         ? slavesim::Esc::DcUnit::kNone
                         : entry.dc == "delay-only" ? slavesim::Esc::DcUnit::kDelayOnly
                                                    : slavesim::Esc::DcUnit::kFull);
    const std::size_t i = seg.addSlave(std::move(slave).value());
    seg.setClock(i, entry.clockOffsetNs, entry.driftPpm);
    const auto& type = seg.slave(i).esc().type();
    seg.setDelays(i, entry.processingDelayNs.value_or(type.processingDelayNs),
                  entry.forwardingDelayNs.value_or(type.forwardingDelayNs));
  }
  seg.setMasterCable(config.masterCableMetres);
  net.cables.push_back({"master", 0, 0});
  for (const auto& link : config.links) {
    if (auto s =
            seg.connect(link.fromSlave, link.fromPort, link.toSlave, link.toPort, link.cableMetres);
        !s.ok()) {
      Error e = s.takeError();
      e.context = config.file.string() + ", line " + std::to_string(link.line) + ": " + e.context;
      return e;
    }
    net.cables.push_back({link.name, link.toSlave, link.toPort});
  }
  net.warnings.insert(net.warnings.end(), config.warnings.begin(), config.warnings.end());
  net.warnings.insert(net.warnings.end(), factory.warnings().begin(), factory.warnings().end());
  return net;
}

}  // namespace ecsim::topology
