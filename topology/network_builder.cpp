#include "topology/network_builder.hpp"

#include <fmt/core.h>

#include <fstream>

#include "protocol/read_file.hpp"
#include "protocol/sii.hpp"
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
  auto found = esiFiles_.find(entry.esiFile);
  if (found == esiFiles_.end()) {
    auto file = loadEsiFile(entry.esiFile);
    if (!file.ok()) return file.takeError();
    found = esiFiles_.emplace(entry.esiFile, std::move(file).value()).first;
  }
  const EsiFile& file = found->second;
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
  if (!entry.params.empty()) {
    if (slavesim::devices::deviceModelFor(file.vendor.id, *entry.productCode, device->profileNo) ==
        slavesim::devices::DeviceModelKind::kNone) {
      return at(entry, "Param given, but this device has no model of ecsim with parameters");
    }
    std::vector<slavesim::devices::DeviceParam> params;
    for (const auto& p : entry.params) params.push_back({p.name, p.value, p.line});
    if (auto s = slavesim::devices::applyDeviceParams(options.models, params, entry.folder);
        !s.ok()) {
      return s.takeError();
    }
  }
  auto slave = slavesim::makeSlaveFromEsi(file, *device, entry.name, options);
  if (!slave.ok()) return slave;
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
  return net;
}

}  // namespace ecsim::topology
