// Builds a simulated network (Segment) from a topology file's description: each slave from
// its ESI device or as a device of ours, ESC type and delays, clocks, wiring with cable
// lengths, initial inputs. Cable names are kept so captures and faults can address cables.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "config/topology_file.hpp"
#include "protocol/result.hpp"
#include "topology/segment.hpp"

namespace ecsim::topology {

struct CableRef {
  std::string name;
  std::size_t slave{0};  // the downstream end: observers and faults attach here
  unsigned port{0};
};

struct Network {
  std::unique_ptr<Segment> segment;
  std::vector<CableRef> cables;  // "master" first (slave 0, port 0), then the file's links
  const CableRef* findCable(std::string_view name) const;
};

// Makes the slave a topology entry describes; the default handles built-in devices and ESI
// devices (see slavesim/esi_slave.hpp).
using SlaveMaker = std::function<Result<std::unique_ptr<slavesim::Slave>>(const TopologySlave&)>;
Result<std::unique_ptr<slavesim::Slave>> makeTopologySlave(const TopologySlave& entry);

Result<Network> buildNetwork(const TopologyConfig& config,
                             const SlaveMaker& maker = makeTopologySlave);

}  // namespace ecsim::topology
