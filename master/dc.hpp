// Distributed clocks set-up by the master, as a step-driven task (ESC datasheet section I §9.1,
// /work/shared/notes/ethercat-facts.md §C.4; the order SOEM uses, notes/soem-interop.md §3.3):
//
//   1. BWR 0x0900: every ESC latches the local time at which the frame reached each port
//      (0x0900-0x090F) and its processing unit (0x0918);
//   2. FPRD the latches of every DC slave;
//   3. propagation delays from the port receive times (computeDcDelays: lines and trees,
//      ports visited in the order 0-3-1-2 as docs/timing.md describes), relative to the
//      reference clock (the first DC slave); FPWR 0x0928 delay and 0x0920 offset (master time
//      at the latch minus the slave's 0x0918), BWR 0x0930 resets the drift filters;
//   4. static drift compensation: `staticDriftFrames` FRMW of the reference's 0x0910, one per
//      frame. Each only nudges the slaves' drift filters, so a lost one is counted
//      (DcSetup::driftFramesLost) and the next sent, as a frame lost in the cyclic FRMW is; only
//      `maxDriftFramesLostInRow` lost one after the other (the reference clock gone) fail;
//   5. SYNC0: for the slaves that ask for it, FPRD the reference's system time, then FPWR
//      0x0981 = 0, 0x09A0 cycle time, 0x0990 start time (a whole number of cycles at least
//      `sync0StartDelay` ahead, plus the shift) and 0x0980/0x0981 = AssignActivate (0x0300:
//      cyclic unit + SYNC0).
//
// Afterwards the cyclic frame carries an FRMW of the reference's 0x0910 (CyclicExchange::
// setDcReference) so the slaves' drift control loops keep running; readDcSyncError() reads
// back every slave's 0x092C to report the achieved synchronisation.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "master/batch.hpp"
#include "master/bus.hpp"
#include "master/slave_info.hpp"
#include "master/transport.hpp"

namespace ecsim::master {

struct DcOptions {
  bool enable{false};  // Master::start() runs the DC set-up
  std::size_t staticDriftFrames{15000};
  // Static drift frames lost one after the other (each after every retry) before the set-up
  // fails: one lost frame of 15,000 is a busy host or a noisy cable, not a missing reference.
  std::size_t maxDriftFramesLostInRow{3};
  bool activateSync0{true};
  SimTime sync0Cycle{0};  // 0: MasterOptions::cycleTime
  SimTime sync0Shift{0};
  SimTime sync0StartDelay{100 * kNsPerMs};
  // A recovered slave's SYNC0 starts on the running grid at least this long after the
  // reference's system time when the recovery reads it (DcRecovery::sync0Margin).
  SimTime recoverySync0Margin{10 * kNsPerMs};
  // The master's time written as every slave's system time at the latch (ns since 2000);
  // nullopt: the bus clock's time at the latch.
  std::optional<std::uint64_t> masterTime;
};

// Port receive times 0x0900-0x090F of one slave (local clock, 32 bits each).
using PortTimes = std::array<std::uint32_t, 4>;

// Propagation delay of every slave from slave 0's port 0, from the receive times latched by one
// frame: slave i hangs on port P of its parent (slaves[i].parent), children taking the parent's
// open ports (activePorts) in the order 3, 1, 2 by position. For a child on port P,
//   delay = delay(parent) + (t_parent[previous open port] - t_parent[0])
//           + ((t_parent[P] - t_parent[previous open port]) - loop(child)) / 2
// where loop(child) = t_child[its last open port] - t_child[0] (0 for an end slave): half the
// time the frame spent below port P outside the child's own loop is the way down. Exact when an
// ESC's processing and forwarding delays are equal (the model's defaults).
std::vector<SimTime> computeDcDelays(const std::vector<SlaveInfo>& slaves,
                                     const std::vector<PortTimes>& times);

struct DcSetup {
  std::optional<std::size_t> reference;       // position of the reference clock
  std::vector<bool> dc;                       // per slave: has a DC unit (0x0008 bit 2)
  std::vector<SimTime> delays;                // per slave, relative to the reference (0x0928)
  std::vector<std::uint64_t> offsets;         // per slave (0x0920)
  std::vector<std::size_t> sync0;             // positions SYNC0 was activated for
  std::vector<std::uint16_t> assignActivate;  // per slave: the 0x0980 word written (0: none)
  std::uint64_t sync0Start{0};                // 0x0990 written
  SimTime sync0Cycle{0};
  std::size_t driftFramesLost{0};  // static drift FRMWs given up after every retry
};

class DcInitTask final : public Task {
 public:
  // `assignActivate[i]`: the 0x0980 word for slave i (0: no SYNC0 for it).
  DcInitTask(Transport& transport, std::vector<SlaveInfo>& slaves, DcOptions options,
             SimTime cycleTime, std::vector<std::uint16_t> assignActivate);

  void start(SimTime now);
  bool step(SimTime now) override;
  const Status& status() const { return status_; }
  const DcSetup& result() const { return setup_; }

 private:
  enum class Phase { kLatch, kRead, kWrite, kDrift, kSync0Time, kSync0, kDone };
  bool fail(Error error);
  void queue();
  void enter(Phase phase, SimTime now);

  Transport& transport_;
  std::vector<SlaveInfo>& slaves_;
  DcOptions options_;
  SimTime cycleTime_;
  std::vector<std::uint16_t> assignActivate_;
  DcSetup setup_;
  Phase phase_{Phase::kDone};
  DatagramBatch batch_;
  std::size_t driftSent_{0};
  std::size_t driftLostInRow_{0};
  std::uint64_t masterTime_{0};
  Status status_;
};

// What a recovery needs to give a power-cycled DC slave its clock back (SlaveRecoveryTask's
// stage kDc, in PREOP before PREOP->SAFEOP). The time comes from a "source" clock that kept
// running: the reference clock, or, when the slave is the reference clock itself, the first
// other slave the master set up for DC (its system time is the reference's own, the delay
// between them accounted for), so that the recovered reference continues the system time the
// others run on instead of starting over from its power-up.
//   1. FPWR 0x0930 = 0x1000 (its drift loop restarted: a power-cycled slave has no station
//      address, so each FRMW of the reference time wrote it as one of the others), then BWR
//      0x0900: every ESC latches its local time at that datagram in 0x0918, the source and this
//      slave at the same point of the same frame, as the start-up's latch does;
//   2. FPRD the source's 0x0918-0x0927 (latched local time and its offset: its system time
//      at the latch) and the slave's 0x0918;
//   3. FPWR 0x0928 = delay, 0x0920 = recoveredDcOffset(), 0x0930 = 0x1000 (restart the drift
//      filter, as start-up does); with SYNC0: 0x0981 = 0, 0x09A0 = cycle, 0x0990 =
//      nextSync0Time(grid, source's system time at the latch + margin), 0x0980/0x0981 =
//      assignActivate.
struct DcRecovery {
  std::uint16_t sourceStation{0};  // the running clock the time is taken from
  SimTime sourceDelay{0};          // its 0x0928 (0 for the reference clock)
  SimTime delay{0};                // 0x0928 of the recovered slave, from DcSetup::delays
  bool sync0{false};
  std::uint16_t assignActivate{0};  // 0x0980 word
  std::uint64_t sync0Start{0};      // the grid the others run on: sync0Start + k * sync0Cycle
  SimTime sync0Cycle{0};
  SimTime sync0Margin{10 * kNsPerMs};
};

// The recovery's data for the slave at `position`; nullopt when the master did not set it up
// for distributed clocks (no DC set-up, no DC unit), or when it is the reference clock and no
// other slave has a clock to take the time from.
std::optional<DcRecovery> dcRecoveryFor(const DcSetup& setup, const std::vector<SlaveInfo>& slaves,
                                        std::size_t position, SimTime sync0Margin);

// 0x0920 for a slave whose local time was `slaveLocal` when one datagram passed it, the
// source clock's local time being `sourceLocal` (offset `sourceOffset`) when the same datagram
// passed the source: `delay` = the slave's 0x0928 minus the source's, the time the datagram
// took from the source to the slave (negative when the slave lies before the source, as the
// reference clock does). Its system time then equals the source's at once, modulo 2^64 (the
// start-up's offsets leave a lag of the delay for the drift loop to take up).
std::uint64_t recoveredDcOffset(std::uint64_t sourceLocal, std::uint64_t sourceOffset,
                                std::uint64_t slaveLocal, SimTime delay);

// The first point of the grid gridStart + k * cycle (k >= 0) at or after `earliest`; gridStart
// itself when cycle is 0 or earliest is not after it.
std::uint64_t nextSync0Time(std::uint64_t gridStart, SimTime cycle, std::uint64_t earliest);

// The largest |system time difference| (0x092C, sign-magnitude) over the DC slaves other than
// the reference, as a batch to queue and a function to read it once answered.
void addDcSyncErrorReads(DatagramBatch& batch, const std::vector<SlaveInfo>& slaves,
                         const DcSetup& setup);
Result<SimTime> dcSyncErrorFrom(const DatagramBatch& batch);

}  // namespace ecsim::master
