// One mailbox request/response with one slave, as a non-blocking state machine (ETG.1000.4
// §5.6; register use as notes/soem-interop.md §3.2/§3.5 describes SOEM's):
//
//   check    FPRD SM0 status (0x0805) and SM1 status (0x080D) in one frame: a response
//            already waiting in SM1 is read first (a stale answer, or an emergency, which is
//            collected); SM0 still full means the slave has not taken the last request: wait
//   write    FPWR of the whole SM0 buffer, the request at its start with the next mailbox
//            counter (1..7); WKC 0 means SM0 was full after all: check again
//   poll     FPRD 0x080D until bit 3 (mailbox full) is set, every pollInterval
//   read     FPRD of the whole SM1 buffer; an emergency (CoE service 1) is collected and the
//            wait goes on; a mailbox error (type 0) ends the exchange with its detail text
//   repeat   the read came back empty or not at all (its answer was lost, and reading
//            emptied SM1): toggle the repeat request (SM1 activate, 0x080E bit 1), wait for
//            the slave's repeat acknowledge (0x080F bit 1) and poll again: the slave puts the
//            last response back
//
// startReceive() skips check and write: for the further fragments of a response.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "master/bus.hpp"
#include "master/datagram.hpp"
#include "master/slave_info.hpp"
#include "master/transport.hpp"
#include "protocol/coe.hpp"
#include "protocol/mailbox.hpp"

namespace ecsim::master {

struct MailboxOptions {
  SimTime sendTimeout{20 * kNsPerMs};       // SM0 free again; SOEM's EC_TIMEOUTTXM
  SimTime responseTimeout{700 * kNsPerMs};  // SOEM's EC_TIMEOUTRXM
  SimTime pollInterval{200 * kNsPerUs};     // SOEM's EC_LOCALDELAY
  unsigned repeatRequests{3};
};

struct ReceivedEmergency {
  std::size_t position{0};
  std::uint16_t station{0};
  Emergency emergency;
  SimTime receivedAt{0};
};

class MailboxExchange final : public Task {
 public:
  // `emergencies` (may be null) collects the emergencies that arrive meanwhile.
  MailboxExchange(Transport& transport, SlaveInfo& slave,
                  std::vector<ReceivedEmergency>* emergencies, MailboxOptions options = {});

  // Sends `message` (a complete mailbox, header included; its counter is set here) and
  // waits for the response. kInvalidArgument if the slave has no mailbox or the message
  // does not fit SM0.
  Status start(ConstBytes message, SimTime now);
  // Sends `message` the same way and is done once the slave took it: for a request that gets
  // no answer (the acknowledge of the last packet of an FoE read, ETG.1000.6 §5.7).
  Status send(ConstBytes message, SimTime now);
  // Waits for one more message without sending.
  Status startReceive(SimTime now);

  bool step(SimTime now) override;
  std::optional<SimTime> wakeAt() const override { return wakeAt_; }
  bool done() const { return state_ == State::kDone; }
  const Status& status() const { return status_; }
  // The SM1 buffer that held the response (the mailbox header says how much is message).
  ConstBytes response() const { return response_; }
  std::uint64_t repeats() const { return repeats_; }

 private:
  enum class State {
    kIdle,
    kCheck,
    kFlush,
    kWrite,
    kPoll,
    kRead,
    kRepeatRead,
    kRepeatWrite,
    kRepeatWait,
    kDone
  };

  bool fail(ErrorCode code, const std::string& what);
  bool datagramFailed(const Datagram& datagram, std::string_view what);
  void queueCheck();
  void queuePoll();
  void queueRead();
  bool wait(SimTime now, SimTime until);
  bool startRepeat(SimTime now);
  // A message read from SM1: true when it is the response; false when it was consumed
  // (an emergency) and the wait goes on.
  bool takeMessage(SimTime now);

  Transport& transport_;
  SlaveInfo& slave_;
  std::vector<ReceivedEmergency>* emergencies_;
  MailboxOptions options_;
  State state_{State::kIdle};
  Status status_;
  Datagram first_;
  Datagram second_;
  std::vector<std::uint8_t> request_;
  std::vector<std::uint8_t> response_;
  SimTime phaseStart_{0};
  std::optional<SimTime> wakeAt_;
  unsigned repeatsLeft_{0};
  std::uint8_t repeatBit_{0};
  std::uint64_t repeats_{0};
  bool sendOnly_{false};
};

}  // namespace ecsim::master
