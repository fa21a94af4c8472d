// Bringing one slave back to OP while the others keep cycling: a non-blocking task that the
// master steps once per cycle between its cyclic frames (IgH's fsm discipline). Where it
// starts depends on what the slave shows:
//
//   kAddress   the slave answers at its position but not at its station address (a power
//              cycle cleared it): APWR 0x0010 = station address
//   kIdentity  EEPROM words 0x08-0x0B (vendor id, product code) through 0x0502-0x050F must
//              match what the scan found, or the task fails naming both identities
//   kMailbox   mailbox SyncManagers as at start-up, then INIT -> PREOP
//   kProcess   SM and FMMU settings of the slave's part of the process image, PREOP -> SAFEOP
//   kOp        SAFEOP -> OP (an error shown is acknowledged with the request), while the
//              cyclic frames keep valid outputs flowing
//
// PDO assignment is not written: the master takes the slave's own mapping at start-up, and a
// slave that was power-cycled comes back with that same default.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "master/batch.hpp"
#include "master/bus.hpp"
#include "master/process_image.hpp"
#include "master/slave_info.hpp"
#include "master/state_change.hpp"
#include "master/transport.hpp"

namespace ecsim::master {

class SlaveRecoveryTask final : public Task {
 public:
  enum class Stage : std::uint8_t { kAddress, kIdentity, kMailbox, kProcess, kOp, kDone, kFailed };

  // `slave` is the master's record (updated as the task learns the AL status); `layout` the
  // process image whose SM/FMMU settings the slave gets back. Both must outlive the task.
  SlaveRecoveryTask(Transport& transport, SlaveInfo& slave, const ProcessImageLayout& layout,
                    StateChangeOptions options = {});

  void start(Stage first, SimTime now, SimTime timeout);
  bool step(SimTime now) override;
  std::optional<SimTime> wakeAt() const override;

  Stage stage() const { return stage_; }
  bool done() const { return stage_ == Stage::kDone || stage_ == Stage::kFailed; }
  const Status& status() const { return status_; }

 private:
  enum class Sub : std::uint8_t { kStart, kWait, kEepromCommand, kEepromPoll };

  void enter(Stage stage, SimTime now);
  void fail(Status status);
  bool stepIdentity(SimTime now);
  bool stepStateChange(AlState target, Stage next, SimTime now);
  void queueEepromRead(std::uint32_t word);

  Transport& transport_;
  SlaveInfo& slave_;
  const ProcessImageLayout& layout_;
  StateChangeOptions options_;
  Stage stage_{Stage::kDone};
  Sub sub_{Sub::kStart};
  Status status_;
  SimTime deadline_{0};
  DatagramBatch batch_;
  std::vector<SlaveInfo> one_;  // the slave alone, for a StateChangeTask
  std::unique_ptr<StateChangeTask> change_;
  std::uint32_t eepromWord_{0};
  std::vector<std::uint8_t> identity_;  // EEPROM bytes from word 0x08
};

std::string_view toString(SlaveRecoveryTask::Stage stage);

}  // namespace ecsim::master
