// The query and control API of `ecsim serve` (docs/control.md): what an external master's
// tester asks the simulator through the control socket (topology/control_server.hpp).
//
// A request line starting with '{' is one JSON object {"op": ...}; every other line is a fault
// action in the text form of topology/faults.hpp ("link-down cable=drives"), the thin layer
// kept for `ecsim ctl link-down ...` and scripts. Each JSON request is answered by one JSON
// object on one line, {"ok":true,...} or {"ok":false,"error":"..."}; a text line keeps its
// "ok ..."/"error ..." answer. Our own format is strict: an unknown op or key is an error
// naming the closest valid one, malformed JSON an error naming the byte.
//
// Process-data entries are named as the master names them (master/variables.hpp):
// "<slave>.<entry>" ("DO1.Output 8", "Drive1.Statusword"), with the same aliases
// ("<position>.<entry>", "<slave>.0xIIII:SS"); a request gives {"slave":"DO1","entry":"Output 8"}
// or {"name":"DO1.Output 8"}. The slave-side names come from the slave's own PDO mapping (what
// its firmware copies), the topology's slave names and the dictionary's entry names, so they
// are the names a master configured from the same ESI gives.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "master/variables.hpp"
#include "protocol/time.hpp"
#include "topology/control_server.hpp"
#include "topology/faults.hpp"
#include "topology/network_builder.hpp"

namespace ecsim::tools {

// How many subscriptions one client may hold.
inline constexpr std::size_t kMaxSubscriptionsPerClient = 64;

class ControlApi {
 public:
  explicit ControlApi(topology::Network& network) : network_(network) {}

  // Answers one request line of `client` (without its newline) at `now`.
  std::string answer(std::string_view line, topology::ControlServer::ClientId client, SimTime now);
  // Pushes {"event":"change",...} to each subscriber whose entry changed since it was last
  // told; called once per served frame batch. A subscriber whose replies are not read is
  // skipped (its value is sent, the newest, once it reads again); a gone client's
  // subscriptions are dropped.
  void publish(topology::ControlServer& server);
  std::size_t subscriptions() const { return subscriptions_.size(); }

 private:
  struct Subscription {
    topology::ControlServer::ClientId client{0};
    master::VariableInfo variable;
    std::size_t slave{0};  // segment index
    std::uint64_t last{0};
  };
  struct AppliedFault {
    SimTime at{0};
    std::string action;
    std::string result;
  };
  std::string answerJson(std::string_view line, topology::ControlServer::ClientId client,
                         SimTime now);
  std::string answerFault(std::string_view line, SimTime now);

  topology::Network& network_;
  // Made at the first fault: as the segment's wire faults it turns off the replay of the
  // recorded route (docs/timing.md), which a network without faults keeps.
  std::optional<topology::FaultInjector> faults_;
  std::vector<AppliedFault> applied_;
  std::vector<Subscription> subscriptions_;
};

}  // namespace ecsim::tools
