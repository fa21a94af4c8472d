#include "topology/network_builder.hpp"

#include <fmt/core.h>

#include <fstream>

#include <algorithm>
#include <string_view>
#include <unordered_map>

#include "config/esi_modules.hpp"
#include "protocol/closest_name.hpp"
#include "protocol/read_file.hpp"
#include "protocol/sii.hpp"
#include "slavesim/coe/od_from_esi.hpp"
#include "slavesim/devices/device_params.hpp"
#include "slavesim/eoe/eoe_params.hpp"
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

// A device whose ESI says where its ID is read (Info/IdentificationAdo, without
// IdentificationReg134: an EK1101, whose ESC in digital I/O mode samples the ID switch into
// 0x1000) keeps the ID there, and in the input PDO entry mapped at that address (its TxPDO "ID",
// 0x6000:01), so a master reads it at the address in any state and in the process data in
// SAFEOP and OP. No 0x0134 answer: such an ESC runs without a microcontroller.
void showDeviceIdAtAdo(std::uint16_t id, const EsiDevice& device, slavesim::Slave& slave) {
  const std::uint16_t ado = *device.identificationAdo;
  slave.profile().adoDeviceId = slavesim::SlaveProfile::AdoDeviceId{ado, id};
  auto* od = slavesim::objectDictionaryOf(slave);
  for (std::size_t sm = 0; od != nullptr && sm < device.syncManagers.size(); ++sm) {
    if (device.syncManagers[sm].startAddress != ado) continue;
    for (const auto& pdo : device.txPdos) {
      if (pdo.sm != sm || pdo.entries.empty() || pdo.entries.front().index == 0) continue;
      const EsiPdoEntry& first = pdo.entries.front();
      const auto* e = od->findEntry(first.index, first.subIndex);
      if (e == nullptr) return;
      std::array<std::uint8_t, 8> raw{};
      writeLe16(raw, 0, id);
      (void)od->setBytes(first.index, first.subIndex,
                         ConstBytes(raw.data(), std::min<std::size_t>(e->byteSize(), 2)));
      return;
    }
  }
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
  // eoe.* go to the EoE server once the slave exists, the rest to its device model.
  std::vector<slavesim::eoe::EoeParam> eoeParams;
  std::vector<slavesim::devices::DeviceParam> params;
  for (const auto& p : entry.params) {
    if (p.name.rfind(slavesim::eoe::kEoeParamPrefix, 0) == 0) {
      eoeParams.push_back({p.name, p.value, p.line});
    } else {
      params.push_back({p.name, p.value, p.line});
    }
  }
  if (!params.empty()) {
    if (auto s = slavesim::devices::applyDeviceParams(options.models, params, entry.folder);
        !s.ok()) {
      return s.takeError();
    }
    const auto& m = options.models;
    if (!m.loopbackFrom.empty() && entry.model != "loopback") {
      return makeError(ErrorCode::kInvalidArgument,
                       "line " + std::to_string(m.loopbackLine) +
                           ": loopback.from needs model=\"loopback\" on the <Slave>");
    }
  }
  if (entry.model == "loopback" && options.models.loopbackFrom.empty()) {
    return at(entry, "model=\"loopback\" needs <Param name=\"loopback.from\" value=\"SLAVE\"/>");
  }
  if (!entry.soeDictionaryFile.empty()) {
    if (!device->mailbox.soe) {
      return at(entry, "soeDictionary given, but the ESI mailbox of this device has no <SoE>");
    }
    ECSIM_ASSIGN_OR_RETURN(const EsiFile* dict, esiFile(entry.soeDictionaryFile));
    if (dict->root != EsiRoot::kEtherCatDict) {
      return at(entry, "soeDictionary " + entry.soeDictionaryFile.string() +
                           " is no EtherCATDict file (its IDNs are the <Object>s of one)");
    }
    options.soeDictionary = &dict->dictionary;
    options.soeDictionaryFile = entry.soeDictionaryFile.string();
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
    warnings_.push_back("slave '" + entry.name + "' (" + entry.esiFile.string() +
                        "): " + std::move(n));
  }
  if (!eoeParams.empty()) {
    auto* eoe = slavesim::eoeServerOf(**slave);
    if (eoe == nullptr) return at(entry, "eoe.* Param given, but the device's ESI lists no EoE");
    ECSIM_TRY(slavesim::eoe::applyEoeParams(*eoe, eoeParams));
  }
  if (!params.empty() && slavesim::devices::deviceModelOf(**slave) == nullptr) {
    return at(entry, "Param given, but this device has no model of ecsim with parameters" +
                         std::string(entry.model == "none" ? " (model=\"none\")" : ""));
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
  if (entry.deviceId && configured.identificationAdo && !configured.identificationReg134) {
    showDeviceIdAtAdo(*entry.deviceId, configured, **slave);
  }
  return slave;
}

Result<const EsiFile*> SlaveFactory::esiFile(const std::filesystem::path& path) {
  auto found = esiFiles_.find(path);
  if (found == esiFiles_.end()) {
    auto file = loadEsiFile(path);
    if (!file.ok()) return file.takeError();
    found = esiFiles_.emplace(path, std::move(file).value()).first;
    warnings_.insert(warnings_.end(), found->second.warnings.begin(), found->second.warnings.end());
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
      return makeError(ErrorCode::kInvalidArgument, "line " + std::to_string(m.line) + ": " + what);
    }
    chosen.push_back(module);
  }
  std::vector<std::string> notes;
  auto configured = instantiateModules(device, chosen, &notes);
  if (!configured.ok()) return at(entry, configured.error().context);
  for (auto& n : notes) warnings_.push_back("slave '" + entry.name + "': " + std::move(n));
  return configured;
}

namespace {

// Binds the inputs that follow another slave's outputs ("output slave=... channel=..." in a
// signal.N, model="loopback" with loopback.from) once every slave exists. Errors name the
// topology file and the <Param>'s line.
Status bindOutputSignals(const TopologyConfig& config, Segment& seg) {
  namespace dev = slavesim::devices;
  std::unordered_map<std::string_view, std::size_t> byName;
  std::vector<std::string_view> names;
  for (std::size_t i = 0; i < config.slaves.size(); ++i) {
    byName.emplace(config.slaves[i].name, i);
    names.push_back(config.slaves[i].name);
  }
  for (std::size_t i = 0; i < config.slaves.size(); ++i) {
    const TopologySlave& entry = config.slaves[i];
    auto fail = [&](int line, const std::string& message) {
      return makeError(ErrorCode::kInvalidArgument,
                       fmt::format("{}, slave '{}': line {}: {}", config.file.string(), entry.name,
                                   line, message));
    };
    // The outputs of slave `from`, channel `channel`, or an error for the <Param> at `line`.
    auto source = [&](int line, const std::string& from,
                      unsigned channel) -> Result<std::shared_ptr<const dev::SignalSource>> {
      auto found = byName.find(from);
      if (found == byName.end()) {
        return fail(line, unknownNameText("slave", from, names));
      }
      auto* pd = slavesim::processDataDeviceOf(seg.slave(found->second));
      if (pd == nullptr) return fail(line, "slave '" + from + "' has no digital outputs");
      auto s = dev::outputChannelSource(*pd, channel);
      if (!s.ok()) return fail(line, "slave '" + from + "' " + s.error().context);
      return s;
    };
    dev::DigitalInputTerminal* inputs = dev::digitalInputsOf(seg.slave(i));
    for (const TopologyParam& p : entry.params) {
      if (p.name.rfind("signal.", 0) != 0) continue;
      const std::string_view value = p.value;
      if (value.find_first_not_of(' ') == std::string_view::npos ||
          value.substr(value.find_first_not_of(' ')).rfind("output", 0) != 0) {
        continue;
      }
      auto signal = dev::parseSignal(p.value);
      if (!signal.ok() || signal->kind() != dev::Signal::Kind::kOutput) continue;
      if (inputs == nullptr) return fail(p.line, "the device has no digital inputs to drive");
      const unsigned channel = static_cast<unsigned>(std::stoul(p.name.substr(7)));
      ECSIM_ASSIGN_OR_RETURN(auto src,
                             source(p.line, signal->outputSlave(), signal->outputChannel()));
      inputs->setScript(channel, signal->bind(std::move(src)));
    }
    if (entry.model != "loopback") continue;
    int line = entry.line;
    std::string from;
    for (const TopologyParam& p : entry.params) {
      if (p.name == "loopback.from") {
        line = p.line;
        from = p.value;
      }
    }
    if (inputs == nullptr) return fail(entry.line, "model loopback: no digital inputs");
    if (auto check = source(line, from, 1); !check.ok()) return check.takeError();
    auto* pd = slavesim::processDataDeviceOf(seg.slave(byName.at(from)));
    const unsigned count =
        std::min(inputs->channels(), dev::digitalOutputsIn(pd->application())->channels());
    for (unsigned c = 1; c <= count; ++c) {
      ECSIM_ASSIGN_OR_RETURN(auto src, source(line, from, c));
      inputs->setScript(c, dev::Signal::output(from, c).bind(std::move(src)));
    }
  }
  return okStatus();
}

}  // namespace

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
    if (entry.alias) {  // in the EEPROM as delivered: loaded into 0x0012 from the start
      made.esc().setSiiStationAlias(*entry.alias);
      made.esc().powerOnReset();
    }
    if (entry.deviceId && !made.profile().adoDeviceId) {
      // An ESC in device emulation has no firmware to answer the ID request (AL control bit
      // 5): the deviceId would show nowhere.
      if (made.esc().deviceEmulation()) {
        return makeError(ErrorCode::kInvalidArgument,
                         config.file.string() + ", line " + std::to_string(entry.line) +
                             ", slave '" + entry.name +
                             "': deviceId on a device whose ESC runs in device emulation (no "
                             "firmware answers the ID request in 0x0134) and whose ESI names no "
                             "IdentificationAdo to read it at");
      }
      made.profile().explicitDeviceId = entry.deviceId;
    }
    made.esc().setDcUnit(entry.dc == "none"         ? slavesim::Esc::DcUnit::kNone
                         : entry.dc == "delay-only" ? slavesim::Esc::DcUnit::kDelayOnly
                                                    : slavesim::Esc::DcUnit::kFull);
    const std::size_t i = seg.addSlave(std::move(slave).value());
    seg.setClock(i, entry.clockOffsetNs, entry.driftPpm);
    const auto& type = seg.slave(i).esc().type();
    seg.setDelays(i, entry.processingDelayNs.value_or(type.processingDelayNs),
                  entry.forwardingDelayNs.value_or(type.forwardingDelayNs));
  }
  ECSIM_TRY(bindOutputSignals(config, seg));
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
  if (config.redundantPort) {
    const auto [slave, port] = *config.redundantPort;
    // Its link is down until a master's second port is there (ecsim serve --redundant-iface):
    // a master without one sees an open ring, as on hardware with that cable unplugged.
    if (auto s = seg.setRedundantPort(slave, port, config.redundantCableMetres, false); !s.ok()) {
      Error e = s.takeError();
      e.context =
          config.file.string() + ", line " + std::to_string(config.masterLine) + ": " + e.context;
      return e;
    }
    net.cables.push_back({"redundant", slave, port});
  }
  // A group detached at power-up: its slaves are off, so the junction's port has no link.
  for (const auto& g : config.groups) {
    net.groups.push_back({g.name, g.slaves});
    if (g.attached) continue;
    for (const std::size_t s : g.slaves) seg.slave(s).powerOff();
    const TopologyLink& j = config.links[g.junctionLink];
    seg.setLinkUp(j.fromSlave, j.fromPort, false);
    seg.setLinkUp(j.toSlave, j.toPort, false);
  }
  net.warnings.insert(net.warnings.end(), config.warnings.begin(), config.warnings.end());
  net.warnings.insert(net.warnings.end(), factory.warnings().begin(), factory.warnings().end());
  return net;
}

}  // namespace ecsim::topology
