// SyncManager and FMMU channels (ESC datasheet section II: SyncManager 0x0800-0x087F, FMMU
// 0x0600-0x06FF) against the bytes real masters wrote to real ESCs.
#include "protocol/esc_blocks.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>

namespace ecsim {
namespace {

using Sm = std::array<std::uint8_t, reg::kSmSize>;
using Fmmu = std::array<std::uint8_t, reg::kFmmuSize>;

// ../shared/pcap/replay-dc.pcapng frame 2381: EtherCrab FPWR 0x1001:0x0800 (EL2828 SM0).
constexpr Sm kEl2828Sm0 = {0x00, 0x0F, 0x01, 0x00, 0x44, 0x00, 0x01, 0x00};
// replay-dc.pcapng frame 2385: FPWR 0x1001:0x0600 (EL2828 FMMU0, output byte 0 -> 0x0F00).
constexpr Fmmu kEl2828Fmmu0 = {0x00, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x07,
                               0x00, 0x0F, 0x00, 0x02, 0x01, 0x00, 0x00, 0x00};
// replay-dc.pcapng frame 3019: FPWR 0x1002:0x0610 (EL2889 FMMU1, logical 2 -> 0x0F01).
constexpr Fmmu kEl2889Fmmu1 = {0x02, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x07,
                               0x01, 0x0F, 0x00, 0x02, 0x01, 0x00, 0x00, 0x00};
// ../shared/pcap/replay-ek1914-el3004-mailbox.pcapng frames 741 and 743: FPWR 0x1000:0x0800
// and 0x0808 (EK1914 mailbox SM0 at 0x1000 and SM1 at 0x1100, 256 bytes each).
constexpr Sm kEk1914Sm0 = {0x00, 0x10, 0x00, 0x01, 0x26, 0x00, 0x01, 0x00};
constexpr Sm kEk1914Sm1 = {0x00, 0x11, 0x00, 0x01, 0x22, 0x00, 0x01, 0x00};

TEST(SyncManagerBlock, ParsesTheThreeBufferOutputSmEtherCrabWroteToAnEl2828) {
  auto sm = SyncManagerBlock::parse(kEl2828Sm0);
  ASSERT_TRUE(sm.ok()) << sm.error().message();
  EXPECT_EQ(sm->start, 0x0F00);
  EXPECT_EQ(sm->length, 1);
  EXPECT_EQ(sm->control.mode, SmMode::kBuffered);
  EXPECT_EQ(sm->control.direction, SmDirection::kEcatWrite);
  EXPECT_FALSE(sm->control.ecatEvent);
  EXPECT_FALSE(sm->control.pdiEvent);
  EXPECT_TRUE(sm->control.watchdogTrigger);
  EXPECT_EQ(sm->status, SmStatus{});
  EXPECT_TRUE(sm->activate.enable);
  EXPECT_FALSE(sm->activate.repeatRequest);
  EXPECT_EQ(sm->pdiControl, SmPdiControl{});
  EXPECT_EQ(sm->bytes(), kEl2828Sm0);
}

TEST(SyncManagerBlock, ParsesTheMailboxSmsEtherCrabWroteToAnEk1914) {
  auto out = SyncManagerBlock::parse(kEk1914Sm0);
  auto in = SyncManagerBlock::parse(kEk1914Sm1);
  ASSERT_TRUE(out.ok() && in.ok());
  EXPECT_EQ(out->start, 0x1000);
  EXPECT_EQ(in->start, 0x1100);
  EXPECT_EQ(out->length, 0x100);
  EXPECT_TRUE(out->control.isMailbox());
  EXPECT_TRUE(out->control.isEcatWrite());
  EXPECT_TRUE(out->control.pdiEvent);
  EXPECT_TRUE(in->control.isMailbox());
  EXPECT_EQ(in->control.direction, SmDirection::kEcatRead);
  EXPECT_EQ(out->bytes(), kEk1914Sm0);
  EXPECT_EQ(in->bytes(), kEk1914Sm1);
}

// The master builds the channel from the EL2828's SII SyncManager category
// (../shared/eeprom/el2828.hex byte 0x1A6: 000f 0100 44 00 09 03 = start 0x0F00, length 1,
// control 0x44, enable byte 0x09 = enable + "OP only", type outputs) and writes what EtherCrab
// wrote in frame 2381: the control byte as the SII has it, activate = enable only.
TEST(SyncManagerBlock, BuiltFromTheSiiEntryEmitsWhatARealMasterWrote) {
  SyncManagerBlock sm;
  sm.start = 0x0F00;
  sm.length = 1;
  sm.control = SmControl::decode(0x44);
  sm.activate.enable = true;
  EXPECT_EQ(sm.bytes(), kEl2828Sm0);
}

// Section II 0x0805: bits 5:4 "buffered mode: 00 1st buffer, 01 2nd, 10 3rd, 11 no buffer
// written"; 0x0806 bits 6/7 latch events; 0x0807 bit 0 deactivate, bit 1 repeat ack.
TEST(SyncManagerBlock, DecodesStatusActivateAndPdiControlBits) {
  const Sm bytes = {0x00, 0x10, 0x80, 0x00, 0x36, 0xF9, 0xC3, 0x03};
  auto sm = SyncManagerBlock::parse(bytes);
  ASSERT_TRUE(sm.ok());
  EXPECT_TRUE(sm->control.ecatEvent);
  EXPECT_TRUE(sm->control.pdiEvent);
  EXPECT_TRUE(sm->status.interruptWrite);
  EXPECT_FALSE(sm->status.interruptRead);
  EXPECT_TRUE(sm->status.mailboxFull);
  EXPECT_EQ(sm->status.lastBuffer, 3);
  EXPECT_TRUE(sm->status.readBufferOpen);
  EXPECT_TRUE(sm->status.writeBufferOpen);
  EXPECT_TRUE(sm->activate.enable && sm->activate.repeatRequest);
  EXPECT_TRUE(sm->activate.latchEcat && sm->activate.latchPdi);
  EXPECT_TRUE(sm->pdiControl.deactivate && sm->pdiControl.repeatAck);
  EXPECT_EQ(sm->bytes(), bytes);
}

// Reserved bits (control bit 7, status bit 2, activate bits 5:2, PDI control bits 7:2) and the
// reserved mode/direction values survive parse and emit.
TEST(SyncManagerBlock, KeepsReservedBitsAndValues) {
  const Sm bytes = {0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF};
  auto sm = SyncManagerBlock::parse(bytes);
  ASSERT_TRUE(sm.ok());
  EXPECT_EQ(sm->control.mode, SmMode::kReserved3);
  EXPECT_EQ(sm->control.direction, SmDirection::kReserved3);
  EXPECT_EQ(sm->control.reserved, 0x80);
  EXPECT_EQ(sm->status.reserved, 0x04);
  EXPECT_EQ(sm->activate.reserved, 0x3C);
  EXPECT_EQ(sm->pdiControl.reserved, 0xFC);
  EXPECT_EQ(sm->bytes(), bytes);
}

TEST(SyncManagerBlock, ShortInputIsAnErrorNamingTheSizes) {
  auto sm = SyncManagerBlock::parse(ConstBytes(kEl2828Sm0).first(7));
  ASSERT_FALSE(sm.ok());
  EXPECT_EQ(sm.error().code, ErrorCode::kTruncated);
  EXPECT_NE(sm.error().context.find("7 bytes"), std::string::npos) << sm.error().context;
  EXPECT_NE(sm.error().context.find("8"), std::string::npos);
}

TEST(FmmuBlock, ParsesTheOutputFmmusEtherCrabWroteToAnEl2828AndEl2889) {
  auto f = FmmuBlock::parse(kEl2828Fmmu0);
  ASSERT_TRUE(f.ok()) << f.error().message();
  EXPECT_EQ(f->logicalStart, 0u);
  EXPECT_EQ(f->length, 1);
  EXPECT_EQ(f->logicalStartBit, 0);
  EXPECT_EQ(f->logicalStopBit, 7);
  EXPECT_EQ(f->physicalStart, 0x0F00);
  EXPECT_EQ(f->physicalStartBit, 0);
  EXPECT_FALSE(f->read);
  EXPECT_TRUE(f->write);
  EXPECT_TRUE(f->enable);
  EXPECT_EQ(f->bytes(), kEl2828Fmmu0);

  auto g = FmmuBlock::parse(kEl2889Fmmu1);
  ASSERT_TRUE(g.ok());
  EXPECT_EQ(g->logicalStart, 2u);
  EXPECT_EQ(g->physicalStart, 0x0F01);
  EXPECT_EQ(g->bytes(), kEl2889Fmmu1);
}

// What our master's layout produces for that EL2828 output (process_image.cpp fmmusOf):
// the same channel EtherCrab wrote.
TEST(FmmuBlock, BuiltFieldByFieldEmitsWhatARealMasterWrote) {
  FmmuBlock f;
  f.logicalStart = 0;
  f.length = 1;
  f.physicalStart = 0x0F00;
  f.write = true;
  f.enable = true;
  EXPECT_EQ(f.bytes(), kEl2828Fmmu0);
}

TEST(FmmuBlock, KeepsReservedBitsAndBytes) {
  Fmmu bytes{};
  bytes.fill(0xA5);
  auto f = FmmuBlock::parse(bytes);
  ASSERT_TRUE(f.ok());
  EXPECT_TRUE(f->read);
  EXPECT_FALSE(f->write);
  EXPECT_EQ(f->typeReserved, 0xA4);
  EXPECT_TRUE(f->enable);
  EXPECT_EQ(f->activateReserved, 0xA4);
  EXPECT_EQ(f->reserved, (std::array<std::uint8_t, 3>{0xA5, 0xA5, 0xA5}));
  EXPECT_EQ(f->bytes(), bytes);
}

TEST(FmmuBlock, ShortInputIsAnError) {
  auto f = FmmuBlock::parse(ConstBytes(kEl2828Fmmu0).first(12));
  ASSERT_FALSE(f.ok());
  EXPECT_EQ(f.error().code, ErrorCode::kTruncated);
  EXPECT_NE(f.error().context.find("FMMU"), std::string::npos);
}

}  // namespace
}  // namespace ecsim
