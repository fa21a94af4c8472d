// The ESC's time-driven units against the ESC datasheet (section I "Watchdog" and "SyncSignal
// generation", section II registers 0x0400-0x0443, 0x0980-0x09A7) and the ESM reactions of
// ETG.1000.6 Table 11: the process-data watchdog drops a slave in OP to SAFEOP with 0x001B;
// SYNC0/SYNC1 pulses reach the device at the times the cyclic unit's registers give; DC sync
// configuration is checked at PREOP->SAFEOP (0x0030, 0x0036) and a lost SYNC0 in OP gives
// 0x002C.
#include <gtest/gtest.h>

#include <cstdint>

#include "protocol/sii.hpp"
#include "slavesim/dc_clock.hpp"
#include "support/test_network.hpp"

namespace ecsim::testing {
namespace {

constexpr SimTime kMs = kNsPerMs;
constexpr std::uint16_t kStation = 0x1001;

std::vector<std::uint8_t> le32(std::uint32_t v) {
  std::vector<std::uint8_t> b(4);
  writeLe32(b, 0, v);
  return b;
}

std::vector<std::uint8_t> le64(std::uint64_t v) {
  std::vector<std::uint8_t> b(8);
  writeLe64(b, 0, v);
  return b;
}

// An SII image whose ESC configuration byte (0x0141) is 0: a slave with firmware (no device
// emulation), so the firmware's ESM reacts to the watchdog. emulation = true keeps the
// EL2004's 0x01.
std::vector<std::uint8_t> firmwareSii(bool emulation = false) {
  auto sii = makeSii(0xABCD, 7, 0x1000, 128, 0x1080, 128);
  sii[1] = emulation ? 0x01 : 0x00;
  sii[sii::kWordChecksum * 2] = siiChecksum(ConstBytes(sii.data(), sii::kChecksumCoveredBytes));
  return sii;
}

struct Pulse {
  unsigned signal;
  SimTime time;
};

class RecordingDevice : public slavesim::Device {
 public:
  explicit RecordingDevice(std::vector<Pulse>& pulses) : pulses_(pulses) {}
  void sync(slavesim::Esc&, unsigned signal, AlState, SimTime now) override {
    pulses_.push_back({signal, now});
  }

 private:
  std::vector<Pulse>& pulses_;
};

class TimeUnits : public ::testing::Test {
 protected:
  void make(bool emulation = false, bool dcSupported = true, std::uint32_t minCycleNs = 0) {
    slavesim::SlaveProfile p;
    p.mailbox = slavesim::SlaveProfile::Mailbox{0x1000, 128, 0x1080, 128};
    p.processData = {{2, true, 2}, {3, false, 4}};
    p.sync.dcSupported = dcSupported;
    p.sync.mode = p.sync.initialMode = 0;
    p.sync.minCycleNs = minCycleNs;
    seg_.addSlave(makeSlave("drive", 7, p, firmwareSii(emulation)));
    seg_.slave(0).setDevice(std::make_unique<RecordingDevice>(pulses_));
    one(seg_, Command::kApwr, phys(0, 0x0010), le16(kStation));
  }
  DatagramResult wr(std::uint16_t ado, std::vector<std::uint8_t> data, SimTime t = 0) {
    return one(seg_, Command::kFpwr, phys(kStation, ado), std::move(data), t);
  }
  std::vector<std::uint8_t> rd(std::uint16_t ado, std::uint16_t n, SimTime t = 0) {
    return one(seg_, Command::kFprd, phys(kStation, ado), std::vector<std::uint8_t>(n, 0), t).data;
  }
  std::uint16_t status(SimTime t = 0) { return readLe16(rd(0x0130, 2, t), 0); }
  std::uint16_t code(SimTime t = 0) { return readLe16(rd(0x0134, 2, t), 0); }
  void request(std::uint16_t control, SimTime t = 0) { wr(0x0120, le16(control), t); }
  void toSafeOp(SimTime t = 0) {
    wr(0x0800, smChannelBytes(0x1000, 128, 0x26), t);
    wr(0x0808, smChannelBytes(0x1080, 128, 0x22), t);
    request(0x0002, t);  // no acknowledge bit: device emulation would copy it into AL status
    wr(0x0810, smChannelBytes(0x1100, 2, 0x64), t);  // outputs, 3-buffer, watchdog trigger on
    wr(0x0818, smChannelBytes(0x1180, 4, 0x20), t);
    request(0x0004, t);
  }
  void toOp(SimTime t = 0) {
    toSafeOp(t);
    ASSERT_EQ(status(t), 0x0004) << std::hex << code(t);
    wr(0x1100, {1, 2}, t);
    request(0x0008, t);
    ASSERT_EQ(status(t), 0x0008);
  }
  // Activates the cyclic unit: start time, SYNC0 cycle, SYNC1 cycle, activation byte.
  void activate(std::uint64_t start, std::uint32_t cycle0, std::uint32_t cycle1,
                std::uint8_t activation, SimTime t = 0) {
    wr(0x0990, le64(start), t);
    wr(0x09A0, le32(cycle0), t);
    wr(0x09A4, le32(cycle1), t);
    wr(0x0981, {activation}, t);
  }
  void idle(SimTime t) { seg_.pollSlaves(t); }

  topology::Segment seg_;
  std::vector<Pulse> pulses_;
};

// ---- process-data watchdog --------------------------------------------------------------------

TEST_F(TimeUnits, WatchdogExpiryDropsOpToSafeOpWith001B) {
  make();
  toOp();
  // Default divider 2498 and time 1000: (2498 + 2) x 40 ns x 1000 = 100 ms after the output
  // write (which passed the slave a few microseconds after t = 0: wire time).
  idle(99 * kMs);
  EXPECT_EQ(status(99 * kMs), 0x0008);
  EXPECT_EQ(rd(0x0440, 1, 99 * kMs)[0] & 0x01, 0x01) << "active";
  idle(100 * kMs + 10 * kNsPerUs);
  EXPECT_EQ(status(100 * kMs + 10 * kNsPerUs), 0x0014) << "SAFEOP + error";
  EXPECT_EQ(code(), 0x001B);
  EXPECT_EQ(rd(0x0440, 1)[0] & 0x01, 0x00) << "expired";
  EXPECT_EQ(rd(0x0442, 1)[0], 1) << "expiry counter";
}

TEST_F(TimeUnits, WatchdogRearmsAfterRecovery) {
  make();
  toOp();
  idle(200 * kMs);
  ASSERT_EQ(code(200 * kMs), 0x001B);
  // The master acknowledges, writes outputs again and returns to OP; the next silence counts.
  wr(0x1100, {5, 6}, 200 * kMs);
  request(0x0018, 200 * kMs);
  ASSERT_EQ(status(200 * kMs), 0x0008);
  EXPECT_EQ(rd(0x0440, 1, 200 * kMs)[0] & 0x01, 0x01);
  idle(400 * kMs);
  EXPECT_EQ(status(400 * kMs), 0x0014);
  EXPECT_EQ(rd(0x0442, 1, 400 * kMs)[0], 2);
}

TEST_F(TimeUnits, OutputWritesKeepTheWatchdogCalm) {
  make();
  toOp();
  for (SimTime t = 10 * kMs; t <= 1000 * kMs; t += 10 * kMs) wr(0x1100, {3, 4}, t);
  EXPECT_EQ(status(1000 * kMs), 0x0008);
  EXPECT_EQ(rd(0x0442, 1)[0], 0);
}

TEST_F(TimeUnits, WatchdogDividerAndTimeSetTheTimeout) {
  make();
  wr(0x0400, le16(498), 0);  // (498 + 2) x 40 ns = 20 us per increment
  wr(0x0420, le16(100), 0);  // 2 ms
  toOp();
  idle(1999 * kNsPerUs);
  EXPECT_EQ(status(1999 * kNsPerUs), 0x0008);
  idle(2 * kMs + 10 * kNsPerUs);
  EXPECT_EQ(code(2 * kMs + 10 * kNsPerUs), 0x001B);
}

TEST_F(TimeUnits, WatchdogTimeZeroDisablesIt) {
  make();
  wr(0x0420, le16(0), 0);
  toOp();
  idle(10'000 * kMs);
  EXPECT_EQ(status(10'000 * kMs), 0x0008);
}

TEST_F(TimeUnits, DeviceEmulationCountsButKeepsState) {
  make(/*emulation=*/true);
  toOp();
  idle(200 * kMs);
  EXPECT_EQ(status(200 * kMs), 0x0008) << "the ESC has no firmware that could leave OP";
  EXPECT_EQ(rd(0x0442, 1)[0], 1);
}

// ---- SYNC generation ------------------------------------------------------------------------

TEST_F(TimeUnits, Sync0PulsesFollowStartTimeAndCycle) {
  make();
  activate(5 * kMs, 1'000'000, 0, 0x03);
  idle(5 * kMs - 1);
  EXPECT_TRUE(pulses_.empty());
  EXPECT_EQ(rd(0x0984, 1)[0] & 0x01, 0x01) << "first SYNC0 pending";
  idle(9 * kMs + 500);
  ASSERT_EQ(pulses_.size(), 5u);
  for (std::size_t k = 0; k < pulses_.size(); ++k) {
    EXPECT_EQ(pulses_[k].signal, 0u);
    EXPECT_EQ(pulses_[k].time, static_cast<SimTime>(5 + k) * kMs);
  }
  EXPECT_EQ(seg_.slave(0).syncPulses(), 5u);
  // 0x0990 reads as the next SYNC0 pulse; the activation status has cleared.
  EXPECT_EQ(readLe64(rd(0x0990, 8, 9 * kMs + 500), 0), static_cast<std::uint64_t>(10 * kMs));
  EXPECT_EQ(rd(0x0984, 1, 9 * kMs + 500)[0] & 0x01, 0x00);
}

TEST_F(TimeUnits, PulsesAreInSystemTimeOfTheDriftingClock) {
  make();
  seg_.setClock(0, 0, 100.0);  // local clock runs 100 ppm fast
  activate(10 * kMs, 1'000'000, 0, 0x03);
  idle(20 * kMs);
  ASSERT_FALSE(pulses_.empty());
  // Local 10 ms is reached at global 10 ms / (1 + 100e-6) = 9'999'000 ns.
  EXPECT_NEAR(static_cast<double>(pulses_[0].time), 9'999'000.0, 2.0);
  EXPECT_EQ(pulses_.size(), 11u) << "local 10..20.002 ms";
}

// A power cycle restarts the ESC's local clock from 0 (datasheet: the local time register
// 0x0910 counts from power-up); the oscillator's drift is the same afterwards.
TEST_F(TimeUnits, PowerCycleRestartsTheLocalClockFromZero) {
  make();
  seg_.setClock(0, 0, 100.0);  // 100 ppm fast
  // The read samples the clock when the datagram passes the slave, a little after the frame's
  // start: the same lag for both reads.
  const auto before = static_cast<double>(readLe64(rd(0x0910, 8, 20 * kMs), 0));
  const double lag = before - 20'002'000.0;
  EXPECT_GT(lag, 0.0);
  EXPECT_LT(lag, 10'000.0);
  seg_.slave(0).powerOff();
  seg_.slave(0).powerOn(30 * kMs);
  one(seg_, Command::kApwr, phys(0, 0x0010), le16(kStation), 30 * kMs);  // address cleared too
  EXPECT_NEAR(static_cast<double>(readLe64(rd(0x0910, 8, 35 * kMs), 0)), 5'000'500.0 + lag, 2.0);
}

TEST_F(TimeUnits, StartTimeInThePastNeverPulses) {
  make();
  idle(50 * kMs);
  activate(10 * kMs, 1'000'000, 0, 0x03, 50 * kMs);  // start 40 ms ago
  idle(500 * kMs);
  EXPECT_TRUE(pulses_.empty());
  EXPECT_TRUE(seg_.slave(0).esc().syncStartMissed());
  EXPECT_EQ(rd(0x0984, 1, 500 * kMs)[0] & 0x01, 0x01) << "first pulse pending forever";
}

TEST_F(TimeUnits, Sync1ShiftedAfterEachSync0) {
  make();
  activate(1 * kMs, 1'000'000, 250'000, 0x07);
  idle(3 * kMs + 300'000);
  std::vector<SimTime> s0, s1;
  for (const auto& p : pulses_) (p.signal == 0 ? s0 : s1).push_back(p.time);
  EXPECT_EQ(s0, (std::vector<SimTime>{1 * kMs, 2 * kMs, 3 * kMs}));
  EXPECT_EQ(s1, (std::vector<SimTime>{1'250'000, 2'250'000, 3'250'000}));
  // In time order.
  for (std::size_t i = 1; i < pulses_.size(); ++i) EXPECT_LE(pulses_[i - 1].time, pulses_[i].time);
  EXPECT_EQ(readLe64(rd(0x0998, 8, 3 * kMs + 300'000), 0), 4'250'000u) << "next SYNC1";
}

TEST_F(TimeUnits, Sync1AsMultipleOfSync0) {
  make();
  activate(0 + 1 * kMs, 1'000'000, 3'000'000, 0x07);
  idle(10 * kMs);
  std::vector<SimTime> s1;
  for (const auto& p : pulses_)
    if (p.signal == 1) s1.push_back(p.time);
  EXPECT_EQ(s1, (std::vector<SimTime>{4 * kMs, 7 * kMs, 10 * kMs}));
}

TEST_F(TimeUnits, SingleShotSync0) {
  make();
  activate(2 * kMs, 0, 0, 0x03);
  idle(50 * kMs);
  ASSERT_EQ(pulses_.size(), 1u);
  EXPECT_EQ(pulses_[0].time, 2 * kMs);
}

TEST_F(TimeUnits, Sync0StatusAcknowledgeModeClearsOnRead) {
  make();
  wr(0x0982, le16(0));  // read-only for ECAT: the SII value (0 here) stays
  activate(1 * kMs, 1'000'000, 0, 0x03);
  EXPECT_EQ(rd(0x098E, 1, 500'000)[0], 0) << "no pulse yet";
  EXPECT_EQ(rd(0x098E, 1, 1'100'000)[0], 1) << "pulse at 1 ms";
  EXPECT_EQ(rd(0x098E, 1, 1'200'000)[0], 0) << "cleared by the read";
  EXPECT_EQ(rd(0x098E, 1, 2'000'000)[0], 1) << "next pulse";
}

TEST_F(TimeUnits, DeactivationStopsPulses) {
  make();
  activate(1 * kMs, 1'000'000, 0, 0x03);
  idle(3 * kMs);
  ASSERT_EQ(pulses_.size(), 3u);
  wr(0x0981, {0x00}, 3 * kMs);
  idle(10 * kMs);
  EXPECT_EQ(pulses_.size(), 3u);
  EXPECT_FALSE(seg_.slave(0).esc().syncActive(0));
}

// ---- DC synchronisation checks in the ESM -----------------------------------------------------

TEST_F(TimeUnits, SyncOnDeviceWithoutDcRefusedWith0030) {
  make(false, /*dcSupported=*/false);
  activate(100 * kMs, 1'000'000, 0, 0x03);
  toSafeOp();
  EXPECT_EQ(status(), 0x0012);
  EXPECT_EQ(code(), 0x0030);
}

TEST_F(TimeUnits, DcModeChosenWithoutSync0RefusedWith0030) {
  make();
  seg_.slave(0).profile().sync.mode = 2;  // as if the master wrote 0x1C32:01 = 2 in PREOP
  toSafeOp();
  EXPECT_EQ(code(), 0x0030);
  activate(100 * kMs, 1'000'000, 0, 0x03);
  request(0x0014);
  EXPECT_EQ(status(), 0x0004) << std::hex << code();
}

TEST_F(TimeUnits, Sync0CycleBelowMinimumRefusedWith0036) {
  make(false, true, /*minCycleNs=*/250'000);
  activate(100 * kMs, 125'000, 0, 0x03);
  toSafeOp();
  EXPECT_EQ(code(), 0x0036);
}

TEST_F(TimeUnits, LosingSync0InOpGivesFatalSyncError) {
  make();
  activate(1 * kMs, 1'000'000, 0, 0x03);
  toOp();
  EXPECT_TRUE(seg_.slave(0).stateMachine().dcSynchronous());
  wr(0x1100, {1, 2}, 5 * kMs);
  wr(0x0981, {0x00}, 5 * kMs);
  EXPECT_EQ(status(5 * kMs), 0x0014);
  EXPECT_EQ(code(5 * kMs), 0x002C);
}

// 0x092C (datasheet section II): bit 31 "local copy smaller", bits 30-0 the magnitude, held
// at its largest. A master may write any system time, so any 64-bit difference arrives here:
// fuzz_esc found INT64_MIN, whose negation overflowed (UBSan abort).
TEST(SystemTimeDifference, EveryDifferenceHasARegisterValue) {
  using slavesim::systemTimeDifferenceRegister;
  EXPECT_EQ(systemTimeDifferenceRegister(0), 0u);
  EXPECT_EQ(systemTimeDifferenceRegister(5), 5u);
  EXPECT_EQ(systemTimeDifferenceRegister(-5), 0x80000005u);
  EXPECT_EQ(systemTimeDifferenceRegister(0x7FFFFFFF), 0x7FFFFFFFu);
  EXPECT_EQ(systemTimeDifferenceRegister(0x80000000), 0x7FFFFFFFu);
  EXPECT_EQ(systemTimeDifferenceRegister(-0x80000000LL), 0xFFFFFFFFu);
  EXPECT_EQ(systemTimeDifferenceRegister(INT64_MAX), 0x7FFFFFFFu);
  EXPECT_EQ(systemTimeDifferenceRegister(INT64_MIN), 0xFFFFFFFFu);
}

}  // namespace
}  // namespace ecsim::testing
