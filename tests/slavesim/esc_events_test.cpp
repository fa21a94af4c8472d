// ECAT event request 0x0210, masked by the ECAT event mask 0x0200 and ORed into the IRQ field
// of every datagram as the frame passes each ESC (ESC datasheet section II 0x0200/0x0210).
// The reference is soem-sdinfo-ek1100-el1004.pcapng: SOEM writes 0x0200 = 0x0004 (DL status
// event, frame 12); from frame 15 on every returning datagram carries IRQ 0x0004 until the
// master reads DL status 0x0110 of the last slave that had it pending (frame 201, whose own
// datagram still carries it); from frame 203 on the IRQ is 0x0000.
#include <gtest/gtest.h>

#include "support/test_network.hpp"

namespace ecsim::testing {
namespace {

TEST(EcatEvents, DlStatusEventUntilEachSlaveIsReadAsInTheSoemCapture) {
  topology::Segment seg;
  buildLine(seg, 2);
  one(seg, Command::kApwr, phys(0, 0x0010), le16(0x1001));
  one(seg, Command::kApwr, phys(0xFFFF, 0x0010), le16(0x1002));
  one(seg, Command::kBwr, phys(0, 0x0200), le16(0x0004));  // frame 12: DL status event only
  EXPECT_EQ(one(seg, Command::kBwr, phys(0, 0x0300), {0, 0}).irq, 0x0004) << "frame 15";
  EXPECT_EQ(one(seg, Command::kFprd, phys(0x1001, 0x0110), {0, 0}).irq, 0x0004) << "frame 129";
  EXPECT_EQ(one(seg, Command::kFprd, phys(0x1002, 0x0008), {0, 0}).irq, 0x0004)
      << "the second slave's event is still pending (frame 199)";
  EXPECT_EQ(one(seg, Command::kFprd, phys(0x1002, 0x0110), {0, 0}).irq, 0x0004)
      << "the header passes before the read clears it (frame 201)";
  EXPECT_EQ(one(seg, Command::kFprd, phys(0x1002, 0x0007), {0, 0}).irq, 0x0000) << "frame 203";
  EXPECT_EQ(seg.slave(1).esc().read(reg::kEcatEventRequest) & reg::ecat_event::kDlStatus, 0);
}

TEST(EcatEvents, DlStatusChangeSetsTheEventAgain) {
  topology::Segment seg;
  buildLine(seg, 2);
  one(seg, Command::kBwr, phys(0, 0x0200), le16(0x0004));
  one(seg, Command::kBrd, phys(0, 0x0110), {0, 0});  // clears it at both
  EXPECT_EQ(one(seg, Command::kBrd, phys(0, 0x0000), {0}).irq, 0x0000);
  // A closed port 1 at slave 0 changes its DL status (loop bit): DL status event.
  one(seg, Command::kApwr, phys(0, 0x0101), {0x0C});
  EXPECT_EQ(one(seg, Command::kBrd, phys(0, 0x0000), {0}).irq, 0x0004);
}

TEST(EcatEvents, MaskSelectsWhatReachesTheIrqFieldAndOrsIntoIt) {
  topology::Segment seg;
  buildLine(seg, 1);
  // Reset: mask 0, so nothing reaches the frames although the DL status event is pending.
  const auto r = exchange(seg, {{Command::kBrd, phys(0, 0x0210), {0, 0}}});
  EXPECT_EQ(r[0].irq, 0x0000);
  EXPECT_EQ(readLe16(r[0].data, 0), 0x0004) << "0x0210 shows the event whatever the mask";
  one(seg, Command::kBwr, phys(0, 0x0200), le16(0x0008));  // AL status event only
  EXPECT_EQ(one(seg, Command::kBrd, phys(0, 0x0000), {0}).irq, 0x0000);
}

class EcatAlEvents : public ::testing::Test {
 protected:
  void SetUp() override {
    slavesim::SlaveProfile p;
    p.mailbox = slavesim::SlaveProfile::Mailbox{0x1000, 128, 0x1080, 128};
    seg_.addSlave(makeSlave("fw", 7, p, makeSii(0xABCD, 7, 0x1000, 128, 0x1080, 128)));
    one(seg_, Command::kApwr, phys(0, 0x0010), le16(0x1001));
  }
  topology::Segment seg_;
};

TEST_F(EcatAlEvents, AlStatusEventSetByTheFirmwareClearedByReadingAlStatus) {
  one(seg_, Command::kFpwr, phys(0x1001, 0x0200), le16(0x0008));
  one(seg_, Command::kFpwr, phys(0x1001, 0x0800), smChannelBytes(0x1000, 128, 0x26));
  one(seg_, Command::kFpwr, phys(0x1001, 0x0808), smChannelBytes(0x1080, 128, 0x22));
  EXPECT_EQ(one(seg_, Command::kBrd, phys(0, 0x0000), {0}).irq, 0x0000);
  one(seg_, Command::kFpwr, phys(0x1001, 0x0120), le16(0x0002));  // the firmware goes to PREOP
  EXPECT_EQ(one(seg_, Command::kBrd, phys(0, 0x0000), {0}).irq, 0x0008);
  const auto r = one(seg_, Command::kFprd, phys(0x1001, 0x0130), {0, 0});
  EXPECT_EQ(readLe16(r.data, 0), 0x0002);
  EXPECT_EQ(r.irq, 0x0008) << "still set while the header passed";
  EXPECT_EQ(one(seg_, Command::kBrd, phys(0, 0x0000), {0}).irq, 0x0000);
}

TEST_F(EcatAlEvents, MailboxSmEventWhileAResponseWaits) {
  // SM1 with "interrupt in ECAT event request" (control bit 4); mask bit 4 + 1.
  one(seg_, Command::kFpwr, phys(0x1001, 0x0800), smChannelBytes(0x1000, 128, 0x26));
  one(seg_, Command::kFpwr, phys(0x1001, 0x0808), smChannelBytes(0x1080, 128, 0x32));
  one(seg_, Command::kFpwr, phys(0x1001, 0x0200), le16(0x0020));
  EXPECT_EQ(one(seg_, Command::kBrd, phys(0, 0x0000), {0}).irq, 0x0000);
  const std::vector<std::uint8_t> response(16, 0x5A);
  ASSERT_TRUE(seg_.slave(0).esc().pdiMailboxSend(response));
  EXPECT_EQ(one(seg_, Command::kBrd, phys(0, 0x0000), {0}).irq, 0x0020);
  one(seg_, Command::kFprd, phys(0x1001, 0x1080), std::vector<std::uint8_t>(128, 0));
  EXPECT_EQ(one(seg_, Command::kBrd, phys(0, 0x0000), {0}).irq, 0x0000) << "read: empty";
}

TEST_F(EcatAlEvents, SmEventFollowsTheControlByteWhenTheMasterReconfiguresTheSm) {
  // The SM event follows SM control bit 4 as last written (the ESC decodes it when the channel
  // is written, not on every datagram): rewritten without it while disabled, no event.
  one(seg_, Command::kFpwr, phys(0x1001, 0x0800), smChannelBytes(0x1000, 128, 0x26));
  one(seg_, Command::kFpwr, phys(0x1001, 0x0808), smChannelBytes(0x1080, 128, 0x22));
  one(seg_, Command::kFpwr, phys(0x1001, 0x0200), le16(0x0020));
  const std::vector<std::uint8_t> response(16, 0x5A);
  ASSERT_TRUE(seg_.slave(0).esc().pdiMailboxSend(response));
  EXPECT_EQ(one(seg_, Command::kBrd, phys(0, 0x0000), {0}).irq, 0x0000) << "control 0x22: none";
  one(seg_, Command::kFpwr, phys(0x1001, 0x080E), {0});  // SM1 off (its mailbox is emptied)
  one(seg_, Command::kFpwr, phys(0x1001, 0x0808), smChannelBytes(0x1080, 128, 0x32));
  ASSERT_TRUE(seg_.slave(0).esc().pdiMailboxSend(response));
  EXPECT_EQ(one(seg_, Command::kBrd, phys(0, 0x0000), {0}).irq, 0x0020) << "control 0x32";
  one(seg_, Command::kFpwr, phys(0x1001, 0x080E), {0});
  EXPECT_EQ(one(seg_, Command::kBrd, phys(0, 0x0000), {0}).irq, 0x0000) << "disabled";
  one(seg_, Command::kFpwr, phys(0x1001, 0x0808), smChannelBytes(0x1080, 128, 0x22));
  ASSERT_TRUE(seg_.slave(0).esc().pdiMailboxSend(response));
  EXPECT_EQ(one(seg_, Command::kBrd, phys(0, 0x0000), {0}).irq, 0x0000) << "control 0x22 again";
}

TEST_F(EcatAlEvents, InputBufferSmEventUntilTheMasterReadsTheNewData) {
  // SM3, 3-buffer inputs with "interrupt in ECAT event request" (control 0x30); mask bit 4 + 3.
  // Section II 0x0805: "interrupt write" is set when the writer (here the PDI) completed a
  // buffer and cleared when the reader's first byte is read; the SM's ECAT event follows it.
  one(seg_, Command::kFpwr, phys(0x1001, 0x0818), smChannelBytes(0x1180, 4, 0x30));
  one(seg_, Command::kFpwr, phys(0x1001, 0x0200), le16(0x0080));
  EXPECT_EQ(one(seg_, Command::kBrd, phys(0, 0x0000), {0}).irq, 0x0000) << "nothing written";
  const std::vector<std::uint8_t> inputs{1, 2, 3, 4};
  ASSERT_TRUE(seg_.slave(0).esc().pdiWriteInputs(3, inputs));
  EXPECT_EQ(one(seg_, Command::kBrd, phys(0, 0x0000), {0}).irq, 0x0080) << "new inputs";
  EXPECT_EQ(one(seg_, Command::kFprd, phys(0x1001, 0x1180), std::vector<std::uint8_t>(4, 0)).data,
            inputs);
  EXPECT_EQ(one(seg_, Command::kBrd, phys(0, 0x0000), {0}).irq, 0x0000) << "read by the master";
  EXPECT_NE(seg_.slave(0).esc().reg8(reg::smChannel(3) + reg::sm::kStatus.address) &
                reg::sm::kStatusInterruptRead,
            0)
      << "buffer completely read: the PDI's interrupt";
}

}  // namespace
}  // namespace ecsim::testing
