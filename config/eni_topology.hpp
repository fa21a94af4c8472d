// The topology an ENI file (<EtherCATConfig>, config/eni.hpp) describes, as configuration
// tools export it: one slave per ENI slave, its device found by vendor id, product code and
// revision among the ESI files of a search path (every *.xml in the folders given; an exact
// revision first, else the highest revision of that product), wired by the ENI's PreviousPort
// entries (a tree) or, without them, as a line in ENI order. A topology file that references
// an ENI (<Eni file= esiDir=>, config/topology_file.hpp) and topology/network_from_eni.hpp
// both use it.
#pragma once

#include <filesystem>
#include <vector>

#include "config/eni.hpp"
#include "config/topology_file.hpp"
#include "protocol/result.hpp"

namespace ecsim::topology {

// The topology an ENI describes; errors name the ENI file and line of the slave whose device
// no ESI file of `esiDirs` has.
Result<TopologyConfig> topologyFromEni(const EniConfig& eni,
                                       const std::vector<std::filesystem::path>& esiDirs);

}  // namespace ecsim::topology
