// A frame corrupted on the way still passes the ESCs behind the fault, and they process it as
// an invalid frame. ESC datasheet section I §14.1 "Frame error detection": the processing unit
// "discards register operations, e.g., write operations to registers, SyncManager buffer changes,
// etc.. RAM areas will be written, because they do not have a shadow buffer for write data like
// registers", and the error counters count it (§14, Table 50 note: an error received at port 0
// is counted in 0x0300 and 0x030C, a forwarded error in 0x0308 and 0x030C). Registers are
// 0x0000-0x0F7F; user RAM 0x0F80-0x0FFF is RAM (section I §17.3.1).
#include <gtest/gtest.h>

#include "support/esc_frames.hpp"

namespace ecsim::testing {
namespace {

class InvalidFrame : public ::testing::Test {
 protected:
  void SetUp() override {
    buildLine(seg_, 3);
    for (std::uint16_t i = 0; i < 3; ++i) {
      one(seg_, Command::kApwr, phys(static_cast<std::uint16_t>(-i), 0x0010),
          le16(static_cast<std::uint16_t>(0x1001 + i)));
    }
  }
  slavesim::Esc& esc(std::size_t i) { return seg_.slave(i).esc(); }
  topology::Segment seg_;
};

TEST_F(InvalidFrame, RamWritesTakeEffectRegisterWritesDoNot) {
  const bool delivered =
      sendCorrupted(seg_, 1,
                    {{Command::kBwr, phys(0, reg::kUserRam.address), {0xA1}},
                     {Command::kBwr, phys(0, 0x1200), {0xB1, 0xB2}},
                     {Command::kBwr, phys(0, reg::kEcatEventMask.address), {0x34, 0x12}},
                     {Command::kBwr, phys(0, reg::kAlControl.address), le16(0x0002)},
                     {Command::kFpwr, phys(0x1002, reg::kUserRam.address + 0x10), {0xC1}},
                     {Command::kApwr,
                      phys(static_cast<std::uint16_t>(-2), reg::kUserRam.address + 0x20),
                      {0xD1}}});
  EXPECT_FALSE(delivered) << "the frame stays lost for the master";
  // Slave 0 saw a valid frame: everything happened there.
  EXPECT_EQ(esc(0).reg8(reg::kUserRam.address), 0xA1);
  EXPECT_EQ(esc(0).read(reg::kEcatEventMask), 0x1234);
  EXPECT_EQ(esc(0).read(reg::kAlStatus), 0x0002) << "slave 0 went to PREOP";
  // Slaves 1 (corrupted at its port 0) and 2 (forwarded error) processed an invalid frame.
  for (std::size_t i : {1u, 2u}) {
    SCOPED_TRACE("slave " + std::to_string(i));
    EXPECT_EQ(esc(i).reg8(reg::kUserRam.address), 0xA1) << "user RAM is written";
    EXPECT_EQ(esc(i).reg8(0x1200), 0xB1) << "process RAM is written";
    EXPECT_EQ(esc(i).reg8(0x1201), 0xB2);
    EXPECT_EQ(esc(i).read(reg::kEcatEventMask), 0) << "register write discarded";
    EXPECT_EQ(esc(i).read(reg::kAlControl), 0x0001) << "AL control not written";
    EXPECT_EQ(esc(i).read(reg::kAlStatus), 0x0001) << "no state change requested";
    EXPECT_EQ(esc(i).read(reg::kEcatProcessingUnitErrorCounter), 1)
        << "the invalid frame passed the processing unit (0x030C)";
  }
  EXPECT_EQ(esc(1).reg8(reg::kUserRam.address + 0x10), 0xC1) << "configured addressing works";
  EXPECT_EQ(esc(2).reg8(reg::kUserRam.address + 0x10), 0);
  EXPECT_EQ(esc(2).reg8(reg::kUserRam.address + 0x20), 0xD1)
      << "auto-increment addressing still counts through the invalid frame";
  EXPECT_EQ(esc(1).reg8(reg::kUserRam.address + 0x20), 0);
  EXPECT_EQ(esc(0).read(reg::kEcatProcessingUnitErrorCounter), 0);
  EXPECT_EQ(esc(1).reg8(reg::rxErrorCounters(0)), 1) << "invalid frame counted at port 0";
  EXPECT_EQ(esc(2).reg8(reg::forwardedRxErrorCounter(0)), 1) << "forwarded error at port 0";
}

TEST_F(InvalidFrame, DcReceiveTimeLatchIsNotArmed) {
  // A write to 0x0900 is a register write: discarded, so no port receive times are latched.
  EXPECT_FALSE(sendCorrupted(
      seg_, 0, {{Command::kBwr, phys(0, reg::kReceiveTimePort0.address), {0, 0, 0, 0}}}));
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(esc(i).read(reg::kReceiveTimeEcatProcessingUnit), 0u) << "slave " << i;
  }
}

TEST_F(InvalidFrame, ReadsDoNotClearEvents) {
  // The DL status event is pending after reset (soem-sdinfo frames 12-203) and an ECAT read of
  // 0x0110 clears it: a side effect of a register read, discarded in an invalid frame
  // (section I §14.1) as the register writes are.
  for (std::size_t i = 0; i < 3; ++i) {
    ASSERT_NE(esc(i).read(reg::kEcatEventRequest) & reg::ecat_event::kDlStatus, 0) << i;
  }
  EXPECT_FALSE(
      sendCorrupted(seg_, 1, {{Command::kBrd, phys(0, reg::kDlStatus.address), {0, 0}}}));
  EXPECT_EQ(esc(0).read(reg::kEcatEventRequest) & reg::ecat_event::kDlStatus, 0)
      << "slave 0 saw a valid frame";
  for (std::size_t i : {1u, 2u}) {
    EXPECT_NE(esc(i).read(reg::kEcatEventRequest) & reg::ecat_event::kDlStatus, 0)
        << "slave " << i << ": the invalid frame's read cleared the event";
  }
}

TEST_F(InvalidFrame, LogicalWritesReachPlainRam) {
  // FMMU: logical 0x100 (2 bytes) -> physical 0x1300 of slave 1 (plain RAM, no SM), type write.
  std::vector<std::uint8_t> fmmu(16, 0);
  writeLe32(fmmu, 0, 0x100);
  writeLe16(fmmu, 4, 2);
  fmmu[7] = 7;
  writeLe16(fmmu, 8, 0x1300);
  fmmu[11] = 2;
  fmmu[12] = 1;
  one(seg_, Command::kFpwr, phys(0x1002, reg::kFmmuBase), fmmu);
  EXPECT_FALSE(sendCorrupted(seg_, 0, {{Command::kLwr, 0x100, {0x42, 0x43}}}));
  EXPECT_EQ(esc(1).reg8(0x1300), 0x42);
  EXPECT_EQ(esc(1).reg8(0x1301), 0x43);
}

TEST_F(InvalidFrame, FirstFrameAfterTheFaultsAreRemovedIsProcessed) {
  // The segment replays a recorded route for frames without faults; a frame walked with faults
  // installed must not leave that route empty (every ESC skipped the next frame: WKC 0).
  one(seg_, Command::kBrd, phys(0, reg::kType.address), {0});  // records the route
  sendCorrupted(seg_, 1, {{Command::kBrd, phys(0, reg::kType.address), {0}}});
  EXPECT_EQ(one(seg_, Command::kBrd, phys(0, reg::kType.address), {0}).wkc, 3);
}

}  // namespace
}  // namespace ecsim::testing
