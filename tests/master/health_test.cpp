// Cyclic health and recovery against the in-process simulator on virtual time: a line of
// ecsim's demo devices (examples/topologies/demo.xml without the second drive) runs at 1 ms;
// a cable is pulled and put back, a slave is power-cycled, a slave drops to SAFEOP+ERROR, and
// with recovery off the same faults stay errors. A power-cycled drive gets its PDO assignment
// back over CoE; a recovery that cannot succeed (EEPROM checksum error, silent mailbox, SDO
// abort) is reported once with its reason and retried. The SlaveSetup the master gives its
// recoveries (PDO assignment, ENI init commands). Also the latency histogram.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <random>

#include "config/eni.hpp"
#include "master/health.hpp"
#include "master/histogram.hpp"
#include "master/master.hpp"
#include "master/recovery.hpp"
#include "protocol/sdo.hpp"
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

// Stands between a simulated slave and its mailbox server: records the SDO downloads it gets,
// and can swallow every request (silent) or abort those for one object.
class WatchedMailbox final : public slavesim::MailboxServer {
 public:
  explicit WatchedMailbox(std::unique_ptr<slavesim::MailboxServer> inner)
      : inner_(std::move(inner)) {}
  void onRequest(slavesim::Esc& esc, ConstBytes mailbox, SimTime now) override {
    auto request = decodeSdoRequestMailbox(mailbox);
    const auto* down =
        request.ok() ? std::get_if<SdoInitiateDownloadRequest>(&request->sdo) : nullptr;
    if (down != nullptr) downloads.emplace_back(down->index, down->subindex);
    if (silent) return;
    if (down != nullptr && abortIndex == down->index) {
      std::array<std::uint8_t, 64> out{};
      MailboxHeader header;
      header.counter = request->mailbox.counter;
      auto n = encodeSdoResponseMailbox(
          out, SdoResponse{SdoAbort{down->index, down->subindex, 0x06010000}}, header);
      if (n.ok()) (void)esc.pdiMailboxSend(ConstBytes(out.data(), *n));
      return;
    }
    inner_->onRequest(esc, mailbox, now);
  }
  void poll(slavesim::Esc& esc, SimTime now) override {
    if (!silent) inner_->poll(esc, now);
  }

  std::vector<std::pair<std::uint16_t, std::uint8_t>> downloads;
  bool silent{false};
  std::optional<std::uint16_t> abortIndex;

 private:
  std::unique_ptr<slavesim::MailboxServer> inner_;
};

class RecoveryTest : public ::testing::Test {
 protected:
  void build(bool recovery = true) {
    addDemoSlaves(net_, 1);
    net_.start();
    master::MasterOptions options;
    options.recovery = recovery;
    master_ = std::make_unique<master::Master>(net_.masterLink(), net_.bus(), options);
    auto status = master_->start();
    ASSERT_TRUE(status.ok()) << status.error().message();
    master_->resetStatistics();
  }
  // Runs `n` cycles of 1 ms; returns how many failed.
  std::uint64_t run(std::uint64_t n) { return runCycles(*master_, net_, n); }
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
    return testing::findEvent(master_->events(), kind, position);
  }
  std::string eventLog() const { return testing::eventLog(master_->events()); }
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

// ---- what a recovery gives back, and recoveries that cannot succeed -------------------------

class RecoveryFailureTest : public RecoveryTest {
 protected:
  WatchedMailbox& watchDriveMailbox() {
    auto watched = std::make_unique<WatchedMailbox>(sim(kDrive).takeMailboxServer());
    WatchedMailbox& ref = *watched;
    sim(kDrive).setMailboxServer(std::move(watched));
    return ref;
  }
  void powerCycle(std::size_t i) {
    sim(i).powerOff();
    sim(i).powerOn(net_.clock().now());
  }
  std::size_t countEvents(MasterEventKind kind, std::size_t position) const {
    return static_cast<std::size_t>(
        std::count_if(master_->events().begin(), master_->events().end(),
                      [&](const auto& e) { return e.kind == kind && e.position == position; }));
  }
};

TEST_F(RecoveryFailureTest, PowerCycledDriveGetsItsPdoAssignmentBackOverCoe) {
  build();
  EXPECT_EQ(run(100), 0u);
  WatchedMailbox& mailbox = watchDriveMailbox();
  powerCycle(kDrive);
  runUntil([&] { return findEvent(MasterEventKind::kSlaveRecovered, kDrive) != nullptr; }, 3000);
  ASSERT_NE(findEvent(MasterEventKind::kSlaveRecovered, kDrive), nullptr) << eventLog();
  // What the master found at start-up (the drive's CoE dictionary), written back the way a
  // PDO assignment is changed: sub 0 cleared, the PDOs, then their number.
  const auto& data = master_->processData()[kDrive];
  ASSERT_EQ(data.source, master::PdoSource::kCoe);
  std::vector<std::pair<std::uint16_t, std::uint8_t>> expected;
  for (const auto& sm : data.sms) {
    const auto index = static_cast<std::uint16_t>(0x1C10 + sm.sm);
    expected.emplace_back(index, 0);
    for (std::size_t k = 0; k < sm.pdos.size(); ++k) {
      expected.emplace_back(index, static_cast<std::uint8_t>(k + 1));
    }
    expected.emplace_back(index, 0);
  }
  EXPECT_GE(expected.size(), 6u);  // 0x1C12 and 0x1C13, one PDO each at least
  EXPECT_EQ(mailbox.downloads, expected);
  EXPECT_EQ(sim(kDrive).state(), AlState::kOp);
  EXPECT_EQ(run(200), 0u);
}

TEST_F(RecoveryFailureTest, SilentMailboxFailsTheRecoveryOnceRetriesAndRecoversWhenItAnswers) {
  build();
  EXPECT_EQ(run(100), 0u);
  WatchedMailbox& mailbox = watchDriveMailbox();
  mailbox.silent = true;
  powerCycle(kDrive);
  run(3500);  // the first attempt times out, two retries (every 1000 cycles) too
  ASSERT_EQ(countEvents(MasterEventKind::kRecoveryFailed, kDrive), 1u) << eventLog();
  const auto* failed = findEvent(MasterEventKind::kRecoveryFailed, kDrive);
  EXPECT_NE(failed->text.find("PDO assignment 0x1C12:00"), std::string::npos) << failed->text;
  EXPECT_NE(failed->text.find("tried again every 1000 cycles"), std::string::npos) << failed->text;
  EXPECT_EQ(countEvents(MasterEventKind::kSlaveReturned, kDrive), 0u) << eventLog();
  const auto h = master_->health();
  EXPECT_NE(h.slaves[kDrive].condition, SlaveCondition::kOperational);  // failed, or retrying
  EXPECT_GE(h.slaves[kDrive].failedAttempts, 2u);
  EXPECT_EQ(sim(kDrive).state(), AlState::kPreOp);  // its mailbox works in PREOP: no further
  EXPECT_EQ(run(100), 0u);                          // the others run clean meanwhile
  mailbox.silent = false;
  const auto back = runUntil(
      [&] { return findEvent(MasterEventKind::kSlaveRecovered, kDrive) != nullptr; }, 3000);
  EXPECT_LE(back, 2200u) << eventLog();  // the attempt under way times out, the next succeeds
  EXPECT_EQ(sim(kDrive).state(), AlState::kOp);
  EXPECT_TRUE(master_->health().allOperational());
}

TEST_F(RecoveryFailureTest, SdoAbortOnThePdoAssignmentIsReportedWithTheAbortCode) {
  build();
  EXPECT_EQ(run(100), 0u);
  WatchedMailbox& mailbox = watchDriveMailbox();
  mailbox.abortIndex = 0x1C12;
  powerCycle(kDrive);
  run(500);
  const auto* failed = findEvent(MasterEventKind::kRecoveryFailed, kDrive);
  ASSERT_NE(failed, nullptr) << eventLog();
  EXPECT_NE(failed->text.find("0x06010000"), std::string::npos) << failed->text;
  EXPECT_NE(sim(kDrive).state(), AlState::kOp);
}

TEST_F(RecoveryFailureTest, EepromChecksumErrorIsReportedOnceAndTheOthersKeepRunning) {
  build();
  EXPECT_EQ(run(100), 0u);
  constexpr std::size_t kChecksumByte = 14;  // SII word 7, low byte (ETG.1000.6 table 9)
  auto& esc = sim(kAi).esc();
  esc.writeSiiByte(kChecksumByte, static_cast<std::uint8_t>(esc.sii()[kChecksumByte] ^ 0x5A));
  powerCycle(kAi);
  ASSERT_FALSE(sim(kAi).firmwareRunning());
  run(2500);
  ASSERT_NE(findEvent(MasterEventKind::kSlaveReset, kAi), nullptr) << eventLog();
  ASSERT_EQ(countEvents(MasterEventKind::kRecoveryFailed, kAi), 1u) << eventLog();
  const auto* failed = findEvent(MasterEventKind::kRecoveryFailed, kAi);
  EXPECT_NE(failed->text.find("EEPROM checksum error"), std::string::npos) << failed->text;
  EXPECT_NE(failed->text.find("cannot leave INIT"), std::string::npos) << failed->text;
  EXPECT_GE(master_->health().slaves[kAi].failedAttempts, 3u);
  EXPECT_EQ(findEvent(MasterEventKind::kSlaveRecovered, kAi), nullptr);
  // Its station address is back (the slave answers), the rest of the line cycles clean.
  EXPECT_EQ(esc.reg16(reg::kConfiguredStationAddress.address), 0x1004);
  EXPECT_EQ(run(200), 0u);
  EXPECT_EQ(sim(kDrive).state(), AlState::kOp);
}

// A master configured from examples/eni/demo-eni.xml: a power-cycled AI1 gets its ENI init
// commands again - the PS register write of its process-data watchdog (changed here to 500, so
// that the ESC's power-on default of 1000 does not pass for it) and the PS CoE download
// 0x8000:01 (the filter of channel 1).
TEST(EniRecoveryTest, PowerCycledSlaveGetsItsEniInitCommandsAgain) {
  SimNetwork net;
  addDemoSlaves(net);
  net.start();
  std::ifstream in(std::string(ECSIM_SOURCE_DIR) + "/examples/eni/demo-eni.xml");
  std::string xml((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto ai = xml.find("<Name>AI1</Name>");
  ASSERT_NE(ai, std::string::npos);
  const auto watchdog = xml.find("<Data>E803</Data>", ai);  // 0x0420 = 1000
  ASSERT_NE(watchdog, std::string::npos);
  xml.replace(watchdog, 17, "<Data>F401</Data>");  // 500
  auto eni = parseEni(xml, "demo-eni.xml");
  ASSERT_TRUE(eni.ok()) << eni.error().message();
  master::Master master(net.masterLink(), net.bus());
  master.setConfig(masterConfigFromEni(std::move(eni).value()));
  auto started = master.start();
  ASSERT_TRUE(started.ok()) << started.error().message();
  auto& aiSim = net.segment().slave(kAi);
  constexpr std::uint16_t kWatchdogTime = 0x0420;
  ASSERT_EQ(aiSim.esc().reg16(kWatchdogTime), 500);
  auto watched = std::make_unique<WatchedMailbox>(aiSim.takeMailboxServer());
  WatchedMailbox& mailbox = *watched;
  aiSim.setMailboxServer(std::move(watched));
  aiSim.powerOff();
  aiSim.powerOn(net.clock().now());
  ASSERT_EQ(aiSim.esc().reg16(kWatchdogTime), 1000);
  bool back = false;
  for (int i = 0; i < 3000 && !back; ++i) {
    const SimTime next = net.clock().now() + kNsPerMs;
    (void)master.cycle();
    while (net.clock().now() < next) net.bus().wait(next);
    back = master.health().allOperational() && aiSim.state() == AlState::kOp;
  }
  const std::string log = eventLog(master.events());
  ASSERT_TRUE(back) << log;
  EXPECT_EQ(aiSim.esc().reg16(kWatchdogTime), 500) << log;
  EXPECT_EQ(mailbox.downloads, (std::vector<std::pair<std::uint16_t, std::uint8_t>>{{0x8000, 1}}))
      << "the ENI's own commands, not the master's PDO assignment";
  EXPECT_EQ(aiSim.esc().reg16(reg::kConfiguredStationAddress.address), 1004);  // the ENI's
}

// ---- SlaveSetup ----------------------------------------------------------------------------

TEST(SlaveSetupTest, PdoAssignmentWritesOnlyForPdosFoundThroughCoe) {
  master::SlaveProcessData data;
  data.source = master::PdoSource::kCoe;
  data.sms.push_back({2, true, {{0x1600, "", {}}, {0x1601, "", {}}}});
  data.sms.push_back({3, false, {}});
  const auto writes = master::pdoAssignmentWrites(data);
  ASSERT_EQ(writes.size(), 6u);
  EXPECT_EQ(writes[0].index, 0x1C12);
  EXPECT_EQ(writes[0].data, std::vector<std::uint8_t>{0});
  EXPECT_EQ(writes[1].subindex, 1);
  EXPECT_EQ(writes[1].data, (std::vector<std::uint8_t>{0x00, 0x16}));  // 0x1600, little-endian
  EXPECT_EQ(writes[2].data, (std::vector<std::uint8_t>{0x01, 0x16}));
  EXPECT_EQ(writes[3].subindex, 0);
  EXPECT_EQ(writes[3].data, std::vector<std::uint8_t>{2});
  EXPECT_EQ(writes[4].index, 0x1C13);  // an empty assignment is written as empty
  EXPECT_EQ(writes[5].data, std::vector<std::uint8_t>{0});
  EXPECT_NE(writes[1].what.find("0x1C12:01"), std::string::npos) << writes[1].what;
  data.source = master::PdoSource::kSii;  // the SII's PDOs are fixed: nothing to write
  EXPECT_TRUE(master::pdoAssignmentWrites(data).empty());
}

TEST(SlaveSetupTest, AnEniSlaveGetsItsInitCommandsPerTransition) {
  EniConfig eni;
  eni.file = "bus.xml";
  EniSlave slave;
  auto reg = [](std::uint16_t ado, std::vector<std::uint8_t> data, std::vector<char> from,
                std::vector<char> to, int line, std::uint8_t cmd = 5) {
    EniRegisterCmd c;
    for (std::size_t k = 0; k < from.size(); ++k) c.transitions.push_back({from[k], to[k]});
    c.cmd = cmd;
    c.ado = ado;
    c.data = std::move(data);
    c.line = line;
    return c;
  };
  slave.initCmds.push_back(reg(0x0800, {1, 2, 3, 4}, {'I'}, {'P'}, 10));   // SM0
  slave.initCmds.push_back(reg(0x0120, {2, 0}, {'I'}, {'P'}, 11));         // AL control
  slave.initCmds.push_back(reg(0x0010, {0x05, 0x10}, {'I'}, {'P'}, 12));   // station address
  slave.initCmds.push_back(reg(0x0130, {}, {'I'}, {'P'}, 13, 4));          // a read
  slave.initCmds.push_back(reg(0x0810, {5, 6, 7, 8}, {'P'}, {'S'}, 14));   // SM2
  slave.initCmds.push_back(reg(0x0600, {9}, {'P', 'S'}, {'S', 'O'}, 15));  // FMMU0
  EniMailbox mailbox;
  EniCoeCmd pdo;
  pdo.transitions.push_back({'P', 'S'});
  pdo.index = 0x1C12;
  pdo.subIndex = 0;
  pdo.data = {0};
  pdo.line = 20;
  EniCoeCmd ip = pdo;
  ip.transitions = {{'I', 'P'}};
  ip.index = 0x6060;
  ip.line = 21;
  EniCoeCmd upload = pdo;
  upload.ccs = 2;
  upload.line = 22;
  mailbox.coeInitCmds = {pdo, ip, upload};
  slave.mailbox = mailbox;
  eni.slaves.push_back(slave);
  std::optional<MasterConfig> config = masterConfigFromEni(eni);
  std::vector<master::SlaveProcessData> processData(1);
  master::MasterSlaveSetup setup(processData, config);
  master::SlaveInfo info;
  info.position = 0;

  auto lines = [](const std::vector<master::SetupWrite>& writes) {
    std::vector<std::string> out;
    for (const auto& w : writes) out.push_back(w.what);
    return out;
  };
  const auto preop = setup.writesFor(info, AlState::kPreOp);
  ASSERT_EQ(preop.size(), 1u) << ::testing::PrintToString(lines(preop));
  EXPECT_EQ(preop[0].kind, master::SetupWrite::Kind::kRegister);
  EXPECT_EQ(preop[0].index, 0x0800);
  EXPECT_NE(preop[0].what.find("bus.xml line 10"), std::string::npos) << preop[0].what;
  // In PREOP: the CoE commands of IP (a mailbox exists from PREOP on), then those of PS.
  const auto safeop = setup.writesFor(info, AlState::kSafeOp);
  ASSERT_EQ(safeop.size(), 4u) << ::testing::PrintToString(lines(safeop));
  EXPECT_EQ(safeop[0].index, 0x6060);
  EXPECT_EQ(safeop[0].kind, master::SetupWrite::Kind::kSdo);
  EXPECT_EQ(safeop[1].index, 0x0810);
  EXPECT_EQ(safeop[2].index, 0x0600);
  EXPECT_EQ(safeop[3].index, 0x1C12);
  EXPECT_NE(safeop[3].what.find("line 20"), std::string::npos) << safeop[3].what;
  const auto op = setup.writesFor(info, AlState::kOp);
  ASSERT_EQ(op.size(), 1u);
  EXPECT_EQ(op[0].index, 0x0600);
  // Without an ENI: the PDO assignment found through CoE, for SAFEOP only.
  std::optional<MasterConfig> none;
  processData[0].source = master::PdoSource::kCoe;
  processData[0].sms.push_back({2, true, {{0x1600, "", {}}}});
  master::MasterSlaveSetup own(processData, none);
  EXPECT_TRUE(own.writesFor(info, AlState::kPreOp).empty());
  EXPECT_EQ(own.writesFor(info, AlState::kSafeOp).size(), 3u);
}

}  // namespace
}  // namespace ecsim::testing
