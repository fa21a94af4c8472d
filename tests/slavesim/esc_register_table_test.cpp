// The ESC register table (slavesim/esc_register_table.cpp) against ESC datasheet section II:
// the table is well-formed, and the access columns it encodes are what a master sees.
#include <gtest/gtest.h>

#include "slavesim/esc_register_table.hpp"
#include "support/test_network.hpp"

namespace ecsim::testing {
namespace {

TEST(EscRegisterTable, RowsAreOrderedNamedAndInsideTheRegisterSpace) {
  std::uint32_t previousEnd = 0;
  for (const slavesim::RegisterRow& r : slavesim::escRegisterRows()) {
    EXPECT_GE(r.address, previousEnd) << r.name << " overlaps the row before it";
    EXPECT_GT(r.width, 0) << r.name;
    EXPECT_FALSE(r.name.empty()) << "row at " << r.address;
    previousEnd = static_cast<std::uint32_t>(r.address) + r.width;
    EXPECT_LE(previousEnd, reg::kRegisterSpaceEnd) << r.name;
  }
}

TEST(EscRegisterTable, EveryRegisterOfTheMapHasARow) {
  // Every named register of protocol/registers.hpp is covered by a row, so its access rules are
  // stated rather than defaulted.
  const auto& bytes = slavesim::escRegisterBytes();
  (void)bytes;
  for (const reg::RegisterInfo& info : reg::registerTable()) {
    bool covered = false;
    for (const slavesim::RegisterRow& r : slavesim::escRegisterRows()) {
      covered |= info.address >= r.address && info.address < r.address + r.width;
    }
    EXPECT_TRUE(covered) << info.name << " at 0x" << std::hex << info.address;
  }
}

class RegisterAccess : public ::testing::Test {
 protected:
  void SetUp() override { buildLine(seg_, 1); }
  slavesim::Esc& esc() { return seg_.slave(0).esc(); }
  topology::Segment seg_;
};

TEST_F(RegisterAccess, ResetValuesComeFromTheTable) {
  // Section II reset values: AL control/status INIT, watchdog divider 2498 (100 us), watchdog
  // times 1000, speed counter start 0x1000, filter depths 4 and 12.
  EXPECT_EQ(esc().read(reg::kAlStatus), 0x0001);
  EXPECT_EQ(esc().read(reg::kAlControl), 0x0001);
  EXPECT_EQ(esc().read(reg::kWatchdogDivider), 0x09C2);
  EXPECT_EQ(esc().read(reg::kWatchdogTimePdi), 0x03E8);
  EXPECT_EQ(esc().read(reg::kWatchdogTimeProcessData), 0x03E8);
  EXPECT_EQ(esc().read(reg::kSpeedCounterStart), 0x1000);
  EXPECT_EQ(esc().read(reg::kSystemTimeDifferenceFilterDepth), 0x04);
  EXPECT_EQ(esc().read(reg::kSpeedCounterFilterDepth), 0x0C);
}

TEST_F(RegisterAccess, MasterCannotWriteTheFirmwaresRegisters) {
  // Section II: AL status, AL status code and the station alias are ECAT read-only ("r" in the
  // ECAT column); a write of only such bytes changes nothing and gets no working counter.
  for (auto address :
       {reg::kAlStatus.address, reg::kAlStatusCode.address, reg::kConfiguredStationAlias.address}) {
    auto r = one(seg_, Command::kApwr, phys(0, address), le16(0x0008));
    EXPECT_EQ(r.wkc, 0) << std::hex << address;
  }
  EXPECT_EQ(esc().read(reg::kAlStatus), 0x0001);
  EXPECT_EQ(esc().read(reg::kAlStatusCode), 0x0000);
}

TEST_F(RegisterAccess, OnlyAWriteToByte0x0900LatchesReceiveTimes) {
  // Section II 0x0900: "a write access to register 0x0900 latches"; the other bytes of the
  // register accept the write without effect and nothing is stored.
  constexpr SimTime kAt = 5'000'000;  // the ESC's local clock is far from 0 here
  one(seg_, Command::kApwr, phys(0, reg::kReceiveTimePort0.address + 1), {0xAA}, kAt);
  EXPECT_EQ(esc().read(reg::kReceiveTimePort0), 0u) << "no latch, nothing stored";
  EXPECT_EQ(esc().read(reg::kReceiveTimeEcatProcessingUnit), 0u);
  auto r = one(seg_, Command::kApwr, phys(0, reg::kReceiveTimePort0.address), {0x55}, kAt);
  EXPECT_EQ(r.wkc, 1);
  EXPECT_NE(esc().read(reg::kReceiveTimePort0), 0u) << "latched";
}

}  // namespace
}  // namespace ecsim::testing
