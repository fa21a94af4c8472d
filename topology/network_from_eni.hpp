// A simulated network from an ENI file (<EtherCATConfig>, config/eni.hpp), as configuration
// tools export it: one simulated slave per ENI slave, its device found by vendor id, product
// code and revision among the ESI files of a search path (every *.xml in the folders given;
// an exact revision first, else the highest revision of that product), wired by the ENI's
// PreviousPort entries (a tree) or, without them, as a line in ENI order. The result is a
// topology description (topologyFromEni, config/eni_topology.hpp) built with buildNetwork.
#pragma once

#include <filesystem>
#include <vector>

#include "config/eni.hpp"
#include "config/eni_topology.hpp"
#include "config/topology_file.hpp"
#include "topology/network_builder.hpp"

namespace ecsim::topology {

// loadEniFile + topologyFromEni + buildNetwork.
Result<Network> buildNetworkFromEni(const std::filesystem::path& eniFile,
                                    const std::vector<std::filesystem::path>& esiDirs);

}  // namespace ecsim::topology
