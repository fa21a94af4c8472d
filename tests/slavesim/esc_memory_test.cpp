// FMMU logical mapping (byte and bit granular), SyncManager mailbox and 3-buffer semantics,
// and the SII EEPROM interface, against the ESC datasheet section I (§5 FMMU, §6 SyncManager,
// §11 SII EEPROM) and section II register descriptions.
#include <gtest/gtest.h>

#include "support/test_network.hpp"

namespace ecsim::testing {
namespace {

std::vector<std::uint8_t> fmmuBytes(std::uint32_t logical, std::uint16_t length,
                                    std::uint8_t startBit, std::uint8_t stopBit,
                                    std::uint16_t physical, std::uint8_t physBit,
                                    std::uint8_t type) {
  std::vector<std::uint8_t> f(16, 0);
  writeLe32(f, 0, logical);
  writeLe16(f, 4, length);
  f[6] = startBit;
  f[7] = stopBit;
  writeLe16(f, 8, physical);
  f[10] = physBit;
  f[11] = type;
  f[12] = 1;
  return f;
}

class Memory : public ::testing::Test {
 protected:
  void SetUp() override {
    buildLine(seg_, 2);
    for (std::uint16_t i = 0; i < 2; ++i) {
      one(seg_, Command::kApwr, phys(static_cast<std::uint16_t>(-i), 0x0010),
          le16(static_cast<std::uint16_t>(0x1001 + i)));
    }
  }
  slavesim::Esc& esc(std::size_t i) { return seg_.slave(i).esc(); }
  topology::Segment seg_;
};

TEST_F(Memory, LrwByteAlignedOutputsAndInputs) {
  // Slave 1: outputs SM2 at 0x1100 (2 B) <- logical 0..1, inputs SM3 at 0x1180 (2 B) -> 2..3.
  one(seg_, Command::kFpwr, phys(0x1001, 0x0810), smChannelBytes(0x1100, 2, 0x64));
  one(seg_, Command::kFpwr, phys(0x1001, 0x0818), smChannelBytes(0x1180, 2, 0x20));
  one(seg_, Command::kFpwr, phys(0x1001, 0x0600), fmmuBytes(0, 2, 0, 7, 0x1100, 0, 2));
  one(seg_, Command::kFpwr, phys(0x1001, 0x0610), fmmuBytes(2, 2, 0, 7, 0x1180, 0, 1));
  std::vector<std::uint8_t> in{0x34, 0x12};
  ASSERT_TRUE(esc(0).pdiWriteInputs(3, in));
  auto r = one(seg_, Command::kLrw, 0, {0xAA, 0xBB, 0, 0});
  EXPECT_EQ(r.wkc, 3) << "+2 for the write FMMU hit, +1 for the read";
  EXPECT_EQ(r.data, (std::vector<std::uint8_t>{0xAA, 0xBB, 0x34, 0x12}));
  auto out = esc(0).pdiOutputs(2);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0], 0xAA);
  EXPECT_EQ(out[1], 0xBB);
  EXPECT_TRUE(esc(0).pdiOutputsReceived(2));
  EXPECT_EQ(esc(1).pdiOutputs(2).size(), 0u) << "slave 2 has no outputs configured";
}

TEST_F(Memory, LrdAndLwrUseOnlyTheirDirection) {
  one(seg_, Command::kFpwr, phys(0x1001, 0x0600), fmmuBytes(0x100, 1, 0, 7, 0x1000, 0, 2));
  one(seg_, Command::kFpwr, phys(0x1001, 0x0610), fmmuBytes(0x101, 1, 0, 7, 0x1001, 0, 1));
  esc(0).pdiWrite8(0x1001, 0x77);
  auto rd = one(seg_, Command::kLrd, 0x100, {0x11, 0x22});
  EXPECT_EQ(rd.wkc, 1);
  EXPECT_EQ(rd.data, (std::vector<std::uint8_t>{0x11, 0x77}));
  auto wr = one(seg_, Command::kLwr, 0x100, {0x99, 0x22});
  EXPECT_EQ(wr.wkc, 1);
  EXPECT_EQ(esc(0).reg8(0x1000), 0x99);
  EXPECT_EQ(esc(0).reg8(0x1001), 0x77) << "LWR does not write through a read FMMU";
}

TEST_F(Memory, LogicalWkcCountsPerSlaveNotPerFmmu) {
  for (std::uint16_t s = 0; s < 2; ++s) {
    auto adp = static_cast<std::uint16_t>(0x1001 + s);
    one(seg_, Command::kFpwr, phys(adp, 0x0600), fmmuBytes(s * 2u, 1, 0, 7, 0x1000, 0, 2));
    one(seg_, Command::kFpwr, phys(adp, 0x0610), fmmuBytes(s * 2u + 1, 1, 0, 7, 0x1001, 0, 2));
  }
  EXPECT_EQ(one(seg_, Command::kLwr, 0, {1, 2, 3, 4}).wkc, 2);
  EXPECT_EQ(one(seg_, Command::kLrw, 0, {1, 2, 3, 4}).wkc, 4);
}

TEST_F(Memory, FmmuBitGranularMapping) {
  // Logical 0x10 bits 3..5 -> physical 0x1000 bits 0..2 (write), and physical 0x1001 bits
  // 4..5 -> logical 0x10 bits 6..7 (read).
  one(seg_, Command::kFpwr, phys(0x1001, 0x0600), fmmuBytes(0x10, 1, 3, 5, 0x1000, 0, 2));
  one(seg_, Command::kFpwr, phys(0x1001, 0x0610), fmmuBytes(0x10, 1, 6, 7, 0x1001, 4, 1));
  esc(0).pdiWrite8(0x1000, 0xF8);
  esc(0).pdiWrite8(0x1001, 0x20);  // bit 5 set -> logical bit 7
  auto r = one(seg_, Command::kLrw, 0x10, {0b0010'1000});
  EXPECT_EQ(r.wkc, 3);
  EXPECT_EQ(esc(0).reg8(0x1000), 0xF8 | 0b101) << "bits 3,5 of the datagram land in bits 0,2";
  EXPECT_EQ(r.data[0], 0b1010'1000) << "bit 7 read from physical bit 5, bit 6 cleared";
}

TEST_F(Memory, FmmuSpanningDatagramBoundary) {
  one(seg_, Command::kFpwr, phys(0x1001, 0x0600), fmmuBytes(0x1E, 4, 0, 7, 0x1000, 0, 2));
  auto r = one(seg_, Command::kLwr, 0x20, {0xAB, 0xCD, 0xEF});
  EXPECT_EQ(r.wkc, 1);
  EXPECT_EQ(esc(0).reg8(0x1002), 0xAB);
  EXPECT_EQ(esc(0).reg8(0x1003), 0xCD);
  EXPECT_EQ(esc(0).reg8(0x1000), 0x00);
}

TEST_F(Memory, LogicalWithoutMatchingFmmuGetsNoWkc) {
  EXPECT_EQ(one(seg_, Command::kLrw, 0x5000, {1, 2}).wkc, 0);
}

TEST_F(Memory, MailboxWriteSetsFullAndRefusesASecondWrite) {
  one(seg_, Command::kFpwr, phys(0x1001, 0x0800), smChannelBytes(0x1000, 16, 0x26));
  std::vector<std::uint8_t> msg(16, 0x42);
  EXPECT_EQ(one(seg_, Command::kFpwr, phys(0x1001, 0x1000), msg).wkc, 1);
  EXPECT_EQ(esc(0).reg8(0x0805) & 0x08, 0x08) << "SM0 status: mailbox full";
  EXPECT_EQ(one(seg_, Command::kFpwr, phys(0x1001, 0x1000), msg).wkc, 0) << "full: refused";
  std::vector<std::uint8_t> got(16);
  EXPECT_EQ(esc(0).pdiMailboxReceive(got), 16u) << "the firmware takes the request";
  EXPECT_EQ(got[15], 0x42);
  EXPECT_EQ(esc(0).reg8(0x0805) & 0x08, 0) << "and SM0 is free again";
  EXPECT_EQ(one(seg_, Command::kFpwr, phys(0x1001, 0x1000), msg).wkc, 1);
}

TEST_F(Memory, MailboxReadOnlyWhenFullAndLastByteEmptiesIt) {
  one(seg_, Command::kFpwr, phys(0x1001, 0x0800), smChannelBytes(0x1000, 16, 0x26));
  one(seg_, Command::kFpwr, phys(0x1001, 0x0808), smChannelBytes(0x1080, 16, 0x22));
  EXPECT_EQ(one(seg_, Command::kFprd, phys(0x1001, 0x1080), std::vector<std::uint8_t>(16)).wkc, 0)
      << "empty read mailbox: no WKC";
  std::vector<std::uint8_t> answer{1, 2, 3, 4};
  ASSERT_TRUE(esc(0).pdiMailboxSend(answer));
  EXPECT_FALSE(esc(0).pdiMailboxSend(answer)) << "SM1 still full";
  EXPECT_EQ(one(seg_, Command::kFprd, phys(0x1001, 0x080D), {0}).data[0] & 0x08, 0x08);
  auto partial = one(seg_, Command::kFprd, phys(0x1001, 0x1080), std::vector<std::uint8_t>(8));
  EXPECT_EQ(partial.wkc, 1);
  EXPECT_TRUE(esc(0).pdiMailboxResponsePending()) << "last byte not read yet";
  auto r = one(seg_, Command::kFprd, phys(0x1001, 0x1080), std::vector<std::uint8_t>(16));
  EXPECT_EQ(r.wkc, 1);
  EXPECT_EQ(r.data[2], 3);
  EXPECT_FALSE(esc(0).pdiMailboxResponsePending());
}

TEST_F(Memory, ThreeBufferGivesTheReaderOnlyCompleteBuffers) {
  one(seg_, Command::kFpwr, phys(0x1001, 0x0810), smChannelBytes(0x1100, 4, 0x64));
  one(seg_, Command::kFpwr, phys(0x1001, 0x1100), {1, 2, 3, 4});
  auto first = esc(0).pdiOutputs(2);
  EXPECT_EQ(std::vector<std::uint8_t>(first.begin(), first.end()),
            (std::vector<std::uint8_t>{1, 2, 3, 4}));
  one(seg_, Command::kFpwr, phys(0x1001, 0x1100), {9, 9});  // first half of a new buffer
  auto mid = esc(0).pdiOutputs(2);
  EXPECT_EQ(std::vector<std::uint8_t>(mid.begin(), mid.end()),
            (std::vector<std::uint8_t>{1, 2, 3, 4}))
      << "incomplete buffer stays invisible";
  one(seg_, Command::kFpwr, phys(0x1001, 0x1102), {8, 8});  // completes it
  auto done = esc(0).pdiOutputs(2);
  EXPECT_EQ(std::vector<std::uint8_t>(done.begin(), done.end()),
            (std::vector<std::uint8_t>{9, 9, 8, 8}));
}

TEST_F(Memory, ThreeBufferInputsReadTheNewestPdiBuffer) {
  one(seg_, Command::kFpwr, phys(0x1001, 0x0818), smChannelBytes(0x1180, 2, 0x20));
  esc(0).pdiWriteInputs(3, std::vector<std::uint8_t>{1, 1});
  esc(0).pdiWriteInputs(3, std::vector<std::uint8_t>{2, 2});
  esc(0).pdiWriteInputs(3, std::vector<std::uint8_t>{3, 3});
  auto r = one(seg_, Command::kFprd, phys(0x1001, 0x1180), {0, 0});
  EXPECT_EQ(r.data, (std::vector<std::uint8_t>{3, 3}));
  EXPECT_EQ(one(seg_, Command::kFpwr, phys(0x1001, 0x1180), {7, 7}).wkc, 0)
      << "master cannot write an input buffer";
}

TEST_F(Memory, SmRegistersLockedWhileEnabled) {
  one(seg_, Command::kFpwr, phys(0x1001, 0x0810), smChannelBytes(0x1100, 4, 0x64));
  one(seg_, Command::kFpwr, phys(0x1001, 0x0810), {0x00, 0x12, 0x08});
  EXPECT_EQ(esc(0).smConfig(2).start, 0x1100);
  EXPECT_EQ(esc(0).smConfig(2).length, 4);
  one(seg_, Command::kFpwr, phys(0x1001, 0x0816), {0});  // disable
  one(seg_, Command::kFpwr, phys(0x1001, 0x0810), {0x00, 0x12, 0x08});
  EXPECT_EQ(esc(0).smConfig(2).start, 0x1200);
}

TEST_F(Memory, SiiReadLoadsFourWordsPerCommand) {
  // Read command for word 0x0008 (vendor id), then the data register.
  // The EEPROM is busy for a while after the command (esc_sii_test.cpp): look after 1 ms.
  one(seg_, Command::kFpwr, phys(0x1001, 0x0502), {0x00, 0x01, 0x08, 0x00, 0x00, 0x00});
  auto status = one(seg_, Command::kFprd, phys(0x1001, 0x0502), {0, 0}, kNsPerMs);
  EXPECT_EQ(readLe16(status.data, 0) & 0x8000, 0) << "not busy";
  EXPECT_EQ(readLe16(status.data, 0) & 0x0040, 0x0040)
      << "ET1100 reads 8 bytes, as a real EK1100 reports (replay-dc.pcapng frame 102)";
  auto data = one(seg_, Command::kFprd, phys(0x1001, 0x0508), std::vector<std::uint8_t>(8, 0),
                  kNsPerMs);
  EXPECT_EQ(readLe32(data.data, 0), 0x0000ABCDu) << "word 8-9: vendor";
  EXPECT_EQ(readLe32(data.data, 4), 0x00000100u) << "word A-B: product of slave 0";
  one(seg_, Command::kFpwr, phys(0x1002, 0x0502), {0x00, 0x01, 0x0A, 0x00, 0x00, 0x00}, kNsPerMs);
  EXPECT_EQ(readLe32(one(seg_, Command::kFprd, phys(0x1002, 0x0508), {0, 0, 0, 0}, 2 * kNsPerMs)
                         .data,
                     0),
            0x101u);
}

TEST_F(Memory, SiiWriteNeedsWriteEnable) {
  std::vector<std::uint8_t> cmd{0x00, 0x02, 0x40, 0x00, 0x00, 0x00, 0x34, 0x12};
  one(seg_, Command::kFpwr, phys(0x1001, 0x0502), cmd);
  EXPECT_NE(esc(0).reg16(0x0502) & 0x4000, 0) << "write enable error";
  one(seg_, Command::kFpwr, phys(0x1001, 0x0502), {0x00, 0x00});  // NOP clears errors
  EXPECT_EQ(esc(0).reg16(0x0502) & 0x7800, 0);
  cmd[0] = 0x01;
  one(seg_, Command::kFpwr, phys(0x1001, 0x0502), cmd);
  one(seg_, Command::kFprd, phys(0x1001, 0x0502), {0, 0}, kNsPerMs);  // after the busy time
  EXPECT_EQ(esc(0).sii()[0x80], 0x34);
  EXPECT_EQ(esc(0).sii()[0x81], 0x12);
}

TEST_F(Memory, SiiConfigAreaLoadedAtPowerOn) {
  EXPECT_EQ(esc(0).reg8(0x0140), 0x04) << "PDI control from SII word 0 (EL2004: digital I/O)";
  EXPECT_EQ(esc(0).reg16(0x0110) & 0x0001, 1) << "PDI operational: checksum accepted";
}

TEST_F(Memory, BadSiiChecksumKeepsPdiOff) {
  auto sii = makeSii(1, 2);
  sii[0x0E] ^= 0xFF;
  topology::Segment seg;
  seg.addSlave(makeSlave("bad", 1, {}, sii));
  EXPECT_NE(seg.slave(0).esc().reg16(0x0502) & 0x0800, 0) << "checksum error bit";
  EXPECT_EQ(seg.slave(0).esc().reg16(0x0110) & 0x0001, 0);
}

}  // namespace
}  // namespace ecsim::testing

namespace ecsim::testing {
namespace {

// Process data through 1-buffer (mailbox-mode) SMs, as some devices' ESI ask for (EL9800):
// the master's write fills the buffer, the firmware takes it, inputs are read once per PDI
// write.
TEST(OneBufferProcessData, OutputsAndInputsFlowAndTheEsmAcceptsThem) {
  slavesim::SlaveProfile p;
  p.processData = {{2, true, 2}, {3, false, 2}};
  topology::Segment seg;
  seg.addSlave(makeSlave("io", 1, p));
  one(seg, Command::kApwr, phys(0, 0x0010), le16(0x1001));
  auto sm = [&](std::uint16_t reg, std::uint16_t start, std::uint8_t control) {
    std::vector<std::uint8_t> b(8, 0);
    writeLe16(b, 0, start);
    writeLe16(b, 2, 2);
    b[4] = control;
    b[6] = 1;
    one(seg, Command::kFpwr, phys(0x1001, reg), b);
  };
  sm(0x0810, 0x1100, 0x26);  // outputs, 1-buffer
  sm(0x0818, 0x1180, 0x22);  // inputs, 1-buffer
  auto& esc = seg.slave(0).esc();
  one(seg, Command::kFpwr, phys(0x1001, 0x0120), le16(0x0002));
  one(seg, Command::kFpwr, phys(0x1001, 0x0120), le16(0x0004));
  ASSERT_EQ(esc.alStatus(), 0x0004) << "PREOP -> SAFEOP with 1-buffer SMs";
  EXPECT_EQ(one(seg, Command::kFpwr, phys(0x1001, 0x1100), {0x12, 0x34}).wkc, 1);
  auto out = esc.pdiOutputs(2);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[1], 0x34);
  EXPECT_EQ(one(seg, Command::kFpwr, phys(0x1001, 0x1100), {0x56, 0x78}).wkc, 1)
      << "the firmware took the first buffer, so the next write is accepted";
  ASSERT_TRUE(esc.pdiWriteInputs(3, std::vector<std::uint8_t>{0xAB, 0xCD}));
  EXPECT_FALSE(esc.pdiWriteInputs(3, std::vector<std::uint8_t>{0, 0})) << "not read yet";
  auto in = one(seg, Command::kFprd, phys(0x1001, 0x1180), {0, 0});
  EXPECT_EQ(in.wkc, 1);
  EXPECT_EQ(in.data, (std::vector<std::uint8_t>{0xAB, 0xCD}));
  EXPECT_EQ(one(seg, Command::kFprd, phys(0x1001, 0x1180), {0, 0}).wkc, 0)
      << "read once: empty until the PDI writes again";
  one(seg, Command::kFpwr, phys(0x1001, 0x0120), le16(0x0008));
  EXPECT_EQ(esc.alStatus(), 0x0008);
}

}  // namespace
}  // namespace ecsim::testing
