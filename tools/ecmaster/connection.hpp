// What `ecmaster` talks to: a network interface (raw socket, real clock), or with --sim an
// in-process simulated network (a topology file, or a line of generic slaves) on virtual time,
// so every command can be tried without privileges or hardware.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "link/memory_link.hpp"
#include "master/master.hpp"
#include "protocol/time.hpp"
#include "topology/network_builder.hpp"
#include "topology/network_server.hpp"

namespace ecsim::tools::ecmaster {

struct ConnectOptions {
  std::string iface;
  std::string redundantIface;  // --redundant-iface: the second port of a ring
  std::string netns;
  std::string simTopology;  // --sim FILE
  unsigned simSlaves{0};    // --sim-slaves N
};

class Connection {
 public:
  static Result<std::unique_ptr<Connection>> open(const ConnectOptions& options,
                                                  const master::MasterOptions& masterOptions);

  master::Master& master() { return *master_; }
  master::Bus& bus() { return *bus_; }
  bool simulated() const { return server_ != nullptr; }
  // --sim: the simulated slaves' names in bus order (the topology's); empty otherwise.
  std::vector<std::string> simulatedNames() const;
  const std::string& description() const { return description_; }

 private:
  Connection() = default;
  std::optional<SimTime> serveOne();

  std::unique_ptr<Link> link_;       // raw socket
  std::unique_ptr<Link> redundant_;  // raw socket of --redundant-iface
  RealClock realClock_;
  VirtualClock virtualClock_{kNsPerSecond};
  topology::Network network_;
  std::optional<std::pair<MemoryLink, MemoryLink>> memory_;
  std::unique_ptr<topology::NetworkServer> server_;
  std::unique_ptr<master::Bus> bus_;
  std::unique_ptr<master::Master> master_;
  std::string description_;
};

}  // namespace ecsim::tools::ecmaster
