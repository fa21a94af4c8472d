// SoE client (ETG.1000.6 §5.9) over MailboxExchange, as a non-blocking state machine:
//
//   SoeTask   read of the elements of one IDN of one drive, the response's fragments
//             (`incomplete` set) reassembled; write of the value element in one mailbox
//             (SOEM's ecx_SoEwrite fragments longer values; the lists ecmaster writes fit
//             one mailbox, a longer value is refused with kTooLarge). An error response ends
//             the task with kAborted, the SoE error code and its text.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "master/mailbox_exchange.hpp"
#include "protocol/soe.hpp"

namespace ecsim::master {

// "0x1001 (No IDN)"
std::string describeSoeError(std::uint16_t code);

class SoeTask final : public Task {
 public:
  SoeTask(Transport& transport, SlaveInfo& slave, std::vector<ReceivedEmergency>* emergencies,
          MailboxOptions options = {});

  Status startRead(std::uint8_t driveNo, std::uint8_t elements, std::uint16_t idn, SimTime now);
  Status startWrite(std::uint8_t driveNo, std::uint16_t idn, ConstBytes value, SimTime now);

  bool step(SimTime now) override;
  std::optional<SimTime> wakeAt() const override { return exchange_.wakeAt(); }
  bool done() const { return done_; }
  const Status& status() const { return status_; }
  std::optional<std::uint16_t> errorCode() const { return errorCode_; }
  // The read response's data (the elements asked, in element order), fragments joined.
  const std::vector<std::uint8_t>& data() const { return data_; }
  std::size_t fragments() const { return fragments_; }

 private:
  Status send(SimTime now);
  bool fail(ErrorCode code, const std::string& what);

  MailboxExchange exchange_;
  SlaveInfo& slave_;
  SoeHeader request_;
  std::vector<std::uint8_t> value_;
  std::vector<std::uint8_t> data_;
  Status status_;
  std::optional<std::uint16_t> errorCode_;
  std::size_t fragments_{0};
  bool done_{true};
};

}  // namespace ecsim::master
