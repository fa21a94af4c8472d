// SyncManager access rules of the ESC (datasheet section I §8 "SyncManager", p. I-41): "A buffer
// has to be accessed beginning with the start address, otherwise the access is denied. After
// accessing the start address, the whole buffer can be accessed, even the start address again,
// either as a whole or in several strokes. A buffer access finishes by accessing the end
// address [...]. The end address cannot be accessed twice inside a frame." Section II Table 90
// (SM length): "shall be greater 1, otherwise SyncManager is not activated. If set to 1, only
// Watchdog Trigger is generated if configured". Section II SM status (0x0805+8n) bits 5:4 "last
// written buffer", 11 = no buffer written. And section I §14.1: a frame with an error does not
// change SyncManager buffers.
#include <gtest/gtest.h>

#include "support/esc_frames.hpp"

namespace ecsim::testing {
namespace {

constexpr std::uint8_t kOutputs3Buffer = 0x64;  // 3-buffer, ECAT write, watchdog trigger
constexpr std::uint8_t kOutputs3BufferNoWd = 0x24;
constexpr std::uint8_t kInputs3Buffer = 0x20;  // 3-buffer, ECAT read
constexpr std::uint8_t kMailboxWrite = 0x26;
constexpr std::uint8_t kMailboxRead = 0x22;

class SmRules : public ::testing::Test {
 protected:
  void SetUp() override {
    buildLine(seg_, 1);
    one(seg_, Command::kApwr, phys(0, reg::kConfiguredStationAddress.address), le16(0x1001));
  }
  slavesim::Esc& esc() { return seg_.slave(0).esc(); }
  void configure(unsigned sm, std::uint16_t start, std::uint16_t length, std::uint8_t control) {
    one(seg_, Command::kFpwr, phys(0x1001, reg::smChannel(sm)),
        smChannelBytes(start, length, control));
  }
  std::uint8_t smStatus(unsigned sm) {
    return one(seg_, Command::kFprd, phys(0x1001, reg::smChannel(sm) + reg::sm::kStatus.address),
               {0})
        .data[0];
  }
  std::vector<std::uint8_t> outputs(unsigned sm) {
    auto o = esc().pdiOutputs(sm);
    return {o.begin(), o.end()};
  }
  topology::Segment seg_;
};

TEST_F(SmRules, ThreeBufferWriteNotBeginningAtTheStartAddressIsDenied) {
  // Section I §8: the access is denied; no WKC, nothing delivered, no buffer exchange.
  configure(2, 0x1100, 4, kOutputs3Buffer);
  const std::uint8_t statusBefore = smStatus(2);
  EXPECT_EQ(one(seg_, Command::kFpwr, phys(0x1001, 0x1102), {8, 8}).wkc, 0)
      << "second half first: the buffer was never opened at its start address";
  EXPECT_FALSE(esc().pdiOutputsReceived(2)) << "no buffer completed";
  EXPECT_EQ(smStatus(2), statusBefore) << "no state change";
  EXPECT_EQ(esc().reg8(reg::kWatchdogStatusProcessData.address) & 0x01, 0)
      << "a denied write does not trigger the process-data watchdog";
  // From the start address, in two strokes (two frames): allowed.
  EXPECT_EQ(one(seg_, Command::kFpwr, phys(0x1001, 0x1100), {9, 9}).wkc, 1);
  EXPECT_EQ(one(seg_, Command::kFpwr, phys(0x1001, 0x1102), {8, 8}).wkc, 1);
  EXPECT_EQ(outputs(2), (std::vector<std::uint8_t>{9, 9, 8, 8}));
  // Closed by the end access: the next stroke must begin at the start address again.
  EXPECT_EQ(one(seg_, Command::kFpwr, phys(0x1001, 0x1102), {7, 7}).wkc, 0);
  EXPECT_EQ(outputs(2), (std::vector<std::uint8_t>{9, 9, 8, 8}));
}

TEST_F(SmRules, SeveralStrokesInOneFrameStartingAtTheStartAddress) {
  configure(2, 0x1100, 4, kOutputs3Buffer);
  auto r = exchange(seg_, {{Command::kFpwr, phys(0x1001, 0x1100), {1, 2}},
                           {Command::kFpwr, phys(0x1001, 0x1100), {3, 4}},  // start again: fine
                           {Command::kFpwr, phys(0x1001, 0x1102), {5, 6}}});
  EXPECT_EQ(r[0].wkc, 1);
  EXPECT_EQ(r[1].wkc, 1);
  EXPECT_EQ(r[2].wkc, 1);
  EXPECT_EQ(outputs(2), (std::vector<std::uint8_t>{3, 4, 5, 6}));
}

TEST_F(SmRules, MailboxAccessNotBeginningAtTheStartAddressIsDenied) {
  configure(0, 0x1000, 16, kMailboxWrite);
  configure(1, 0x1080, 16, kMailboxRead);
  // Write mailbox: the tail alone neither fills the mailbox nor counts.
  EXPECT_EQ(one(seg_, Command::kFpwr, phys(0x1001, 0x1008), std::vector<std::uint8_t>(8, 1)).wkc,
            0);
  EXPECT_EQ(esc().reg8(reg::smChannel(0) + reg::sm::kStatus.address) & reg::sm::kStatusMailboxFull,
            0);
  EXPECT_EQ(esc().counters().mailboxWrites, 0u);
  // Read mailbox holding a response: reading only its tail delivers nothing and leaves it full.
  ASSERT_TRUE(esc().pdiMailboxSend(std::vector<std::uint8_t>(16, 0x5A)));
  auto tail = one(seg_, Command::kFprd, phys(0x1001, 0x1088), std::vector<std::uint8_t>(8, 0xEE));
  EXPECT_EQ(tail.wkc, 0);
  EXPECT_EQ(tail.data, std::vector<std::uint8_t>(8, 0xEE)) << "nothing delivered";
  EXPECT_TRUE(esc().pdiMailboxResponsePending()) << "the response is still there";
  auto whole = one(seg_, Command::kFprd, phys(0x1001, 0x1080), std::vector<std::uint8_t>(16));
  EXPECT_EQ(whole.wkc, 1);
  EXPECT_EQ(whole.data, std::vector<std::uint8_t>(16, 0x5A));
  EXPECT_FALSE(esc().pdiMailboxResponsePending());
}

TEST_F(SmRules, EndAddressCannotBeAccessedTwiceInOneFrame) {
  configure(2, 0x1100, 2, kOutputs3Buffer);
  configure(3, 0x1180, 2, kInputs3Buffer);
  ASSERT_TRUE(esc().pdiWriteInputs(3, std::vector<std::uint8_t>{0x34, 0x12}));
  auto r = exchange(seg_, {{Command::kFpwr, phys(0x1001, 0x1100), {1, 2}},
                           {Command::kFpwr, phys(0x1001, 0x1100), {3, 4}},
                           {Command::kFprd, phys(0x1001, 0x1180), {0, 0}},
                           {Command::kFprd, phys(0x1001, 0x1180), {0xEE, 0xEE}}});
  EXPECT_EQ(r[0].wkc, 1);
  EXPECT_EQ(r[1].wkc, 0) << "second write of the end address in the frame: denied";
  EXPECT_EQ(outputs(2), (std::vector<std::uint8_t>{1, 2})) << "the first buffer counts";
  EXPECT_EQ(r[2].wkc, 1);
  EXPECT_EQ(r[2].data, (std::vector<std::uint8_t>{0x34, 0x12}));
  EXPECT_EQ(r[3].wkc, 0) << "second read of the end address in the frame: denied";
  EXPECT_EQ(r[3].data, (std::vector<std::uint8_t>{0xEE, 0xEE})) << "nothing delivered";
  // The rule is per frame: the next frame may access the buffer again.
  EXPECT_EQ(one(seg_, Command::kFpwr, phys(0x1001, 0x1100), {3, 4}).wkc, 1);
  EXPECT_EQ(outputs(2), (std::vector<std::uint8_t>{3, 4}));
  EXPECT_EQ(one(seg_, Command::kFprd, phys(0x1001, 0x1180), {0, 0}).wkc, 1);
}

TEST_F(SmRules, LengthOneSmIsPlainMemoryOnlyTriggeringTheWatchdog) {
  // Section II Table 90: length 1 does not activate the SM; only the watchdog trigger works.
  // Real digital terminals configure exactly this (EL2004: 0x0F00, 1 byte, control 0x44 in
  // ../shared/esi/Beckhoff_EtherCAT_Terminals.xml; EL1xxx inputs: 0x1000, 1 byte).
  configure(2, 0x1000, 1, kOutputs3Buffer);
  configure(3, 0x1001, 1, kOutputs3BufferNoWd);
  EXPECT_EQ(one(seg_, Command::kFpwr, phys(0x1001, 0x1001), {0x11}).wkc, 1);
  EXPECT_EQ(esc().reg8(reg::kWatchdogStatusProcessData.address) & 0x01, 0)
      << "SM3 has no watchdog trigger bit";
  EXPECT_EQ(one(seg_, Command::kFpwr, phys(0x1001, 0x1000), {0x5A}).wkc, 1);
  EXPECT_EQ(esc().reg8(0x1000), 0x5A) << "written into the memory itself, no hidden buffer";
  EXPECT_EQ(esc().reg8(reg::kWatchdogStatusProcessData.address) & 0x01, 0x01)
      << "the watchdog trigger still works";
  EXPECT_EQ(smStatus(2) & (reg::sm::kStatusInterruptWrite | reg::sm::kStatusBufferMask), 0)
      << "no buffer logic: no write event, no buffer number";
  EXPECT_EQ(one(seg_, Command::kFpwr, phys(0x1001, 0x1000), {0x5B}).wkc, 1)
      << "no end-address rule either (plain memory)";
  EXPECT_TRUE(esc().pdiOutputsReceived(2));
  EXPECT_EQ(outputs(2), (std::vector<std::uint8_t>{0x5B}));
  // The digital-output register of an EL2004-style SM at 0x0F00 keeps what the master wrote.
  configure(4, reg::kDigitalIoOutputData.address, 1, 0x44);
  one(seg_, Command::kFpwr, phys(0x1001, reg::kDigitalIoOutputData.address), {0x0F});
  EXPECT_EQ(esc().reg8(reg::kDigitalIoOutputData.address), 0x0F);
}

TEST_F(SmRules, LengthOneInputSmIsReadFromMemory) {
  configure(3, 0x1000, 1, 0x00);  // EL1xxx: inputs, 1 byte at 0x1000, control 0x00
  ASSERT_TRUE(esc().pdiWriteInputs(3, std::vector<std::uint8_t>{0x3C}));
  EXPECT_EQ(esc().reg8(0x1000), 0x3C);
  auto r = exchange(seg_, {{Command::kFprd, phys(0x1001, 0x1000), {0}},
                           {Command::kFprd, phys(0x1001, 0x1000), {0}}});
  EXPECT_EQ(r[0].data[0], 0x3C);
  EXPECT_EQ(r[1].wkc, 1) << "plain memory: may be read twice in one frame";
}

TEST_F(SmRules, FreshlyActivatedThreeBufferSmReportsNoBufferWritten) {
  // Section II SM status bits 5:4: "Buffered mode: last written buffer ... 11: (no buffer
  // written)"; an SM that was just activated has none.
  configure(2, 0x1100, 2, kOutputs3Buffer);
  configure(3, 0x1180, 2, kInputs3Buffer);
  EXPECT_EQ(smStatus(2) & reg::sm::kStatusBufferMask, reg::sm::kStatusBufferMask);
  EXPECT_EQ(smStatus(3) & reg::sm::kStatusBufferMask, reg::sm::kStatusBufferMask);
  one(seg_, Command::kFpwr, phys(0x1001, 0x1100), {1, 2});
  EXPECT_NE(smStatus(2) & reg::sm::kStatusBufferMask, reg::sm::kStatusBufferMask)
      << "a buffer was written";
  ASSERT_TRUE(esc().pdiWriteInputs(3, std::vector<std::uint8_t>{1, 2}));
  EXPECT_NE(smStatus(3) & reg::sm::kStatusBufferMask, reg::sm::kStatusBufferMask)
      << "the PDI wrote a buffer";
  // Deactivated and activated again: fresh again.
  one(seg_, Command::kFpwr, phys(0x1001, reg::smChannel(2) + reg::sm::kActivate.address), {0});
  one(seg_, Command::kFpwr, phys(0x1001, reg::smChannel(2) + reg::sm::kActivate.address), {1});
  EXPECT_EQ(smStatus(2) & reg::sm::kStatusBufferMask, reg::sm::kStatusBufferMask);
}

// Section II SM PDI control 0x0807+8n bit 0 "Deactivate SyncManager": the firmware switches an
// SM off; its mailbox and buffers are gone for the PDI until it switches it on again. (The ESC
// keeps each SM's configuration decoded from the last write of its channel: this checks that a
// PDI write of the channel reaches that cache as an ECAT write does.)
TEST_F(SmRules, SmDeactivatedByThePdiHasNoMailboxAndNoBuffers) {
  configure(0, 0x1000, 64, kMailboxWrite);
  configure(1, 0x1080, 64, kMailboxRead);
  configure(2, 0x1100, 2, kOutputs3BufferNoWd);
  one(seg_, Command::kFpwr, phys(0x1001, 0x1100), {7, 8});
  ASSERT_TRUE(esc().pdiMailboxAvailable());
  ASSERT_EQ(outputs(2), (std::vector<std::uint8_t>{7, 8}));
  const auto pdiControl = [](unsigned sm) {
    return static_cast<std::uint16_t>(reg::smChannel(sm) + reg::sm::kPdiControl.address);
  };
  esc().pdiWrite8(pdiControl(1), reg::sm::kPdiDeactivate);
  esc().pdiWrite8(pdiControl(2), reg::sm::kPdiDeactivate);
  EXPECT_FALSE(esc().pdiMailboxAvailable());
  EXPECT_FALSE(esc().pdiMailboxSend(std::vector<std::uint8_t>(8, 1)));
  EXPECT_TRUE(outputs(2).empty());
  esc().pdiWrite8(pdiControl(1), 0);
  esc().pdiWrite8(pdiControl(2), 0);
  EXPECT_TRUE(esc().pdiMailboxAvailable());
  EXPECT_TRUE(esc().pdiMailboxSend(std::vector<std::uint8_t>(8, 1)));
  EXPECT_EQ(outputs(2), (std::vector<std::uint8_t>{7, 8}));
}

// Section I §14.1: with a frame error the processing unit discards "SyncManager buffer changes";
// RAM is written. The corruption happens on the cable into the slave's port 0.
TEST_F(SmRules, InvalidFrameChangesNoSyncManagerState) {
  configure(1, 0x1080, 16, kMailboxRead);
  configure(2, 0x1100, 2, kOutputs3Buffer);
  ASSERT_TRUE(esc().pdiMailboxSend(std::vector<std::uint8_t>(16, 0x5A)));
  const std::uint8_t status2 = smStatus(2);
  EXPECT_FALSE(sendCorrupted(seg_, 0,
                             {{Command::kFprd, phys(0x1001, 0x1080), std::vector<std::uint8_t>(16)},
                              {Command::kFpwr, phys(0x1001, 0x1100), {1, 2}},
                              {Command::kFpwr, phys(0x1001, 0x1200), {3, 4}}}))
      << "a corrupted frame stays lost for the master";
  EXPECT_TRUE(esc().pdiMailboxResponsePending()) << "the read mailbox was not emptied";
  EXPECT_FALSE(esc().pdiOutputsReceived(2)) << "no buffer exchange";
  EXPECT_EQ(smStatus(2), status2);
  EXPECT_EQ(esc().reg8(reg::kWatchdogStatusProcessData.address) & 0x01, 0)
      << "no watchdog trigger from a discarded SM write";
  EXPECT_EQ(esc().reg8(0x1200), 3) << "process RAM outside any SM is written on the fly";
  EXPECT_EQ(esc().reg8(0x1201), 4);
  // The SM open/closed state was not touched either: a valid frame works as usual.
  EXPECT_EQ(one(seg_, Command::kFpwr, phys(0x1001, 0x1100), {5, 6}).wkc, 1);
  EXPECT_EQ(outputs(2), (std::vector<std::uint8_t>{5, 6}));
}

}  // namespace
}  // namespace ecsim::testing
