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

TEST(DcRecoveryMathTest, OnlySlavesSetUpForDcGetAStep) {
  std::vector<master::SlaveInfo> slaves(4);
  for (std::size_t i = 0; i < slaves.size(); ++i) {
    slaves[i].position = i;
    slaves[i].station = static_cast<std::uint16_t>(0x1001 + i);
  }
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
  EXPECT_FALSE(master::dcRecoveryFor(setup, slaves, 1, kNsPerMs)) << "the reference itself";
  auto plain = master::dcRecoveryFor(setup, slaves, 2, kNsPerMs);
  ASSERT_TRUE(plain);
  EXPECT_EQ(plain->referenceStation, 0x1002);
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

// ---- a power-cycled drive on the demo line -----------------------------------------------------

enum : std::size_t { kCoupler, kDi, kDo, kAi, kDrive1, kDrive2, kCount };

class DcRecoveryTest : public ::testing::Test {
 protected:
  void SetUp() override {
    addDemoSlaves(net_, 2);
    net_.segment().setClock(kDrive1, 3'000'000, 40.0);
    net_.segment().setClock(kDrive2, -7'000'000, -60.0);
    net_.start();
    master::MasterOptions options;
    options.dc.enable = true;
    options.dc.staticDriftFrames = 1000;
    master_ = std::make_unique<master::Master>(net_.masterLink(), net_.bus(), options);
    auto status = master_->start();
    ASSERT_TRUE(status.ok()) << status.error().message();
    const DcSetup& setup = master_->dcSetup();
    ASSERT_EQ(setup.sync0, (std::vector<std::size_t>{kDrive1, kDrive2}));
    ASSERT_TRUE(setup.reference);
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
    for (const auto& e : master_->events()) {
      if (e.kind == kind && e.position == position) return &e;
    }
    return nullptr;
  }
  std::string eventLog() const {
    std::string s;
    for (const auto& e : master_->events()) s += e.text + "\n";
    return s;
  }
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

}  // namespace
}  // namespace ecsim::testing
