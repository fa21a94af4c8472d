#include "topology/network_builder.hpp"

#include "slavesim/generic_slave.hpp"

namespace ecsim::topology {

const CableRef* Network::findCable(std::string_view name) const {
  for (const auto& c : cables) {
    if (c.name == name) return &c;
  }
  return nullptr;
}

Result<std::unique_ptr<slavesim::Slave>> makeTopologySlave(const TopologySlave& entry) {
  auto esc = slavesim::escTypeByName(entry.esc);
  if (!esc) {
    return makeError(ErrorCode::kInvalidArgument, "line " + std::to_string(entry.line) +
                                                      ": unknown ESC type '" + entry.esc +
                                                      "' (ET1100, ET1200, LAN9252)");
  }
  if (entry.builtin == "generic") {
    return slavesim::makeGenericSlave(entry.name, static_cast<std::uint32_t>(entry.line), *esc);
  }
  if (!entry.builtin.empty()) {
    return makeError(ErrorCode::kNotFound, "line " + std::to_string(entry.line) +
                                               ": unknown built-in device '" + entry.builtin + "'");
  }
  return makeError(ErrorCode::kUnsupported,
                   "line " + std::to_string(entry.line) + ": ESI devices need slavesim/esi_slave");
}

Result<Network> buildNetwork(const TopologyConfig& config, const SlaveMaker& maker) {
  Network net;
  net.segment = std::make_unique<Segment>();
  Segment& seg = *net.segment;
  for (const auto& entry : config.slaves) {
    auto slave = maker(entry);
    if (!slave.ok()) {
      Error e = slave.takeError();
      e.context = config.file.string() + ", slave '" + entry.name + "': " + e.context;
      return e;
    }
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
