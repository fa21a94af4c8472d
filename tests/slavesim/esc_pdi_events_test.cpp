// SyncManager events of the write direction: the PDI (firmware) reading a buffer the master
// wrote. ESC datasheet section II, SyncManager status register 0x0805+8n: bit 0 "interrupt
// write" is set when a buffer was completely written and cleared when the first byte is read;
// bit 1 "interrupt read" is set when a buffer was completely read and cleared when the first
// byte is written; each is signalled to the other side, to the master as the SM's ECAT event
// (0x0210 bit 4+n, section II 0x0210 "mirrors values of each SyncManager status") when SM
// control bit 4 is set, masked by 0x0200 into the datagrams' IRQ field.
//
// Reference: a real EL3004 in ../shared/pcap/replay-ek1914-el3004-mailbox.pcapng. Its SM0
// (mailbox the master writes) reads 0x02 after its firmware took a request (frames 970, 984):
// empty, "interrupt read"; its SM1 reads 0x09 while a response waits (frames 964, 978, 992):
// full, "interrupt write".
#include <gtest/gtest.h>

#include "coe_test_support.hpp"
#include "support/test_network.hpp"

namespace ecsim::testing {
namespace {

constexpr std::uint16_t kSm0Status = reg::smChannel(0) + reg::sm::kStatus.address;
constexpr std::uint16_t kSm1Status = reg::smChannel(1) + reg::sm::kStatus.address;
constexpr std::uint16_t kSm2Status = reg::smChannel(2) + reg::sm::kStatus.address;

// Firmware whose mailbox server takes every request and answers nothing.
class SwallowingServer final : public slavesim::MailboxServer {
 public:
  void onRequest(slavesim::Esc& /*esc*/, ConstBytes /*mailbox*/, SimTime /*now*/) override {
    ++requests;
  }
  int requests{0};
};

class PdiSmEvents : public ::testing::Test {
 protected:
  void SetUp() override {
    slavesim::SlaveProfile p;
    p.mailbox = slavesim::SlaveProfile::Mailbox{0x1000, 128, 0x1080, 128};
    auto slave = makeSlave("fw", 7, p, makeSii(0xABCD, 7, 0x1000, 128, 0x1080, 128));
    auto server = std::make_unique<SwallowingServer>();
    server_ = server.get();
    slave->setMailboxServer(std::move(server));
    seg_.addSlave(std::move(slave));
    one(seg_, Command::kApwr, phys(0, 0x0010), le16(0x1001));
  }
  slavesim::Esc& esc() { return seg_.slave(0).esc(); }
  // One datagram through the ESC without running the firmware after it.
  DatagramResult escOnly(Command c, std::uint16_t ado, std::vector<std::uint8_t> data) {
    return exchange(seg_, {{c, phys(0x1001, ado), std::move(data)}}, 0, false).at(0);
  }
  topology::Segment seg_;
  SwallowingServer* server_{nullptr};
};

TEST_F(PdiSmEvents, FirmwareTakingAMailboxRequestIsSm0sEventAsOnTheEl3004) {
  // SM0 with "interrupt in ECAT event request" (control 0x26 | 0x10); mask bit 4 + 0.
  one(seg_, Command::kFpwr, phys(0x1001, 0x0800), smChannelBytes(0x1000, 128, 0x36));
  one(seg_, Command::kFpwr, phys(0x1001, 0x0808), smChannelBytes(0x1080, 128, 0x22));
  one(seg_, Command::kFpwr, phys(0x1001, 0x0200), le16(0x0010));
  EXPECT_EQ(esc().reg8(kSm0Status), 0x00) << "frame 956: nothing written yet";
  EXPECT_EQ(escOnly(Command::kBrd, 0x0000, {0}).irq, 0x0000);

  // The master writes a request; the firmware has not run yet: full, "interrupt write" (the
  // PDI's interrupt), no event for the master.
  EXPECT_EQ(escOnly(Command::kFpwr, 0x1000, std::vector<std::uint8_t>(128, 0x11)).wkc, 1);
  EXPECT_EQ(esc().reg8(kSm0Status), reg::sm::kStatusMailboxFull | reg::sm::kStatusInterruptWrite);
  EXPECT_EQ(escOnly(Command::kBrd, 0x0000, {0}).irq, 0x0000);

  // The firmware reads it (Slave::poll -> Esc::pdiMailboxReceive): empty, "interrupt read".
  seg_.pollSlaves(0);
  EXPECT_EQ(server_->requests, 1);
  EXPECT_EQ(escOnly(Command::kFprd, kSm0Status, {0}).data[0], 0x02) << "frames 970, 984";
  EXPECT_EQ(escOnly(Command::kBrd, 0x0000, {0}).irq, 0x0010) << "SM0 event for the master";
  EXPECT_NE(esc().read(reg::kEcatEventRequest) & 0x0010, 0);

  // The master's next request: its first byte clears "interrupt read" (the header of that
  // datagram passed before it and still carries the event).
  EXPECT_EQ(escOnly(Command::kFpwr, 0x1000, std::vector<std::uint8_t>(128, 0x22)).irq, 0x0010);
  EXPECT_EQ(esc().reg8(kSm0Status) & reg::sm::kStatusInterruptRead, 0);
  EXPECT_EQ(escOnly(Command::kBrd, 0x0000, {0}).irq, 0x0000);
}

TEST_F(PdiSmEvents, MailboxEventStaysOutOfTheIrqFieldWithoutControlBit4) {
  one(seg_, Command::kFpwr, phys(0x1001, 0x0800), smChannelBytes(0x1000, 128, 0x26));
  one(seg_, Command::kFpwr, phys(0x1001, 0x0808), smChannelBytes(0x1080, 128, 0x22));
  one(seg_, Command::kFpwr, phys(0x1001, 0x0200), le16(0x0010));
  one(seg_, Command::kFpwr, phys(0x1001, 0x1000), std::vector<std::uint8_t>(128, 0x11));
  EXPECT_EQ(esc().reg8(kSm0Status), 0x02) << "the status shows the read all the same";
  EXPECT_EQ(escOnly(Command::kBrd, 0x0000, {0}).irq, 0x0000);
}

TEST_F(PdiSmEvents, ResponseWaitingShowsInterruptWriteAsOnTheEl3004) {
  one(seg_, Command::kFpwr, phys(0x1001, 0x0800), smChannelBytes(0x1000, 128, 0x26));
  one(seg_, Command::kFpwr, phys(0x1001, 0x0808), smChannelBytes(0x1080, 128, 0x22));
  ASSERT_TRUE(esc().pdiMailboxSend(std::vector<std::uint8_t>(16, 0x5A)));
  EXPECT_EQ(escOnly(Command::kFprd, kSm1Status, {0}).data[0], 0x09) << "frames 964, 978, 992";
  // The master reads it: the first byte clears "interrupt write", the end empties the mailbox
  // and sets "interrupt read" (the PDI's interrupt; the EL3004's firmware then opens its
  // buffer again at once, 0x80 in frame 968, which is the firmware's doing).
  escOnly(Command::kFprd, 0x1080, std::vector<std::uint8_t>(128, 0));
  EXPECT_EQ(esc().reg8(kSm1Status), reg::sm::kStatusInterruptRead);
  // The firmware's next response: "interrupt read" cleared by its first byte.
  ASSERT_TRUE(esc().pdiMailboxSend(std::vector<std::uint8_t>(16, 0x5B)));
  EXPECT_EQ(esc().reg8(kSm1Status), 0x09);
}

TEST_F(PdiSmEvents, ThreeBufferOutputsReadByThePdiAreTheSmEvent) {
  // SM2: 3-buffer, ECAT writes, "interrupt in ECAT event request" (0x04 | 0x10); mask bit 4+2.
  one(seg_, Command::kFpwr, phys(0x1001, 0x0810), smChannelBytes(0x1100, 4, 0x14));
  one(seg_, Command::kFpwr, phys(0x1001, 0x0200), le16(0x0040));
  escOnly(Command::kFpwr, 0x1100, {1, 2, 3, 4});
  EXPECT_EQ(esc().reg8(kSm2Status) & 0x03, reg::sm::kStatusInterruptWrite);
  EXPECT_EQ(escOnly(Command::kBrd, 0x0000, {0}).irq, 0x0000) << "not read by the PDI yet";
  const ConstBytes out = esc().pdiReadOutputs(2);
  ASSERT_EQ(out.size(), 4u);
  EXPECT_EQ(out[3], 4);
  EXPECT_EQ(esc().reg8(kSm2Status) & 0x03, reg::sm::kStatusInterruptRead);
  EXPECT_EQ(escOnly(Command::kBrd, 0x0000, {0}).irq, 0x0040);
  // A write that does not begin at the start address is denied and clears nothing.
  EXPECT_EQ(escOnly(Command::kFpwr, 0x1102, {9, 9}).wkc, 0);
  EXPECT_EQ(escOnly(Command::kBrd, 0x0000, {0}).irq, 0x0040);
  // The master's next buffer: the first byte clears it.
  escOnly(Command::kFpwr, 0x1100, {5, 6, 7, 8});
  EXPECT_EQ(escOnly(Command::kBrd, 0x0000, {0}).irq, 0x0000);
  // Looking at the outputs (tests, inspection) is no PDI read.
  (void)esc().pdiOutputs(2);
  EXPECT_EQ(esc().reg8(kSm2Status) & 0x03, reg::sm::kStatusInterruptWrite);
}

TEST(PdiSmEventsDevice, TheDevicesOutputCopyIsAPdiReadOfTheWholeBuffer) {
  // A dictionary-based device (ProcessDataDevice) takes its outputs each firmware step: the
  // SM2 status then shows the PDI's read, as on an ESC whose firmware reads SM2 every cycle.
  CoeTestSlave t;
  ASSERT_EQ(t.toSafeOp(), 0x0004);
  exchange(t.seg, {{Command::kLrw, 0, {0xFB, 0x34, 0x12, 0, 0, 0, 0}}}, 0, false);
  auto& esc = t.seg.slave(0).esc();
  EXPECT_EQ(esc.reg8(kSm2Status) & 0x03, reg::sm::kStatusInterruptWrite) << "before the step";
  t.seg.pollSlaves(0);
  EXPECT_EQ(esc.reg8(kSm2Status) & 0x03, reg::sm::kStatusInterruptRead) << "after the step";
  EXPECT_EQ(t.od->get<std::uint16_t>(0x7000, 3).value(), 0x1234);
}

}  // namespace
}  // namespace ecsim::testing
