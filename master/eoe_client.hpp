// EoE client (ETG.1000.6 §5.7) over MailboxExchange: Set IP Parameter and Get IP Parameter
// of one slave's EoE port, as a non-blocking state machine. A result other than 0 in the
// Set IP response ends the task with kAborted, the result code and its text.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "master/mailbox_exchange.hpp"
#include "protocol/eoe.hpp"

namespace ecsim::master {

class EoeIpTask final : public Task {
 public:
  EoeIpTask(Transport& transport, SlaveInfo& slave, std::vector<ReceivedEmergency>* emergencies,
            MailboxOptions options = {});

  // Sends the fields `parameters` includes (the others are left as the slave has them).
  Status startSet(const EoeIpParameters& parameters, std::uint8_t port, SimTime now);
  Status startGet(std::uint8_t port, SimTime now);

  bool step(SimTime now) override;
  std::optional<SimTime> wakeAt() const override { return exchange_.wakeAt(); }
  bool done() const { return done_; }
  const Status& status() const { return status_; }
  // After a Get: what the slave answered.
  const EoeIpParameters& parameters() const { return parameters_; }

 private:
  Status send(EoeFrameType type, std::uint8_t port, ConstBytes body, SimTime now);
  bool fail(ErrorCode code, const std::string& what);

  MailboxExchange exchange_;
  SlaveInfo& slave_;
  EoeFrameType expected_{EoeFrameType::kSetIpResponse};
  bool done_{false};
  Status status_;
  EoeIpParameters parameters_;
};

}  // namespace ecsim::master
