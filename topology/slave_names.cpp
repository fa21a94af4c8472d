#include "topology/slave_names.hpp"

#include "config/eni.hpp"
#include "config/master_config.hpp"

namespace ecsim::topology {
namespace {

// Where a frame goes next inside an ESC (section I §3.2 Table 10): 0 -> 3 -> 1 -> 2 -> 0.
constexpr std::array<unsigned, kPortCount> kNextPort{3, 2, 0, 1};

}  // namespace

std::vector<std::size_t> busOrder(const std::vector<std::array<PortLink, kPortCount>>& ports) {
  std::vector<std::size_t> order;
  if (ports.empty()) return order;
  struct Visit {
    std::size_t slave;
    unsigned entry;  // the port the frame came in through
    unsigned port;   // the port it left through towards a child
  };
  std::vector<Visit> stack{{0, 0, 0}};
  std::size_t s = 0;
  unsigned k = 0;  // the port the frame is at
  // Each slave is entered once and each of its ports is passed once, so the walk ends; the
  // bound guards against a port table that is not a tree.
  for (std::size_t steps = 0; steps <= ports.size() * (kPortCount + 1) * 2; ++steps) {
    if (k == 0) order.push_back(s);
    const unsigned out = kNextPort[k];
    if (out == stack.back().entry) {  // back towards the master
      stack.pop_back();
      if (stack.empty()) break;
      s = stack.back().slave;
      k = stack.back().port;
      continue;
    }
    const PortLink& link = ports[s][out];
    if (link.slave == kNoSlave || static_cast<std::size_t>(link.slave) >= ports.size()) {
      k = out;  // nothing connected: the ESC loops the frame back to its next port
      continue;
    }
    stack.back().port = out;
    s = static_cast<std::size_t>(link.slave);
    k = link.port;
    stack.push_back({s, k, k});
  }
  return order;
}

std::vector<std::size_t> busOrder(const Segment& segment) {
  std::vector<std::array<PortLink, kPortCount>> ports(segment.size());
  for (std::size_t i = 0; i < segment.size(); ++i) ports[i] = segment.ports(i);
  return busOrder(ports);
}

std::vector<std::size_t> busOrder(const TopologyConfig& config) {
  std::vector<std::array<PortLink, kPortCount>> ports(config.slaves.size());
  for (const TopologyLink& l : config.links) {
    if (l.fromSlave >= ports.size() || l.toSlave >= ports.size() || l.fromPort >= kPortCount ||
        l.toPort >= kPortCount) {
      continue;  // the reader refuses these; nothing to walk
    }
    ports[l.fromSlave][l.fromPort] = {static_cast<int>(l.toSlave),
                                      static_cast<std::uint8_t>(l.toPort), l.cableMetres};
    ports[l.toSlave][l.toPort] = {static_cast<int>(l.fromSlave),
                                  static_cast<std::uint8_t>(l.fromPort), l.cableMetres};
  }
  return busOrder(ports);
}

std::vector<std::string> slaveNamesInBusOrder(const Segment& segment) {
  std::vector<std::string> names;
  for (const std::size_t i : busOrder(segment)) names.push_back(segment.slave(i).name());
  return names;
}

std::vector<std::string> slaveNamesInBusOrder(const TopologyConfig& config) {
  std::vector<std::string> names;
  for (const std::size_t i : busOrder(config)) names.push_back(config.slaves[i].name);
  return names;
}

Result<std::vector<std::string>> loadSlaveNames(const std::filesystem::path& file) {
  ECSIM_ASSIGN_OR_RETURN(const std::string root, xmlRootName(file));
  if (root == "Topology") {
    ECSIM_ASSIGN_OR_RETURN(const TopologyConfig config, loadTopologyFile(file));
    return slaveNamesInBusOrder(config);
  }
  if (root == "EtherCATConfig" || root == "EcsimMaster") {
    ECSIM_ASSIGN_OR_RETURN(const MasterConfig config, loadMasterConfig(file));
    std::vector<std::string> names;
    for (const ExpectedSlave& s : config.slaves) names.push_back(s.name);
    return names;
  }
  return makeError(
      ErrorCode::kInvalidArgument,
      file.string() + ": root element <" + root +
          "> names no slaves (a <Topology>, an ENI <EtherCATConfig> or an <EcsimMaster> does)");
}

}  // namespace ecsim::topology
