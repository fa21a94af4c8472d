// Cyclic health and recovery: what the master knows, cycle by cycle, about each slave, and
// the events it reports. The HealthMonitor runs after every cycle (Master::cycle()):
//
//   watch     every `statusInterval` cycles, and at once after a cycle with a lost frame or a
//             working-counter error, FPRD 0x0130-0x0135 (AL status and code) of every slave;
//             the reads share frames and are answered while the next cycles run
//   lost      a slave that does not answer `lostAfter` reads in a row is reported lost
//             ("slave 3 (0x1004 'DO1') lost at cycle 1002"); the working counters it
//             contributed are taken out of the cyclic datagrams' expectation, so the others
//             keep running without errors
//   returned  a lost slave that answers again at its station address, or that answers at its
//             position with station address 0 (it was power-cycled: APRD 0x0010), is
//             reconfigured by a SlaveRecoveryTask stepped once per cycle, without stopping the
//             cycle; while it is on its way its contribution to the WKC may or may not be
//             there, both are accepted
//   error     a slave that shows an AL error or a state below OP (an SM watchdog, 0x001B, took
//             it to SAFEOP+ERROR) is acknowledged and brought back to OP the same way
//   failed    a recovery that fails (another device, an EEPROM checksum error, a mailbox that
//             does not answer, an SDO abort) is reported with its reason and tried again every
//             `retryAfter` cycles; a retry that fails for the same reason is not reported again
//             (SlaveHealth::failedAttempts counts them), one that succeeds is "back in OP"
//
// With MasterOptions::recovery false the monitor only counts: nothing is read, nothing is
// reconfigured, and every missing working counter is a WKC error.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "master/batch.hpp"
#include "master/cyclic.hpp"
#include "master/process_image.hpp"
#include "master/recovery.hpp"
#include "master/slave_info.hpp"
#include "master/transport.hpp"

namespace ecsim::master {

struct HealthOptions {
  std::uint64_t statusInterval{100};  // cycles between routine AL status reads
  unsigned lostAfter{2};              // status reads unanswered in a row
  SimTime recoveryTimeout{10 * kNsPerSecond};
  // A failed recovery is tried again after this many cycles.
  std::uint64_t retryAfter{1000};
};

enum class SlaveCondition : std::uint8_t {
  kOperational,  // in OP, answering
  kLost,         // not answering
  kRecovering,   // answering again (or in error), being brought back to OP
  kFailed,       // recovery failed (identity differs, refused); tried again later
};
std::string_view toString(SlaveCondition condition);

struct SlaveHealth {
  std::size_t position{0};
  std::uint16_t station{0};
  std::string name;
  SlaveCondition condition{SlaveCondition::kOperational};
  std::uint16_t alStatus{0};  // as last read
  std::uint16_t alStatusCode{0};
  std::uint64_t lostCount{0};
  std::uint64_t recoveredCount{0};
  std::uint64_t errorCount{0};      // AL errors seen while it answered
  std::uint64_t failedAttempts{0};  // recoveries that failed (each retry counts)
  std::uint64_t lastEventCycle{0};
};

struct MasterHealth {
  std::uint64_t cycles{0};
  // Frames the network never returned (Transport: given up, no answer since). A cyclic frame
  // answered after its cycle gave up on it is late, not lost; that cycle itself failed
  // (CyclicStatistics::framesLost counts such frames per cycle).
  std::uint64_t framesLost{0};
  std::uint64_t framesLate{0};  // answered after their deadline, or after being given up
  std::uint64_t wkcErrors{0};
  std::uint64_t cyclesWithErrors{0};
  std::uint64_t slavesLost{0};  // events
  std::uint64_t slavesRecovered{0};
  // Cable redundancy (Transport::setRedundantLink): what the last frame saw, and how often the
  // ring broke.
  RingState ring{RingState::kNone};
  std::uint64_t ringBreaks{0};
  std::vector<SlaveHealth> slaves;
  bool allOperational() const;
};

enum class MasterEventKind : std::uint8_t {
  kSlaveLost,
  kSlaveReturned,   // answering again at its station address
  kSlaveReset,      // answering at its position with station address 0 (power cycle)
  kSlaveError,      // AL error or state below OP
  kSlaveRecovered,  // back in OP
  kRecoveryFailed,
  kRingBroken,  // redundancy: frames come back at the primary port (position: the last slave
                // the primary port reaches)
  kRingWhole,   // redundancy: frames come round to the second port again
};
std::string_view toString(MasterEventKind kind);

struct MasterEvent {
  MasterEventKind kind{MasterEventKind::kSlaveLost};
  std::uint64_t cycle{0};
  SimTime time{0};
  std::size_t position{0};
  std::string text;  // "slave 3 (0x1004 'DO1') lost at cycle 1002"
};

class HealthMonitor {
 public:
  // All references must outlive the monitor; `layout` is the one `cyclic` was built from.
  // `setup` says what a recovered slave is given besides its mailbox and process-data SMs and
  // FMMUs (null: nothing; the Master gives a MasterSlaveSetup).
  HealthMonitor(Transport& transport, std::vector<SlaveInfo>& slaves,
                const ProcessImageLayout& layout, CyclicExchange& cyclic, bool recovery,
                HealthOptions options = {}, StateChangeOptions state = {},
                std::unique_ptr<SlaveSetup> setup = nullptr, MailboxOptions mailbox = {});

  // After each finished cycle (`cycle` counts from 1). Queues datagrams, steps recoveries;
  // never blocks.
  void afterCycle(const CycleResult& result, std::uint64_t cycle, SimTime now);

  const std::vector<MasterEvent>& events() const { return events_; }
  void clearEvents() { events_.clear(); }
  MasterHealth health(const TransportCounters& transport) const;
  SlaveCondition condition(std::size_t position) const {
    return slaves_[position].health.condition;
  }

 private:
  struct Watch {
    SlaveHealth health;
    unsigned misses{0};
    std::uint64_t retryAt{0};
    std::string lastFailure;  // the reason last reported
    std::unique_ptr<SlaveRecoveryTask> recovery;
  };

  void queueStatusReads();
  void takeStatusReads(std::uint64_t cycle, SimTime now);
  void takeProbes(std::uint64_t cycle, SimTime now);
  void startRecovery(std::size_t position, SlaveRecoveryTask::Stage first, SimTime now);
  void markRecovered(std::size_t position, std::uint64_t cycle, SimTime now);
  void event(MasterEventKind kind, std::size_t position, std::uint64_t cycle, SimTime now,
             const std::string& what);
  void updateExpectations();

  Transport& transport_;
  RingState ringSeen_{RingState::kNone};
  void watchRing(std::uint64_t cycle, SimTime now);
  std::vector<SlaveInfo>& slaveInfos_;
  const ProcessImageLayout& layout_;
  CyclicExchange& cyclic_;
  bool recovery_;
  HealthOptions options_;
  StateChangeOptions state_;
  std::unique_ptr<SlaveSetup> setup_;
  MailboxOptions mailbox_;
  std::vector<Watch> slaves_;
  DatagramBatch reads_;  // one per slave, made once; the first readPositions_.size() in use
  bool readsOut_{false};
  DatagramBatch probes_;  // APRD 0x0010 of lost slaves, by position; like reads_
  std::vector<std::size_t> probed_;
  bool probesOut_{false};
  std::uint64_t lastRead_{0};
  bool suspicious_{false};
  std::vector<MasterEvent> events_;
  std::uint64_t slavesLost_{0};
  std::uint64_t slavesRecovered_{0};
  std::vector<std::size_t> readPositions_;
};

}  // namespace ecsim::master
