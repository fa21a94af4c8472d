// Requests one AL state of every slave at once and waits for them (ETG.1000.6 §6.4; the
// ESC datasheet section I §10), as a non-blocking state machine:
//
//   read      FPRD 0x0130-0x0135 of every slave: state, error flag, AL status code
//   request   FPWR 0x0120 = target per slave, with the error-acknowledge bit for a slave
//             that shows an error (the request then also acknowledges it)
//   poll      FPRD 0x0130-0x0135 of the slaves not settled, every pollInterval; a slave
//             settles when it shows the target without error, or refuses: error flag set,
//             AL status code read, the error acknowledged (FPWR 0x0120 = its current state +
//             acknowledge) so it can be asked again
//
// The result lists every slave that refused, with its code and the code's text, and every
// slave that had not reached the target when `timeout` ran out.
#pragma once

#include <string>
#include <vector>

#include "master/batch.hpp"
#include "master/bus.hpp"
#include "master/slave_info.hpp"
#include "master/transport.hpp"
#include "protocol/al_status.hpp"

namespace ecsim::master {

struct StateChangeOptions {
  SimTime timeout{5 * kNsPerSecond};  // SOEM waits 2 s (INIT, PREOP) to 8 s (SAFEOP)
  SimTime pollInterval{kNsPerMs};     // SOEM's statecheck polls every 1 ms
  bool acknowledgeErrors{true};
};

struct StateRefusal {
  std::size_t position{0};
  std::uint16_t station{0};
  std::string name;
  AlState requested{AlState::kInit};
  std::uint16_t alStatus{0};  // as read when the refusal was seen (error flag set)
  std::uint16_t alStatusCode{0};
  bool acknowledged{false};
  // "slave 1 (0x1002 'DO1') refused SAFEOP: AL status code 0x001D (Invalid output
  // configuration), stays PREOP (error acknowledged)"
  std::string describe() const;
};

class StateChangeTask final : public Task {
 public:
  StateChangeTask(Transport& transport, std::vector<SlaveInfo>& slaves,
                  StateChangeOptions options = {});

  void start(AlState target, SimTime now);
  bool step(SimTime now) override;
  std::optional<SimTime> wakeAt() const override { return wakeAt_; }

  // kAborted when a slave refused (context: every refusal), kTimeout when one was too slow,
  // kWorkingCounter when a slave did not answer.
  const Status& status() const { return status_; }
  const std::vector<StateRefusal>& refusals() const { return refusals_; }
  AlState target() const { return target_; }

 private:
  enum class State { kIdle, kRead, kRequest, kPoll, kAcknowledge, kDone };
  enum class Outcome : std::uint8_t { kPending, kReached, kRefused };

  void queueReads(bool onlyPending);
  bool takeReads(SimTime now);  // false when the reads failed (status set)
  bool finish();

  Transport& transport_;
  std::vector<SlaveInfo>& slaves_;
  StateChangeOptions options_;
  AlState target_{AlState::kInit};
  State state_{State::kIdle};
  Status status_;
  SimTime startedAt_{0};
  std::optional<SimTime> wakeAt_;
  std::vector<Outcome> outcome_;
  std::vector<std::size_t> reading_;  // positions of the slaves in batch_, in order
  DatagramBatch batch_;
  DatagramBatch acks_;
  std::vector<bool> ackSent_;  // per slave: the last request carried the acknowledge bit
  std::vector<StateRefusal> refusals_;
};

}  // namespace ecsim::master
