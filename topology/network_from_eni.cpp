#include "topology/network_from_eni.hpp"

namespace ecsim::topology {

Result<Network> buildNetworkFromEni(const std::filesystem::path& eniFile,
                                    const std::vector<std::filesystem::path>& esiDirs) {
  ECSIM_ASSIGN_OR_RETURN(EniConfig eni, loadEniFile(eniFile));
  ECSIM_ASSIGN_OR_RETURN(TopologyConfig config, topologyFromEni(eni, esiDirs));
  ECSIM_ASSIGN_OR_RETURN(Network network, buildNetwork(config));
  // The ENI's own warnings first, then what building the devices reported.
  eni.warnings.insert(eni.warnings.end(), network.warnings.begin(), network.warnings.end());
  network.warnings = std::move(eni.warnings);
  return network;
}

}  // namespace ecsim::topology
