// Working-counter and addressing rules for every command, checked against the ESC datasheet
// section I §2.4 (Tables 5 and 7) and ETG.1000.4: reads +1, writes +1, read-write +1 read and
// +2 write, ARMW/FRMW +1 per slave, broadcast reads OR the slaves' data, auto-increment
// addresses count up at every slave.
#include <gtest/gtest.h>

#include "support/test_network.hpp"

namespace ecsim::testing {
namespace {

class Commands : public ::testing::Test {
 protected:
  void SetUp() override { buildLine(seg_, 3); }
  void assignAddresses() {
    for (std::uint16_t i = 0; i < 3; ++i) {
      auto r = one(seg_, Command::kApwr, phys(static_cast<std::uint16_t>(-i), 0x0010),
                   le16(static_cast<std::uint16_t>(0x1001 + i)));
      ASSERT_EQ(r.wkc, 1);
    }
  }
  topology::Segment seg_;
};

TEST_F(Commands, BrdCountsEverySlave) {
  auto r = one(seg_, Command::kBrd, phys(0, 0x0000), {0, 0});
  EXPECT_EQ(r.wkc, 3);
  EXPECT_EQ(r.data[0], slavesim::kEt1100.typeRegister);
  EXPECT_EQ(r.adp, 3) << "broadcast increments ADP at each slave";
}

TEST_F(Commands, BrdOrsTheSlavesData) {
  assignAddresses();
  // Station addresses 0x1001 | 0x1002 | 0x1003 = 0x1003.
  auto r = one(seg_, Command::kBrd, phys(0, 0x0010), {0, 0});
  EXPECT_EQ(r.wkc, 3);
  EXPECT_EQ(readLe16(r.data, 0), 0x1003);
}

TEST_F(Commands, AprdAddressesByPosition) {
  assignAddresses();
  auto r = one(seg_, Command::kAprd, phys(static_cast<std::uint16_t>(-2), 0x0010), {0, 0});
  EXPECT_EQ(r.wkc, 1);
  EXPECT_EQ(readLe16(r.data, 0), 0x1003);
  EXPECT_EQ(r.adp, 1) << "-2 incremented by three slaves";
}

TEST_F(Commands, AprdPastTheLastSlaveGetsNoAnswer) {
  auto r = one(seg_, Command::kAprd, phys(static_cast<std::uint16_t>(-3), 0x0000), {0, 0});
  EXPECT_EQ(r.wkc, 0);
}

TEST_F(Commands, FprdMatchesStationAddressOnly) {
  assignAddresses();
  EXPECT_EQ(one(seg_, Command::kFprd, phys(0x1002, 0x0000), {0}).wkc, 1);
  EXPECT_EQ(one(seg_, Command::kFprd, phys(0x1009, 0x0000), {0}).wkc, 0);
}

TEST_F(Commands, FpwrThenFprdRoundTrip) {
  assignAddresses();
  EXPECT_EQ(one(seg_, Command::kFpwr, phys(0x1002, 0x0F80), {0xDE, 0xAD}).wkc, 1);
  auto r = one(seg_, Command::kFprd, phys(0x1002, 0x0F80), {0, 0});
  EXPECT_EQ(r.data, (std::vector<std::uint8_t>{0xDE, 0xAD}));
  EXPECT_EQ(one(seg_, Command::kFprd, phys(0x1001, 0x0F80), {0, 0}).data,
            (std::vector<std::uint8_t>{0, 0}));
}

TEST_F(Commands, ReadWriteCommandsCountThree) {
  assignAddresses();
  auto r = one(seg_, Command::kFprw, phys(0x1001, 0x0F80), {0x11, 0x22});
  EXPECT_EQ(r.wkc, 3);
  EXPECT_EQ(r.data, (std::vector<std::uint8_t>{0, 0})) << "read returns memory before write";
  EXPECT_EQ(one(seg_, Command::kFprd, phys(0x1001, 0x0F80), {0, 0}).data,
            (std::vector<std::uint8_t>{0x11, 0x22}));
  EXPECT_EQ(one(seg_, Command::kAprw, phys(0, 0x0F80), {0x33, 0x44}).wkc, 3);
  EXPECT_EQ(one(seg_, Command::kBrw, phys(0, 0x0F82), {0x01}).wkc, 9);
}

TEST_F(Commands, BwrCountsEverySlave) {
  EXPECT_EQ(one(seg_, Command::kBwr, phys(0, 0x0F80), {0x5A}).wkc, 3);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(seg_.slave(i).esc().reg8(0x0F80), 0x5A);
}

TEST_F(Commands, ArmwReadsAtAddressedSlaveAndWritesAtOthers) {
  assignAddresses();
  seg_.slave(1).esc().pdiWrite32(0x0F80, 0xCAFEF00D);
  auto r = one(seg_, Command::kArmw, phys(static_cast<std::uint16_t>(-1), 0x0F80), {0, 0, 0, 0});
  EXPECT_EQ(readLe32(r.data, 0), 0xCAFEF00Du);
  EXPECT_EQ(r.wkc, 3) << "+1 read at the addressed slave, +1 write at each other";
  EXPECT_EQ(seg_.slave(2).esc().reg32(0x0F80), 0xCAFEF00Du) << "written downstream";
  EXPECT_EQ(seg_.slave(0).esc().reg32(0x0F80), 0u) << "upstream of the reader: data was 0";
}

TEST_F(Commands, FrmwDistributesTheReferenceValue) {
  assignAddresses();
  seg_.slave(0).esc().pdiWrite32(0x0F80, 0x01020304);
  auto r = one(seg_, Command::kFrmw, phys(0x1001, 0x0F80), {0, 0, 0, 0});
  EXPECT_EQ(r.wkc, 3);
  EXPECT_EQ(seg_.slave(2).esc().reg32(0x0F80), 0x01020304u);
}

TEST_F(Commands, WritesToReadOnlyRegistersAreIgnoredAndNotCounted) {
  // Real ESCs give no WKC for a write that changes nothing: a BWR to 0x092C (read-only) came
  // back with WKC 0 from EK1100 + EL2828 + EL2889 (../shared/pcap/replay-dc.pcapng frame 75).
  auto r = one(seg_, Command::kBwr, phys(0, 0x0000), {0x55});
  EXPECT_EQ(r.wkc, 0);
  EXPECT_EQ(seg_.slave(0).esc().reg8(0x0000), slavesim::kEt1100.typeRegister);
  EXPECT_EQ(one(seg_, Command::kBwr, phys(0, 0x092C), {1, 2, 3, 4}).wkc, 0);
  // A write that touches a writable byte counts, even if others in it are read-only.
  EXPECT_EQ(one(seg_, Command::kBwr, phys(0, 0x000E), {0, 0, 0x34, 0x12}).wkc, 3);
  EXPECT_EQ(seg_.slave(2).esc().reg16(0x0010), 0x1234);
}

TEST_F(Commands, MissingFmmuAndSmChannelsAreNotCounted) {
  // ET1200 terminals have 3 FMMUs and 4 SMs: writes to FMMU3 or SM4 are not theirs
  // (replay-dc.pcapng frames 11-35, 45-67: only the ET1100 coupler answered).
  topology::Segment seg;
  seg.addSlave(makeSlave("et1100", 1));
  seg.addSlave(std::make_unique<slavesim::Slave>("et1200", slavesim::kEt1200, makeSii(1, 2),
                                                 slavesim::SlaveProfile{}));
  seg.wireLine();
  EXPECT_EQ(one(seg, Command::kBwr, phys(0, 0x0620), std::vector<std::uint8_t>(16, 0)).wkc, 2);
  EXPECT_EQ(one(seg, Command::kBwr, phys(0, 0x0630), std::vector<std::uint8_t>(16, 0)).wkc, 1);
  EXPECT_EQ(one(seg, Command::kBwr, phys(0, 0x0820), std::vector<std::uint8_t>(8, 0)).wkc, 1);
  EXPECT_EQ(one(seg, Command::kBrd, phys(0, 0x0830), std::vector<std::uint8_t>(8, 0)).wkc, 1);
}

TEST_F(Commands, DelayOnlyDcUnitAnswersReceiveTimesOnly) {
  seg_.slave(1).esc().setDcUnit(slavesim::Esc::DcUnit::kDelayOnly);
  seg_.slave(2).esc().setDcUnit(slavesim::Esc::DcUnit::kNone);
  EXPECT_EQ(one(seg_, Command::kBwr, phys(0, 0x0900), {0, 0, 0, 0}).wkc, 2);
  EXPECT_EQ(one(seg_, Command::kBrd, phys(0, 0x0910), std::vector<std::uint8_t>(8, 0)).wkc, 1);
  EXPECT_EQ(one(seg_, Command::kBwr, phys(0, 0x0981), {0}).wkc, 1);
}

TEST_F(Commands, ErrorCountersClearOnWrite) {
  seg_.slave(0).esc().countRxError(1, true);
  seg_.slave(0).esc().countRxError(1, false);
  EXPECT_EQ(seg_.slave(0).esc().reg16(0x0302), 0x0101);
  one(seg_, Command::kBwr, phys(0, 0x0300), {0});
  EXPECT_EQ(seg_.slave(0).esc().reg16(0x0302), 0) << "a write to any RX counter clears all";
}

TEST_F(Commands, NopAndUnknownCommandsAreForwardedUntouched) {
  auto r = one(seg_, Command::kNop, phys(0, 0x0000), {0xAA});
  EXPECT_EQ(r.wkc, 0);
  EXPECT_EQ(r.data[0], 0xAA);
}

TEST_F(Commands, MultipleDatagramsInOneFrame) {
  assignAddresses();
  auto rs = exchange(seg_, {{Command::kFprd, phys(0x1001, 0x0010), {0, 0}},
                            {Command::kFprd, phys(0x1003, 0x0010), {0, 0}},
                            {Command::kBrd, phys(0, 0x0130), {0, 0}}});
  ASSERT_EQ(rs.size(), 3u);
  EXPECT_EQ(readLe16(rs[0].data, 0), 0x1001);
  EXPECT_EQ(readLe16(rs[1].data, 0), 0x1003);
  EXPECT_EQ(rs[2].wkc, 3);
  EXPECT_EQ(rs[2].data[0], 0x01) << "all INIT";
}

TEST_F(Commands, AccessPastMemoryEndReadsZero) {
  assignAddresses();
  auto r = one(seg_, Command::kFprd, phys(0x1001, 0xFFF0), std::vector<std::uint8_t>(8, 0xEE));
  EXPECT_EQ(r.wkc, 1);
  EXPECT_EQ(r.data, std::vector<std::uint8_t>(8, 0));
}

TEST_F(Commands, SourceMacGetsLocallyAdministeredBit) {
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  FrameBuilder b(
      buf, EthernetHeader{kBroadcastMac, {1, 1, 1, 1, 1, 1}, std::nullopt, kEtherTypeEtherCat});
  ASSERT_TRUE(b.add(Command::kBrd, 0, 0, 2).ok());
  auto len = b.finish();
  ASSERT_TRUE(len.ok());
  ASSERT_TRUE(seg_.processFrame(std::span(buf.data(), *len), 0).delivered);
  EXPECT_EQ(buf[6], 0x03);
}

TEST_F(Commands, MalformedFrameIsCountedAndLeftAlone) {
  std::vector<std::uint8_t> junk(60, 0);
  junk[12] = 0x88;
  junk[13] = 0xA4;
  junk[14] = 0xFF;
  junk[15] = 0x17;  // type 1, length 0x7FF
  junk[16 + 6] = 0xFF;
  junk[16 + 7] = 0x07;  // datagram length 2047: runs past the end
  auto copy = junk;
  EXPECT_FALSE(seg_.processFrame(junk, 0).delivered);
  EXPECT_EQ(seg_.counters().framesMalformed, 1u);
  EXPECT_EQ(junk, copy);
}

}  // namespace
}  // namespace ecsim::testing
