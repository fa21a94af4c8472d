// Cyclic health and recovery against the in-process simulator on virtual time: a line of
// ecsim's demo devices (examples/topologies/demo.xml without the second drive) runs at 1 ms;
// a cable is pulled and put back, a slave is power-cycled, a slave drops to SAFEOP+ERROR, and
// with recovery off the same faults stay errors. Also the latency histogram.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "master/health.hpp"
#include "master/histogram.hpp"
#include "master/master.hpp"
#include "tests/master/bring_up.hpp"

namespace ecsim::testing {
namespace {

using master::LatencyHistogram;
using master::MasterEventKind;
using master::SlaveCondition;

// ---- LatencyHistogram ---------------------------------------------------------------------

TEST(LatencyHistogramTest, BucketsAreExactBelow64AndContiguousAbove) {
  for (std::uint64_t v = 0; v < 64; ++v) EXPECT_EQ(LatencyHistogram::bucketOf(v), v);
  // Every bucket starts one past where the previous one ended, up to the last.
  for (std::size_t b = 1; b + 1 < LatencyHistogram::kBucketCount; ++b) {
    ASSERT_EQ(LatencyHistogram::bucketLowest(b), LatencyHistogram::bucketHighest(b - 1) + 1) << b;
    ASSERT_EQ(LatencyHistogram::bucketOf(LatencyHistogram::bucketLowest(b)), b);
    ASSERT_EQ(LatencyHistogram::bucketOf(LatencyHistogram::bucketHighest(b)), b);
  }
  // 64..127 in buckets of 2 ns, 1 ms in a bucket 1/32 of a power of two wide.
  EXPECT_EQ(LatencyHistogram::bucketOf(64), LatencyHistogram::bucketOf(65));
  EXPECT_NE(LatencyHistogram::bucketOf(65), LatencyHistogram::bucketOf(66));
  const std::size_t ms = LatencyHistogram::bucketOf(1'000'000);
  const auto width = LatencyHistogram::bucketHighest(ms) - LatencyHistogram::bucketLowest(ms) + 1;
  EXPECT_EQ(width, 1u << 14);  // 2^19 <= 1e6 < 2^20: 2^19 / 32
  EXPECT_EQ(LatencyHistogram::bucketOf(std::uint64_t{1} << 50), LatencyHistogram::kBucketCount - 1);
}

TEST(LatencyHistogramTest, PercentilesWithinOneBucketOfTheSortedSamples) {
  std::mt19937_64 random(7);
  std::lognormal_distribution<double> rtt(10.0, 0.5);  // around 22 us, long tail
  std::vector<SimTime> samples;
  LatencyHistogram h;
  for (int i = 0; i < 100'000; ++i) {
    const auto v = static_cast<SimTime>(rtt(random));
    samples.push_back(v);
    h.record(v);
  }
  std::sort(samples.begin(), samples.end());
  EXPECT_EQ(h.count(), samples.size());
  EXPECT_EQ(h.min(), samples.front());
  EXPECT_EQ(h.max(), samples.back());
  for (double f : {0.5, 0.9, 0.99, 0.999}) {
    const SimTime exact = samples[static_cast<std::size_t>(f * 100'000) - 1];
    const SimTime got = h.percentile(f);
    EXPECT_GE(got, exact) << f;
    EXPECT_LE(static_cast<double>(got), static_cast<double>(exact) * (1.0 + 1.0 / 32)) << f;
  }
  EXPECT_EQ(h.percentile(1.0), h.max());
  EXPECT_EQ(h.p99(), h.percentile(0.99));
}

TEST(LatencyHistogramTest, MeanMergeNegativeAndEmpty) {
  LatencyHistogram a;
  EXPECT_EQ(a.p99(), 0);
  EXPECT_EQ(a.mean(), 0);
  a.record(10);
  a.record(30);
  a.record(-5);  // counts as 0
  EXPECT_EQ(a.min(), 0);
  EXPECT_EQ(a.mean(), 13);
  LatencyHistogram b;
  b.record(1000);
  a.merge(b);
  EXPECT_EQ(a.count(), 4u);
  EXPECT_EQ(a.max(), 1000);
  EXPECT_EQ(a.percentile(0.5), 10);
  a.clear();
  EXPECT_EQ(a.count(), 0u);
}

// ---- recovery on the demo line -------------------------------------------------------------

enum : std::size_t { kCoupler, kDi, kDo, kAi, kDrive, kCount };

class RecoveryTest : public ::testing::Test {
 protected:
  void build(bool recovery = true) {
    net_.segment().addSlave(makeDemoSlave(0x1100, "Coupler"));
    net_.segment().addSlave(makeDemoSlave(0x1008, "DI1"));
    net_.segment().addSlave(makeDemoSlave(0x2008, "DO1"));
    net_.segment().addSlave(makeDemoSlave(0x3102, "AI1"));
    net_.segment().addSlave(makeDemoSlave(0x7201, "Drive1"));
    net_.segment().wireLine();
    net_.start();
    master::MasterOptions options;
    options.recovery = recovery;
    master_ = std::make_unique<master::Master>(net_.masterLink(), net_.bus(), options);
    auto status = master_->start();
    ASSERT_TRUE(status.ok()) << status.error().message();
    master_->resetStatistics();
  }
  // Runs `n` cycles of 1 ms; returns how many failed.
  std::uint64_t run(std::uint64_t n) {
    std::uint64_t failed = 0;
    for (std::uint64_t i = 0; i < n; ++i) {
      const SimTime next = net_.clock().now() + kNsPerMs;
      if (!master_->cycle().ok()) ++failed;
      while (net_.clock().now() < next) net_.bus().wait(next);
    }
    return failed;
  }
  // Cycles until `done` holds (at most `limit`); the number of cycles it took.
  template <typename F>
  std::uint64_t runUntil(F done, std::uint64_t limit) {
    for (std::uint64_t i = 1; i <= limit; ++i) {
      run(1);
      if (done()) return i;
    }
    return limit + 1;
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
  slavesim::Slave& sim(std::size_t i) { return net_.segment().slave(i); }

  SimNetwork net_;
  std::unique_ptr<master::Master> master_;
};

TEST_F(RecoveryTest, CutCableLosesTheSlavesBehindItAndHealingBringsThemBackToOp) {
  build();
  EXPECT_EQ(run(1000), 0u);
  EXPECT_TRUE(master_->events().empty()) << eventLog();
  // Pull the cable between DO1 (port 1) and AI1: AI1 and Drive1 disappear.
  net_.segment().setLinkUp(kDo, 1, false);
  const auto lostAfter = runUntil(
      [&] {
        const auto h = master_->health();
        return h.slaves[kAi].condition == SlaveCondition::kLost &&
               h.slaves[kDrive].condition == SlaveCondition::kLost;
      },
      50);
  EXPECT_LE(lostAfter, 5u) << eventLog();
  const auto* lost = findEvent(MasterEventKind::kSlaveLost, kAi);
  ASSERT_NE(lost, nullptr) << eventLog();
  EXPECT_NE(lost->text.find("slave 3 (0x1004"), std::string::npos) << lost->text;
  EXPECT_NE(lost->text.find("lost at cycle 100"), std::string::npos) << lost->text;
  EXPECT_EQ(findEvent(MasterEventKind::kSlaveLost, kDo), nullptr) << eventLog();
  // The others keep running: no more WKC errors once the loss is known.
  const auto errorsBefore = master_->statistics().wkcErrors;
  EXPECT_EQ(run(500), 0u);
  EXPECT_EQ(master_->statistics().wkcErrors, errorsBefore);
  EXPECT_EQ(sim(kDo).state(), AlState::kOp);
  EXPECT_EQ(master_->health().slaves[kDi].condition, SlaveCondition::kOperational);

  net_.segment().setLinkUp(kDo, 1, true);
  const auto back = runUntil([&] { return master_->health().allOperational(); }, 2000);
  EXPECT_LE(back, 500u) << eventLog();
  EXPECT_EQ(sim(kAi).state(), AlState::kOp);
  EXPECT_EQ(sim(kDrive).state(), AlState::kOp);
  ASSERT_NE(findEvent(MasterEventKind::kSlaveRecovered, kDrive), nullptr) << eventLog();
  const auto h = master_->health();
  EXPECT_EQ(h.slaves[kAi].lostCount, 1u);
  EXPECT_EQ(h.slaves[kAi].recoveredCount, 1u);
  EXPECT_EQ(h.slavesLost, 2u);
  EXPECT_EQ(h.slavesRecovered, 2u);
  // And the full expectation is back: cycles are clean.
  EXPECT_EQ(run(200), 0u);
}

TEST_F(RecoveryTest, PowerCycledSlaveGetsItsAddressAndConfigurationBack) {
  build();
  EXPECT_EQ(run(100), 0u);
  sim(kAi).esc().powerOnReset();  // station address 0, INIT, SMs and FMMUs cleared
  ASSERT_EQ(sim(kAi).state(), AlState::kInit);
  const auto back =
      runUntil([&] { return findEvent(MasterEventKind::kSlaveRecovered, kAi) != nullptr; }, 3000);
  EXPECT_LE(back, 1000u) << eventLog();
  ASSERT_NE(findEvent(MasterEventKind::kSlaveReset, kAi), nullptr) << eventLog();
  EXPECT_EQ(sim(kAi).state(), AlState::kOp);
  EXPECT_EQ(sim(kAi).esc().reg16(reg::kConfiguredStationAddress.address), 0x1004);
  // Nobody else was disturbed.
  for (std::size_t i : {kCoupler, kDi, kDo, kDrive}) {
    EXPECT_EQ(findEvent(MasterEventKind::kSlaveLost, i), nullptr) << eventLog();
  }
  EXPECT_EQ(run(200), 0u);
}

TEST_F(RecoveryTest, PowerOffInTheLineLosesTheRestAndPowerOnBringsAllBack) {
  build();
  EXPECT_EQ(run(100), 0u);
  // AI1 loses power, as topology/faults.hpp's power-off does it: its neighbours see their
  // links break (the drive behind it is cut off too) ...
  net_.segment().setLinkUp(kDo, 1, false);
  net_.segment().setLinkUp(kDrive, 0, false);
  run(200);
  ASSERT_NE(findEvent(MasterEventKind::kSlaveLost, kAi), nullptr) << eventLog();
  ASSERT_NE(findEvent(MasterEventKind::kSlaveLost, kDrive), nullptr) << eventLog();
  EXPECT_EQ(run(100), 0u);  // the rest runs clean meanwhile
  // ... and comes back from a power-on reset: station address 0, INIT.
  sim(kAi).esc().powerOnReset();
  net_.segment().setLinkUp(kDo, 1, true);
  net_.segment().setLinkUp(kDrive, 0, true);
  const auto back = runUntil([&] { return master_->health().allOperational(); }, 3000);
  EXPECT_LE(back, 1000u) << eventLog();
  EXPECT_NE(findEvent(MasterEventKind::kSlaveReset, kAi), nullptr) << eventLog();
  EXPECT_NE(findEvent(MasterEventKind::kSlaveReturned, kDrive), nullptr) << eventLog();
  EXPECT_EQ(sim(kAi).state(), AlState::kOp);
  EXPECT_EQ(sim(kDrive).state(), AlState::kOp);
  EXPECT_EQ(run(200), 0u);
}

TEST_F(RecoveryTest, SafeOpWithErrorIsAcknowledgedAndBroughtBackToOp) {
  build();
  EXPECT_EQ(run(50), 0u);
  // The drive's firmware reports an SM watchdog (0x001B) and falls back to SAFEOP.
  sim(kDrive).esc().pdiSetAlStatus(
      static_cast<std::uint16_t>(static_cast<std::uint16_t>(AlState::kSafeOp) | kAlErrorFlag),
      0x001B);
  runUntil([&] { return findEvent(MasterEventKind::kSlaveRecovered, kDrive) != nullptr; }, 1000);
  const auto* error = findEvent(MasterEventKind::kSlaveError, kDrive);
  ASSERT_NE(error, nullptr) << eventLog();
  EXPECT_NE(error->text.find("0x001B"), std::string::npos) << error->text;
  ASSERT_NE(findEvent(MasterEventKind::kSlaveRecovered, kDrive), nullptr) << eventLog();
  EXPECT_EQ(sim(kDrive).state(), AlState::kOp);
  EXPECT_EQ(master_->health().slaves[kDrive].errorCount, 1u);
}

TEST_F(RecoveryTest, WithoutRecoveryAPulledCableStaysAWorkingCounterError) {
  build(false);
  EXPECT_EQ(run(100), 0u);
  net_.segment().setLinkUp(kDo, 1, false);
  EXPECT_EQ(run(100), 100u);
  net_.segment().setLinkUp(kDo, 1, true);
  run(100);
  EXPECT_TRUE(master_->events().empty()) << eventLog();
  EXPECT_GE(master_->statistics().wkcErrors, 100u);
  EXPECT_EQ(master_->health().slavesLost, 0u);
}

}  // namespace
}  // namespace ecsim::testing
