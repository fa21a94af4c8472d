// Room to remap in our CiA 402 drives (examples/esi/ecsim_devices.xml, ECS7201/ECS7211):
// real drives offer mapping objects of 8 or more entries (the Ingenia drive of
// ../shared/esi/ingenia_esi.xml: 0x1600 with 15, od_esi_test.cpp), and stock masters remap with
// padding, e.g. TwinCAT and SOEM write 0x1600:00 = 0, then :01...:08, then :00 = n in PREOP
// (ETG.1000.6 §5.6.7.4 PDO mapping; examples/README.md "PDO configuration"). A padding entry
// is a gap (index 0, its length in bits) or a CiA 301 §7.4.8.3 dummy entry (the index of a
// standard data type 0x0001-0x0007, subindex 0, that type's length). Through frames, as a
// master meets the drive: the remapped PDO must give the process image it describes.
#include <gtest/gtest.h>

#include <algorithm>

#include "tests/slavesim/drive_test_support.hpp"

namespace ecsim::testing {
namespace {

// Writes `entries` into `mapping` the way a master does in PREOP (sub 0 = 0, the entries,
// sub 0 = n) and assigns it alone to `assign`; every step must be accepted.
void remap(MailboxMaster& m, std::uint16_t assign, std::uint16_t mapping,
           const std::vector<std::uint32_t>& entries) {
  ASSERT_EQ(m.download(assign, 0, {0}), 0u);
  ASSERT_EQ(m.download(mapping, 0, {0}), 0u);
  for (std::size_t i = 0; i < entries.size(); ++i) {
    EXPECT_EQ(m.download(mapping, static_cast<std::uint8_t>(i + 1), bytesOf(entries[i], 4)), 0u)
        << std::hex << mapping << ":" << i + 1 << " = " << entries[i];
  }
  ASSERT_EQ(m.download(mapping, 0, {static_cast<std::uint8_t>(entries.size())}), 0u);
  ASSERT_EQ(m.download(assign, 1, bytesOf(mapping, 2)), 0u);
  ASSERT_EQ(m.download(assign, 0, {1}), 0u);
}

// Eight RxPDO entries with gaps between them: 17 bytes of outputs.
//   byte 0 controlword, 2 gap, 3 target position, 7 gap, 8 mode, 9 gap (16 bits),
//   11 target velocity, 15 target torque
const std::vector<std::uint32_t> kPaddedRx = {0x60400010, 0x00000008, 0x607A0020, 0x00000008,
                                              0x60600008, 0x00000010, 0x60FF0020, 0x60710010};

TEST(CoeRemap, Ecs7201TakesEightRxEntriesWithGapsAndTheImageFollowsThem) {
  topology::Segment seg;
  seg.addSlave(makeExampleSlave(kEcs7201));
  OpSlave op = bringToOp(seg, {{2, true, 17}, {3, false, 15}}, 0,
                         [](MailboxMaster& m) { remap(m, 0x1C12, 0x1600, kPaddedRx); });
  ASSERT_EQ(alStatus(seg, kStation), 0x0008) << "SAFEOP took SM2 of 17 bytes";
  CyclicExchange x{seg, op.outBytes, op.inBytes};
  std::fill(x.out.begin(), x.out.end(), std::uint8_t{0xAA});  // the gaps carry junk
  x.put16(0, 0x0000);
  x.put32(3, 123456);
  x.put8(8, 9);  // CSV
  x.put32(11, -4242);
  x.put16(15, 77);
  x.cycle();
  x.cycle();
  auto* od = slavesim::objectDictionaryOf(seg.slave(0));
  ASSERT_NE(od, nullptr);
  EXPECT_EQ(od->get<std::uint16_t>(0x6040, 0).valueOr(1), 0x0000);
  EXPECT_EQ(od->get<std::int32_t>(0x607A, 0).valueOr(0), 123456);
  EXPECT_EQ(od->get<std::int8_t>(0x6060, 0).valueOr(0), 9);
  EXPECT_EQ(od->get<std::int32_t>(0x60FF, 0).valueOr(0), -4242);
  EXPECT_EQ(od->get<std::int16_t>(0x6071, 0).valueOr(0), 77);
  EXPECT_EQ(static_cast<std::int8_t>(x.in8(12)), 9) << "0x6061 mode display follows the mode";
}

TEST(CoeRemap, DummyEntriesOfStandardTypesArePadding) {
  // 0x0005:00 UNSIGNED8 (8 bits), 0x0006:00 UNSIGNED16 (16), 0x0001:00 BOOLEAN (1) and a
  // 7-bit gap to the next byte.
  const std::vector<std::uint32_t> tx = {0x60410010, 0x00050008, 0x60640020, 0x00060010,
                                         0x60610008, 0x00010001, 0x00000007, 0x603F0010};
  topology::Segment seg;
  seg.addSlave(makeExampleSlave(kEcs7201));
  OpSlave op = bringToOp(seg, {{2, true, 13}, {3, false, 13}}, 0,
                         [&](MailboxMaster& m) { remap(m, 0x1C13, 0x1A00, tx); });
  ASSERT_EQ(alStatus(seg, kStation), 0x0008) << "SAFEOP took SM3 of 13 bytes";
  auto* od = slavesim::objectDictionaryOf(seg.slave(0));
  ASSERT_NE(od, nullptr);
  CyclicExchange x{seg, op.outBytes, op.inBytes};
  x.put8(12, 8);  // mode CSP through the default RxPDO
  x.cycle();
  x.cycle();
  // byte 0 statusword, 2 dummy, 3 position, 7 dummy (2), 9 mode display, 10 dummy + gap,
  // 11 error code.
  EXPECT_EQ(x.in16(0), od->get<std::uint16_t>(0x6041, 0).valueOr(0xFFFF));
  EXPECT_EQ(static_cast<std::int8_t>(x.in8(9)), 8);
  EXPECT_EQ(x.in8(2), 0) << "padding reads as 0";
  EXPECT_EQ(x.in16(7), 0);
  EXPECT_EQ(x.in8(10), 0);
}

TEST(CoeRemap, DummyEntryMustHaveItsTypesLength) {
  topology::Segment seg;
  seg.addSlave(makeExampleSlave(kEcs7201));
  bringToOp(seg, {{2, true, 13}, {3, false, 15}}, 0, [](MailboxMaster& m) {
    ASSERT_EQ(m.download(0x1600, 0, {0}), 0u);
    EXPECT_EQ(m.download(0x1600, 1, bytesOf(0x00050010, 4)), 0x06040041u)
        << "16 bits of UNSIGNED8";
    EXPECT_EQ(m.download(0x1600, 1, bytesOf(0x00050108, 4)), 0x06040041u) << "subindex 1";
    EXPECT_EQ(m.download(0x1600, 1, bytesOf(0x00080020, 4)), 0x06040041u)
        << "0x0008 REAL32 is not a dummy entry";
    EXPECT_EQ(m.download(0x1600, 1, bytesOf(0x00070020, 4)), 0u) << "UNSIGNED32";
    // The default mapping back, for SAFEOP.
    EXPECT_EQ(m.download(0x1600, 1, bytesOf(0x60400010, 4)), 0u);
    EXPECT_EQ(m.download(0x1600, 0, {5}), 0u);
  });
}

// Every configurable mapping object of both drives offers 8 entries, and says so the same way
// over SDO information (max subindex) as over SDO (the entries exist, 0 until used).
TEST(CoeRemap, DriveMappingObjectsOfferEightEntries) {
  for (std::uint32_t product : {kEcs7201, kEcs7211}) {
    auto slave = makeExampleSlave(product);
    ASSERT_NE(slave, nullptr);
    auto* od = slavesim::objectDictionaryOf(*slave);
    int mappings = 0;
    for (std::uint16_t index = 0x1600; index <= 0x1BFF; ++index) {
      const auto* o = od->find(index);
      if (o == nullptr) continue;
      ++mappings;
      EXPECT_GE(o->maxSubindex(), 8) << std::hex << product << " " << index;
      for (std::uint8_t sub = 1; sub <= 8; ++sub) {
        const auto* e = o->entry(sub);
        ASSERT_NE(e, nullptr) << std::hex << product << " " << index << ":" << int{sub};
        EXPECT_EQ(e->bitLength, 32);
      }
    }
    EXPECT_GE(mappings, 4) << std::hex << product;
  }
}

}  // namespace
}  // namespace ecsim::testing
