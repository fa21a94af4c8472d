#include "tools/ecmaster/connection.hpp"

#include <fmt/core.h>

#include "config/topology_file.hpp"
#include "link/raw_socket_link.hpp"
#include "slavesim/generic_slave.hpp"
#include "topology/slave_names.hpp"

namespace ecsim::tools::ecmaster {

Result<std::unique_ptr<Connection>> Connection::open(const ConnectOptions& options,
                                                     const master::MasterOptions& masterOptions) {
  std::unique_ptr<Connection> c(new Connection());
  const bool sim = !options.simTopology.empty() || options.simSlaves > 0;
  if (sim == !options.iface.empty()) {
    return makeError(ErrorCode::kInvalidArgument,
                     "give either --iface IF or --sim TOPOLOGY / --sim-slaves N");
  }
  if (!options.redundantIface.empty() && sim) {
    return makeError(ErrorCode::kInvalidArgument,
                     "--redundant-iface needs --iface (a ring's two ports)");
  }
  if (!sim) {
    ECSIM_ASSIGN_OR_RETURN(
        RawSocketLink raw,
        RawSocketLink::open(options.iface, RawSocketOptions{options.netns, true}));
    c->link_ = std::make_unique<RawSocketLink>(std::move(raw));
    if (!options.redundantIface.empty()) {
      ECSIM_ASSIGN_OR_RETURN(
          RawSocketLink second,
          RawSocketLink::open(options.redundantIface, RawSocketOptions{options.netns, true}));
      c->redundant_ = std::make_unique<RawSocketLink>(std::move(second));
    }
    c->bus_ = std::make_unique<master::RealTimeBus>(*c->link_, c->realClock_, c->redundant_.get());
    c->master_ = std::make_unique<master::Master>(*c->link_, *c->bus_, masterOptions);
    c->master_->setRedundantLink(c->redundant_.get());
    c->description_ = c->link_->describe();
    if (c->redundant_) c->description_ += " + " + c->redundant_->describe();
    return c;
  }
  if (!options.simTopology.empty()) {
    ECSIM_ASSIGN_OR_RETURN(TopologyConfig config, loadTopologyFile(options.simTopology));
    ECSIM_ASSIGN_OR_RETURN(c->network_, topology::buildNetwork(config));
    for (const auto& w : c->network_.warnings) fmt::print(stderr, "ecmaster: warning: {}\n", w);
    c->description_ = "simulated network " + options.simTopology;
  } else {
    c->network_.segment = std::make_unique<topology::Segment>();
    for (unsigned i = 0; i < options.simSlaves; ++i) {
      c->network_.segment->addSlave(
          slavesim::makeGenericSlave(fmt::format("Slave{}", i + 1), i + 1));
    }
    c->network_.segment->wireLine();
    c->description_ = fmt::format("simulated line of {} generic slaves", options.simSlaves);
  }
  c->memory_.emplace(MemoryLink::makePair(256));
  topology::ServerOptions serverOptions;
  serverOptions.idleWait = std::chrono::nanoseconds(0);
  c->server_ = std::make_unique<topology::NetworkServer>(c->memory_->second, *c->network_.segment,
                                                         c->virtualClock_, serverOptions);
  Connection* self = c.get();
  c->bus_ = std::make_unique<master::VirtualBus>(c->virtualClock_,
                                                 [self](SimTime) { return self->serveOne(); });
  c->master_ = std::make_unique<master::Master>(c->memory_->first, *c->bus_, masterOptions);
  return c;
}

std::vector<std::string> Connection::simulatedNames() const {
  if (!network_.segment) return {};
  return topology::slaveNamesInBusOrder(*network_.segment);
}

std::optional<SimTime> Connection::serveOne() {
  const bool waiting = memory_->second.pending() > 0;
  const auto before = server_->counters().framesAnswered;
  (void)server_->step();
  if (waiting && server_->counters().framesAnswered != before) {
    return server_->counters().lastRoundTrip;
  }
  return std::nullopt;
}

}  // namespace ecsim::tools::ecmaster
