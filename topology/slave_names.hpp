// The names people gave the slaves, by bus position: a master that knows them names process
// variables, events and messages after them ("Drive1.Statusword", "slave 4 (0x1005 'Drive1')
// lost"), Master::setSlaveNames.
//
// The bus position of a slave (its auto-increment address, ETG.1000.4) is the order in which
// a frame passes the slaves' processing units: in at slave 0's port 0, through each ESC's
// ports in the order 0 -> 3 -> 1 -> 2 (ESC datasheet section I §3.2, Table 10), the unit
// passed where the frame is at port 0. Topology files may list the slaves in any order and
// wire them as a tree, so the order is taken from the wiring, as Segment::processFrame walks
// it; an ENI lists its slaves in bus order.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "config/topology_file.hpp"
#include "protocol/result.hpp"
#include "topology/segment.hpp"

namespace ecsim::topology {

// The slaves in bus order, as indices into `ports` (each slave's four ports: neighbour slave
// and its port, kNoSlave where nothing is connected), starting from slave 0 at the master.
// Slaves no cable reaches are left out.
std::vector<std::size_t> busOrder(const std::vector<std::array<PortLink, kPortCount>>& ports);
std::vector<std::size_t> busOrder(const Segment& segment);
std::vector<std::size_t> busOrder(const TopologyConfig& config);

// The slaves' names in bus order.
std::vector<std::string> slaveNamesInBusOrder(const Segment& segment);
std::vector<std::string> slaveNamesInBusOrder(const TopologyConfig& config);

// The names a topology file (<Topology>, in bus order as above), an ENI (<EtherCATConfig>, its
// <Slave><Info><Name>s in the order written) or a master configuration (<EcsimMaster>) gives;
// errors name the file (and line).
Result<std::vector<std::string>> loadSlaveNames(const std::filesystem::path& file);

}  // namespace ecsim::topology
