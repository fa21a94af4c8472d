// A power-cycled DC slave gets its distributed clock back (SlaveRecoveryTask stage kDc,
// master/dc.hpp DcRecovery): the demo line with two drives runs with DC and SYNC0 for the
// drives; Drive2 is power-cycled while cycle() runs and comes back to OP with SYNC0 active on the
// grid the others run on, its system time within 100 ns of the reference's, its SYNC0 pulses at
// the same instants as Drive1's. Also the arithmetic: start times on the grid and in the future,
// the offset that aligns the system times at once, which slaves get a DC step.
#include <gtest/gtest.h>

#include <cstdlib>

#include "master/dc.hpp"
#include "master/master.hpp"
#include "master/recovery.hpp"
#include "tests/master/bring_up.hpp"

namespace ecsim::testing {
namespace {

using master::DcRecovery;
using master::DcSetup;
using master::MasterEventKind;

// ---- arithmetic --------------------------------------------------------------------------------

TEST(DcRecoveryMathTest, Sync0StartLiesOnTheGridAndNotBeforeTheEarliestTime) {
  const std::uint64_t grid = 757'382'400'000'000'000ull + 250'000;  // 2024 in ns since 2000
  const SimTime cycle = 2 * kNsPerMs;
  for (std::uint64_t earliest : {grid + 1, grid + 1'999'999, grid + 2'000'000, grid + 2'000'001,
                                 grid + std::uint64_t{123'456'789'012}}) {
    const std::uint64_t t = master::nextSync0Time(grid, cycle, earliest);
    EXPECT_EQ((t - grid) % 2'000'000u, 0u) << earliest;
    EXPECT_GE(t, earliest);
    EXPECT_LT(t - earliest, 2'000'000u) << "the first grid point, not a later one";
  }
  EXPECT_EQ(master::nextSync0Time(grid, cycle, grid + 2'000'000), grid + 2'000'000);
  // Before the grid's first pulse (or without a cycle) the grid's start is the answer.
  EXPECT_EQ(master::nextSync0Time(grid, cycle, grid - 5), grid);
  EXPECT_EQ(master::nextSync0Time(grid, 0, grid + 5), grid);
}

TEST(DcRecoveryMathTest, OffsetMakesTheSlavesSystemTimeTheReferencesAtOnce) {
  // The datagram passed the reference at local time 1'000'000 (offset 5e17: system time
  // 5e17 + 1e6) and the slave 700 ns later at its local time 42: its system time then must be
  // the reference's 700 ns later.
  const std::uint64_t offset =
      master::recoveredDcOffset(1'000'000, 500'000'000'000'000'000ull, 42, 700);
  EXPECT_EQ(42 + offset, 500'000'000'000'000'000ull + 1'000'000 + 700);
  // Modulo 2^64, as the ESC adds it: a slave whose local time is ahead of the system time.
  const std::uint64_t big = ~std::uint64_t{0} - 10;
  EXPECT_EQ(big + master::recoveredDcOffset(100, 0, big, 5), std::uint64_t{105});
}

// Four slaves at stations 0x1001..0x1004.
std::vector<master::SlaveInfo> fourSlaves() {
  std::vector<master::SlaveInfo> slaves(4);
  for (std::size_t i = 0; i < slaves.size(); ++i) {
    slaves[i].position = i;
    slaves[i].station = static_cast<std::uint16_t>(0x1001 + i);
  }
  return slaves;
}

TEST(DcRecoveryMathTest, OnlySlavesSetUpForDcGetAStep) {
  const std::vector<master::SlaveInfo> slaves = fourSlaves();
  DcSetup setup;
  EXPECT_FALSE(master::dcRecoveryFor(setup, slaves, 2, kNsPerMs)) << "no DC set-up";
  setup.reference = 1;
  setup.dc = {false, true, true, true};
  setup.delays = {0, 0, 1100, 2200};
  setup.sync0 = {3};
  setup.assignActivate = {0, 0, 0, 0x0300};
  setup.sync0Start = 1'000'000'000;
  setup.sync0Cycle = kNsPerMs;
  EXPECT_FALSE(master::dcRecoveryFor(setup, slaves, 0, kNsPerMs)) << "no DC unit";
  auto plain = master::dcRecoveryFor(setup, slaves, 2, kNsPerMs);
  ASSERT_TRUE(plain);
  EXPECT_EQ(plain->sourceStation, 0x1002) << "the time comes from the reference clock";
  EXPECT_EQ(plain->sourceDelay, 0);
  EXPECT_EQ(plain->delay, 1100);
  EXPECT_FALSE(plain->sync0);
  auto synced = master::dcRecoveryFor(setup, slaves, 3, 7 * kNsPerMs);
  ASSERT_TRUE(synced);
  EXPECT_EQ(synced->delay, 2200);
  EXPECT_TRUE(synced->sync0);
  EXPECT_EQ(synced->assignActivate, 0x0300);
  EXPECT_EQ(synced->sync0Start, 1'000'000'000u);
  EXPECT_EQ(synced->sync0Cycle, kNsPerMs);
  EXPECT_EQ(synced->sync0Margin, 7 * kNsPerMs);
}

TEST(DcRecoveryMathTest, TheReferenceClockTakesTheTimeFromTheNextClock) {
  const std::vector<master::SlaveInfo> slaves = fourSlaves();
  DcSetup setup;
  setup.reference = 1;
  setup.dc = {false, true, true, true};
  setup.delays = {0, 0, 1100, 2200};
  auto reference = master::dcRecoveryFor(setup, slaves, 1, kNsPerMs);
  ASSERT_TRUE(reference);
  EXPECT_EQ(reference->sourceStation, 0x1003) << "the first other slave set up for DC";
  EXPECT_EQ(reference->sourceDelay, 1100);
  EXPECT_EQ(reference->delay, 0);
  // The reference alone has nobody to take the time from.
  setup.dc = {false, true, false, false};
  EXPECT_FALSE(master::dcRecoveryFor(setup, slaves, 1, kNsPerMs));
}

TEST(DcRecoveryMathTest, AClockBeforeItsSourceLagsBehindItByTheDelay) {
  // The datagram passed the recovered reference at its local time 50 and the source 1100 ns
  // later at system time 9e17 + 2000: the reference's system time at its own latch was
  // 1100 ns earlier than the source's.
  const std::uint64_t offset =
      master::recoveredDcOffset(2'000, 900'000'000'000'000'000ull, 50, 0 - 1100);
  EXPECT_EQ(50 + offset, 900'000'000'000'000'000ull + 2'000 - 1'100);
}

// ---- a power-cycled drive on the demo line -----------------------------------------------------

enum : std::size_t { kCoupler, kDi, kDo, kAi, kDrive1, kDrive2, kCount };

class DcRecoveryTest : public ::testing::Test {
 protected:
  void SetUp() override {
    addDemoSlaves(net_, 2);
    net_.segment().setClock(kDrive1, 3'000'000, 40.0);
    net_.segment().setClock(kDrive2, -7'000'000, -60.0);
    startMaster();
    ASSERT_EQ(master_->dcSetup().sync0, (std::vector<std::size_t>{kDrive1, kDrive2}));
  }
  void startMaster() {
    net_.start();
    master::MasterOptions options;
    options.dc.enable = true;
    options.dc.staticDriftFrames = 1000;
    master_ = std::make_unique<master::Master>(net_.masterLink(), net_.bus(), options);
    auto status = master_->start();
    ASSERT_TRUE(status.ok()) << status.error().message();
    ASSERT_TRUE(master_->dcSetup().reference);
    master_->resetStatistics();
  }
  void run(std::uint64_t n) {
    for (std::uint64_t i = 0; i < n; ++i) {
      const SimTime next = net_.clock().now() + kNsPerMs;
      (void)master_->cycle();
      while (net_.clock().now() < next) net_.bus().wait(next);
    }
  }
  const master::MasterEvent* findEvent(MasterEventKind kind, std::size_t position) const {
    return testing::findEvent(master_->events(), kind, position);
  }
  std::string eventLog() const { return testing::eventLog(master_->events()); }
  slavesim::Esc& esc(std::size_t i) { return net_.segment().slave(i).esc(); }
  // |0x092C| as the ESC last computed it (sign-magnitude).
  SimTime difference(std::size_t i) { return esc(i).reg32(0x092C) & 0x7FFFFFFF; }
  // The next SYNC0 pulse time 0x0990 as the master reads it.
  std::uint64_t nextPulse(std::size_t i) {
    auto r = master_->readRegisters(i, 0x0990, 8);
    EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message());
    return r.ok() ? readLe64(*r, 0) : 0;
  }
  // The simulation time at which drive i's SYNC0 unit fires for system time `t`.
  SimTime pulseInstant(std::size_t i, std::uint64_t t) {
    return esc(i).dcClock().globalTime(static_cast<SimTime>(t - esc(i).reg64(0x0920)));
  }
  // Slave i's system time now: its local time plus its offset 0x0920.
  std::int64_t systemTime(std::size_t i) {
    const auto local = static_cast<std::uint64_t>(esc(i).dcClock().localTime(net_.clock().now()));
    return static_cast<std::int64_t>(local + esc(i).reg64(0x0920));
  }

  SimNetwork net_;
  std::unique_ptr<master::Master> master_;
};

TEST_F(DcRecoveryTest, PowerCycledDriveGetsItsClockAndSync0BackOnTheRunningGrid) {
  run(200);
  ASSERT_EQ(esc(kDrive2).reg8(0x0981), 0x03);
  const DcSetup& setup = master_->dcSetup();
  const auto cycle = static_cast<std::uint64_t>(setup.sync0Cycle);
  ASSERT_GT(cycle, 0u);

  auto& drive2 = net_.segment().slave(kDrive2);
  drive2.powerOff();
  drive2.powerOn(net_.clock().now());
  ASSERT_EQ(esc(kDrive2).reg8(0x0981), 0x00) << "the power cycle stopped SYNC0";
  ASSERT_EQ(esc(kDrive2).reg32(0x0928), 0u);

  for (int i = 0; i < 3000 && findEvent(MasterEventKind::kSlaveRecovered, kDrive2) == nullptr;
       ++i) {
    run(1);
  }
  ASSERT_NE(findEvent(MasterEventKind::kSlaveRecovered, kDrive2), nullptr) << eventLog();
  EXPECT_EQ(findEvent(MasterEventKind::kRecoveryFailed, kDrive2), nullptr) << eventLog();
  EXPECT_EQ(net_.segment().slave(kDrive2).state(), AlState::kOp);
  EXPECT_EQ(esc(kDrive2).reg32(0x0928), static_cast<std::uint32_t>(setup.delays[kDrive2]));
  EXPECT_EQ(esc(kDrive2).reg8(0x0981), 0x03) << "cyclic unit and SYNC0 active again";
  EXPECT_EQ(esc(kDrive2).reg32(0x09A0), static_cast<std::uint32_t>(cycle));

  run(300);  // the recovery's SYNC0 start lay at least 10 ms ahead; the loop has settled
  EXPECT_EQ(net_.segment().slave(kDrive2).state(), AlState::kOp);
  EXPECT_LT(difference(kDrive2), 100) << "|0x092C| of Drive2";
  EXPECT_LT(difference(kDrive1), 100) << "|0x092C| of Drive1, undisturbed";
  // Pulses have come (first pulse no longer pending) and 0x0990 advances on the grid.
  auto status = master_->readRegisters(kDrive2, 0x0984, 1);
  ASSERT_TRUE(status.ok());
  EXPECT_EQ((*status)[0] & 0x01, 0) << "0x0984: SYNC0 first pulse still pending";
  const std::uint64_t first = nextPulse(kDrive2);
  run(5);
  const std::uint64_t later = nextPulse(kDrive2);
  EXPECT_EQ((first - setup.sync0Start) % cycle, 0u) << first;
  EXPECT_EQ((later - setup.sync0Start) % cycle, 0u) << later;
  EXPECT_GE(later, first + 4 * cycle);
  // Drive1 and Drive2 fire together: the same grid point is the same instant within 100 ns.
  const std::uint64_t drive1Next = nextPulse(kDrive1);
  EXPECT_EQ((drive1Next - setup.sync0Start) % cycle, 0u) << drive1Next;
  const std::uint64_t t = std::max(drive1Next, later) + 10 * cycle;
  const SimTime apart = pulseInstant(kDrive2, t) - pulseInstant(kDrive1, t);
  EXPECT_LT(std::abs(apart), 100) << "SYNC0 at system time " << t;
  // And the cycle goes on without errors once all are back.
  master_->resetStatistics();
  run(100);
  EXPECT_EQ(master_->statistics().wkcErrors, 0u);
}

// ---- a power-cycled reference clock -----------------------------------------------------------

// Three drives in a line: the first is the reference clock, all three run SYNC0.
class DcReferenceRecoveryTest : public DcRecoveryTest {
 protected:
  void SetUp() override {
    for (const char* name : {"DriveA", "DriveB", "DriveC"}) {
      net_.segment().addSlave(makeDemoSlave(0x7201, name));
    }
    net_.segment().wireLine();
    net_.segment().setClock(0, 5'000'000, 30.0);
    net_.segment().setClock(1, 3'000'000, -40.0);
    net_.segment().setClock(2, -7'000'000, 60.0);
    startMaster();
    ASSERT_EQ(*master_->dcSetup().reference, 0u);
    ASSERT_EQ(master_->dcSetup().sync0, (std::vector<std::size_t>{0, 1, 2}));
  }
};

TEST_F(DcReferenceRecoveryTest, PowerCycledReferenceContinuesTheSystemTimeOfTheOthers) {
  run(200);
  const DcSetup& setup = master_->dcSetup();
  const auto cycle = static_cast<std::uint64_t>(setup.sync0Cycle);
  ASSERT_LT(std::abs(systemTime(0) - systemTime(1)), 100);

  auto& reference = net_.segment().slave(0);
  reference.powerOff();
  reference.powerOn(net_.clock().now());
  ASSERT_GT(std::abs(systemTime(0) - systemTime(1)), 10'000'000)
      << "the power cycle restarted the reference's clock";

  // Until the master notices, each FRMW still writes the others what the frame carried (the
  // same window as with any master). Once it has seen the reference lost, no time is
  // distributed (the FRMW goes as a NOP) until the reference has its offset back: its restarted
  // time never reaches the others' drift loops, which run on with what they learnt. Each write
  // of 0x0910 sets 0x092C, so a held distribution leaves 0x092C as it was.
  std::optional<std::pair<SimTime, SimTime>> atLoss;
  int writesWhileOut = 0;
  for (int i = 0; i < 3000 && findEvent(MasterEventKind::kSlaveRecovered, 0) == nullptr; ++i) {
    run(1);
    if (findEvent(MasterEventKind::kSlaveRecovered, 0) != nullptr) break;
    if (findEvent(MasterEventKind::kSlaveLost, 0) == nullptr) continue;
    const std::pair<SimTime, SimTime> now{difference(1), difference(2)};
    if (!atLoss) atLoss = now;
    if (now != *atLoss) ++writesWhileOut;
  }
  ASSERT_TRUE(atLoss) << "the master never reported the reference lost\n" << eventLog();
  EXPECT_EQ(writesWhileOut, 0) << "cycles in which the others got a time while the reference "
                                  "was out";
  ASSERT_NE(findEvent(MasterEventKind::kSlaveRecovered, 0), nullptr) << eventLog();
  EXPECT_EQ(findEvent(MasterEventKind::kRecoveryFailed, 0), nullptr) << eventLog();
  EXPECT_EQ(esc(0).reg8(0x0981), 0x03) << "cyclic unit and SYNC0 active again";

  // The reference continues the others' system time: no step for them, none for the grid.
  EXPECT_LT(std::abs(systemTime(0) - systemTime(1)), 100);
  run(300);
  EXPECT_LT(std::abs(systemTime(0) - systemTime(1)), 100);
  EXPECT_LT(std::abs(systemTime(0) - systemTime(2)), 100);
  EXPECT_LT(difference(1), 100) << "|0x092C| of DriveB";
  EXPECT_LT(difference(2), 100) << "|0x092C| of DriveC";
  const std::uint64_t referenceNext = nextPulse(0);
  const std::uint64_t otherNext = nextPulse(1);
  EXPECT_EQ((referenceNext - setup.sync0Start) % cycle, 0u) << referenceNext;
  const std::uint64_t t = std::max(referenceNext, otherNext) + 10 * cycle;
  EXPECT_LT(std::abs(pulseInstant(0, t) - pulseInstant(1, t)), 100) << "SYNC0 at " << t;
  master_->resetStatistics();
  run(100);
  EXPECT_EQ(master_->statistics().wkcErrors, 0u);
}

}  // namespace
}  // namespace ecsim::testing
