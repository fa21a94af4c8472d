#include "embed/slave_variables.hpp"

#include <fmt/core.h>

#include <map>

#include "slavesim/coe/standard_objects.hpp"
#include "slavesim/esi_slave.hpp"
#include "topology/slave_names.hpp"

namespace ecsim::embed {
namespace {

std::string hexIndex(std::uint16_t index, std::uint8_t subindex) {
  return fmt::format("0x{:04X}:{:02X}", index, subindex);
}

}  // namespace

std::vector<master::VariableInfo> slaveVariables(topology::Segment& segment) {
  const std::vector<std::size_t> order = topology::busOrder(segment);
  // Slave names made unique as master::nameVariables does.
  std::map<std::string, int> uses;
  for (std::size_t s : order) ++uses[segment.slave(s).name()];
  std::vector<master::VariableInfo> out;
  for (std::size_t position = 0; position < order.size(); ++position) {
    slavesim::Slave& slave = segment.slave(order[position]);
    auto* device = slavesim::processDataDeviceOf(slave);
    if (device == nullptr) continue;
    std::string slaveName = slave.name();
    if (slaveName.empty()) slaveName = "Slave" + std::to_string(position);
    if (uses[slave.name()] > 1) slaveName += "_" + std::to_string(position);
    const auto& od = device->dictionary();
    const std::size_t first = out.size();
    std::vector<std::string> pdoNames;
    for (const auto& sm : device->binding().layout()) {
      std::uint32_t bit = 0;
      // Which PDO each entry came from: the SM's assigned PDOs' mappings in order.
      std::vector<std::string> pdoOfEntry;
      const std::uint16_t assign =
          static_cast<std::uint16_t>(slavesim::coe::kPdoAssignBase + sm.sm);
      if (const auto* assigned = od.find(assign)) {
        for (const auto& a : assigned->entries) {
          if (a.subindex == 0) continue;
          const auto pdo = od.getOr<std::uint16_t>(assign, a.subindex, 0);
          const auto* mapping = od.find(pdo);
          if (mapping == nullptr) continue;
          const auto count = od.getOr<std::uint8_t>(pdo, 0, 0);
          for (unsigned k = 0; k < count; ++k) pdoOfEntry.push_back(mapping->name);
        }
      }
      for (std::size_t k = 0; k < sm.entries.size(); ++k) {
        const auto& m = sm.entries[k];
        const auto* e = m.isPadding() ? nullptr : od.findEntry(m.index, m.subindex);
        if (e != nullptr) {
          master::VariableInfo v;
          v.slave = slaveName;
          v.entry = e->name.empty() ? hexIndex(m.index, m.subindex) : e->name;
          v.name = k < pdoOfEntry.size() ? pdoOfEntry[k] : std::string();  // until unique
          v.position = position;
          v.output = sm.outputs;
          v.bitOffset = bit;
          v.bitLength = m.bitLength;
          v.index = m.index;
          v.subindex = m.subindex;
          v.dataType = e->dataType;
          v.type = master::variableType(e->dataType, m.bitLength);
          out.push_back(std::move(v));
        }
        bit += m.bitLength;
      }
    }
    master::finishVariableNames(std::span(out).subspan(first));
  }
  return out;
}

}  // namespace ecsim::embed
