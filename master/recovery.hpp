// Bringing one slave back to OP while the others keep cycling: a non-blocking task that the
// master steps once per cycle between its cyclic frames (IgH's fsm discipline). Where it
// starts depends on what the slave shows:
//
//   kAddress   the slave answers at its position but not at its station address (a power
//              cycle cleared it): APWR 0x0010 = station address
//   kIdentity  EEPROM words 0x08-0x0B (vendor id, product code) through 0x0502-0x050F must
//              match what the scan found, or the task fails naming both identities; an EEPROM
//              whose checksum is wrong (0x0502 bit 11: the ESC did not load its configuration
//              and the slave cannot leave INIT) fails the task saying so
//   kMailbox   mailbox SyncManagers as at start-up, the setup's register writes for PREOP,
//              then INIT -> PREOP
//   kDc        for a slave the master set up for distributed clocks (SlaveSetup::dcRecovery):
//              its delay 0x0928, a new offset 0x0920 from one latch of the reference's and its
//              local time, the drift filter restarted, and SYNC0 on the running grid (see
//              DcRecovery in master/dc.hpp); nothing for the others. A drive in DC-synchronous
//              mode would refuse SAFEOP (0x0030) or run unsynchronised without it
//   kProcess   the setup's writes for SAFEOP (CoE downloads: the PDO assignment the master
//              found or configured, an ENI's init commands), the SM and FMMU settings of the
//              slave's part of the process image, then PREOP -> SAFEOP
//   kOp        the setup's writes for OP, SAFEOP -> OP (an error shown is acknowledged with the
//              request), while the cyclic frames keep valid outputs flowing
//
// A power-cycled slave lost everything the master wrote (RAM): its PDO assignment is its
// default again, which may not be what the master configured. What the master configured comes
// from a SlaveSetup (the master's own choice or its ENI), not from the Master itself.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "master/batch.hpp"
#include "master/bus.hpp"
#include "master/coe_client.hpp"
#include "master/dc.hpp"
#include "master/eni_config.hpp"
#include "master/pdo_config.hpp"
#include "master/process_image.hpp"
#include "master/slave_info.hpp"
#include "master/state_change.hpp"
#include "master/transport.hpp"

namespace ecsim::master {

// One write the master makes to configure a slave for a transition: a register write (an
// FPWR at the slave's station address, or an ENI register command as it is written) or a CoE
// SDO download.
struct SetupWrite {
  enum class Kind : std::uint8_t { kRegister, kSdo };
  Kind kind{Kind::kSdo};
  std::uint16_t index{0};  // register address or object index
  std::uint8_t subindex{0};
  bool completeAccess{false};
  std::vector<std::uint8_t> data;
  std::string what;  // "PDO assignment 0x1C12:01", "bus.xml line 40": names it in errors
};

// The configuration a slave is given back by a recovery, per transition target: PREOP (done in
// INIT, after the mailbox SMs: register writes only), SAFEOP (done in PREOP before the
// process-data SMs and FMMUs: CoE downloads and register writes) and OP (done in SAFEOP).
class SlaveSetup {
 public:
  virtual ~SlaveSetup() = default;
  virtual std::vector<SetupWrite> writesFor(const SlaveInfo& slave, AlState target) const = 0;
  // Its distributed clock, for a slave the master set up for DC (nullopt: none).
  virtual std::optional<DcRecovery> dcRecovery(const SlaveInfo& slave) const {
    (void)slave;
    return std::nullopt;
  }
  // The position of the reference clock, when the master set up distributed clocks: while it
  // is out, the cyclic distribution of its time is held (CyclicExchange::holdDcDistribution).
  virtual std::optional<std::size_t> dcReference() const { return std::nullopt; }
};

// The CoE downloads that give a slave the PDO assignment `data` describes (0x1C10+SM: sub 0
// cleared, the PDOs, then the count), for the PDOs found through CoE; nothing otherwise.
std::vector<SetupWrite> pdoAssignmentWrites(const SlaveProcessData& data);

// The master's own SlaveSetup: for a slave configured from an ENI, its init commands (register
// writes, CoE downloads) of INIT->PREOP and PREOP->SAFEOP (and SAFEOP->OP), the CoE ones of
// INIT->PREOP once PREOP is reached, as Master::requestState() runs them; otherwise the PDO
// assignment the master found through CoE. With `dc` (and `slaves`, the bus it was made for),
// the DC set-up of the slaves it covers. All references and pointers must outlive it.
class MasterSlaveSetup final : public SlaveSetup {
 public:
  MasterSlaveSetup(const std::vector<SlaveProcessData>& processData,
                   const std::optional<MasterConfig>& config, const DcSetup* dc = nullptr,
                   const std::vector<SlaveInfo>* slaves = nullptr,
                   SimTime sync0Margin = 10 * kNsPerMs)
      : processData_(processData),
        config_(config),
        dc_(dc),
        slaves_(slaves),
        sync0Margin_(sync0Margin) {}
  std::vector<SetupWrite> writesFor(const SlaveInfo& slave, AlState target) const override;
  std::optional<DcRecovery> dcRecovery(const SlaveInfo& slave) const override;
  std::optional<std::size_t> dcReference() const override {
    return dc_ != nullptr ? dc_->reference : std::nullopt;
  }

 private:
  const std::vector<SlaveProcessData>& processData_;
  const std::optional<MasterConfig>& config_;
  const DcSetup* dc_;
  const std::vector<SlaveInfo>* slaves_;
  SimTime sync0Margin_;
};

class SlaveRecoveryTask final : public Task {
 public:
  enum class Stage : std::uint8_t {
    kAddress,
    kIdentity,
    kMailbox,
    kDc,
    kProcess,
    kOp,
    kDone,
    kFailed
  };

  // `slave` is the master's record (updated as the task learns the AL status); `layout` the
  // process image whose SM/FMMU settings the slave gets back. Both must outlive the task.
  // `setup` (may be null: nothing beyond mailbox and process-data SMs/FMMUs) must outlive it.
  SlaveRecoveryTask(Transport& transport, SlaveInfo& slave, const ProcessImageLayout& layout,
                    StateChangeOptions options = {}, const SlaveSetup* setup = nullptr,
                    MailboxOptions mailbox = {});

  void start(Stage first, SimTime now, SimTime timeout);
  bool step(SimTime now) override;
  std::optional<SimTime> wakeAt() const override;

  Stage stage() const { return stage_; }
  bool done() const { return stage_ == Stage::kDone || stage_ == Stage::kFailed; }
  const Status& status() const { return status_; }

 private:
  enum class Sub : std::uint8_t {
    kStart,
    kWait,
    kWrites,
    kEepromCommand,
    kEepromPoll,
    kAlias,
    kDeviceId,
    kDcLatch,
    kDcRead,
    kDcWrite
  };

  void enter(Stage stage, SimTime now);
  void fail(Status status);
  bool stepIdentity(SimTime now);
  bool stepIdentification(SimTime now);
  bool stepStateChange(AlState target, Stage next, SimTime now);
  void queueEepromRead(std::uint32_t word);
  void startWrites(AlState target);
  bool stepWrites(SimTime now);
  void queueProcessDataSetup();
  bool stepDc(SimTime now);

  Transport& transport_;
  SlaveInfo& slave_;
  const ProcessImageLayout& layout_;
  StateChangeOptions options_;
  const SlaveSetup* setup_;
  MailboxOptions mailbox_;
  Stage stage_{Stage::kDone};
  Sub sub_{Sub::kStart};
  Status status_;
  SimTime deadline_{0};
  DatagramBatch batch_;
  std::vector<SlaveInfo> one_;  // the slave alone, for a StateChangeTask
  std::unique_ptr<StateChangeTask> change_;
  std::uint32_t eepromWord_{0};
  std::vector<std::uint8_t> identity_;  // EEPROM bytes from word 0x08
  std::vector<SetupWrite> writes_;
  std::size_t write_{0};
  bool writeQueued_{false};
  std::unique_ptr<SdoTask> sdo_;
  std::optional<DcRecovery> dc_;
};

std::string_view toString(SlaveRecoveryTask::Stage stage);

}  // namespace ecsim::master
