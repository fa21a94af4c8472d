// PDO assignment and mapping drive the SM lengths the ESM expects (PREOP->SAFEOP gives
// 0x001D/0x001E for a wrong SM2/SM3 length, ETG.1000.6 Table 11), and the process-data
// binding copies SM buffers to object values and back, bit-packed in mapping order.
#include <gtest/gtest.h>

#include "tests/slavesim/coe_test_support.hpp"

namespace ecsim::testing {
namespace {

void disableProcessDataSms(topology::Segment& seg) {
  one(seg, Command::kFpwr, phys(kStation, reg::smChannel(2) + reg::sm::kActivate.address), {0});
  one(seg, Command::kFpwr, phys(kStation, reg::smChannel(3) + reg::sm::kActivate.address), {0});
}

TEST(CoePdo, DefaultAssignmentGivesTheExpectedSmLengths) {
  CoeTestSlave t;
  auto layout = slavesim::computeProcessDataLayout(*t.od);
  ASSERT_TRUE(layout.ok());
  ASSERT_EQ(layout->size(), 2u);
  EXPECT_EQ((*layout)[0].sm, 2u);
  EXPECT_TRUE((*layout)[0].outputs);
  EXPECT_EQ((*layout)[0].bitLength, 24u);
  EXPECT_EQ((*layout)[1].sm, 3u);
  EXPECT_EQ((*layout)[1].bitLength, 32u);
  EXPECT_EQ(t.toSafeOp(2, 4), 0x0012) << "SM2 of 2 bytes refused";
  EXPECT_EQ(alStatusCode(t.seg, kStation), 0x001D);
  disableProcessDataSms(t.seg);
  EXPECT_EQ(t.toSafeOp(3, 5, 0x0014), 0x0012) << "SAFEOP with acknowledge";
  EXPECT_EQ(alStatusCode(t.seg, kStation), 0x001E) << "SM3 of 5 bytes refused";
  disableProcessDataSms(t.seg);
  requestState(t.seg, kStation, 0x0012);  // acknowledge
  EXPECT_EQ(t.toSafeOp(3, 4), 0x0004);
}

TEST(CoePdo, AssignmentChangedInPreOpChangesTheExpectedLength) {
  CoeTestSlave t;
  // SOEM-style procedure: sub 0 = 0, entries, sub 0 = n.
  ASSERT_EQ(t.master->download(0x1C12, 0, {0}), 0u);
  ASSERT_EQ(t.master->download(0x1C12, 2, bytesOf(0x1601, 2)), 0u);
  ASSERT_EQ(t.master->download(0x1C12, 0, {2}), 0u);
  EXPECT_EQ(t.master->uploadValue<std::uint16_t>(0x1C12, 2), 0x1601);
  EXPECT_EQ(t.toSafeOp(3, 4), 0x0012) << "the old SM2 length no longer matches";
  EXPECT_EQ(alStatusCode(t.seg, kStation), 0x001D);
  disableProcessDataSms(t.seg);
  requestState(t.seg, kStation, 0x0012);
  EXPECT_EQ(t.toSafeOp(4, 4), 0x0004) << "24 + 8 bits";
  // ... and a write in SAFEOP is refused.
  EXPECT_EQ(t.master->download(0x1C12, 0, {0}), 0x08000022u);
  EXPECT_EQ(t.master->download(0x1C13, 0, {0}), 0x08000022u);
}

TEST(CoePdo, MappingChangedInPreOpChangesTheLayout) {
  CoeTestSlave t;
  ASSERT_EQ(t.master->download(0x1A00, 0, {0}), 0u);
  ASSERT_EQ(t.master->download(0x1A00, 1, bytesOf(0x60000410, 4)), 0x06040041u)
      << "6000:04 is 8 bits, not 16";
  ASSERT_EQ(t.master->download(0x1A00, 1, bytesOf(0x60000408, 4)), 0u);
  ASSERT_EQ(t.master->download(0x1A00, 0, {1}), 0u);
  EXPECT_EQ(t.toSafeOp(3, 1), 0x0004) << "inputs now 8 bits";
}

TEST(CoePdo, ExcludedPdosCannotBeAssignedTogether) {
  CoeTestSlave t;
  ASSERT_EQ(t.master->download(0x1C13, 0, {0}), 0u);
  ASSERT_EQ(t.master->download(0x1C13, 2, bytesOf(0x1A01, 2)), 0u);
  EXPECT_EQ(t.master->download(0x1C13, 0, {2}), 0x06040043u) << "0x1A00 excludes 0x1A01";
  ASSERT_EQ(t.master->download(0x1C13, 1, bytesOf(0x1A01, 2)), 0u);
  EXPECT_EQ(t.master->download(0x1C13, 0, {1}), 0u);
  EXPECT_EQ(t.master->download(0x1A01, 0, {0}), 0x06010002u) << "a fixed PDO's mapping";
}

TEST(CoePdo, MandatoryPdoMustStayAssigned) {
  CoeTestSlave t;
  t.od->pdoRules(0x1600).mandatory = true;
  t.od->pdoRules(0x1600).defaultSm = 2;
  ASSERT_EQ(t.master->download(0x1C12, 0, {0}), 0u);
  ASSERT_EQ(t.master->download(0x1C12, 1, bytesOf(0x1601, 2)), 0u);
  EXPECT_EQ(t.master->download(0x1C12, 0, {1}), 0x06040043u);
  ASSERT_EQ(t.master->download(0x1C12, 2, bytesOf(0x1600, 2)), 0u);
  EXPECT_EQ(t.master->download(0x1C12, 0, {2}), 0u);
}

TEST(CoePdo, UnusableConfigurationIsRefusedAtSafeOp) {
  CoeTestSlave t;
  // A mapping whose object disappears (a device model replacing its dictionary).
  ASSERT_TRUE(t.od->erase(0x7000));
  EXPECT_EQ(t.toSafeOp(3, 4), 0x0012);
  EXPECT_EQ(alStatusCode(t.seg, kStation), 0x001D);
  EXPECT_FALSE(t.device->bindStatus().ok());
  EXPECT_NE(t.device->bindStatus().error().context.find("0x7000"), std::string::npos);
}

TEST(CoePdo, ProcessDataBindingBothWaysBitPacked) {
  CoeTestSlave t;
  ASSERT_EQ(t.toSafeOp(), 0x0004);
  // Inputs 0x1A00: 6000:01 (bit 0), 6000:02 (bits 1-4), gap (5-7), 6000:03 (bits 8-23),
  // 6000:04 (bits 24-31).
  ASSERT_TRUE(t.od->set<bool>(0x6000, 1, true).ok());
  ASSERT_TRUE(t.od->set<std::uint8_t>(0x6000, 2, 0x0B).ok());
  ASSERT_TRUE(t.od->set<std::int16_t>(0x6000, 3, -2).ok());
  ASSERT_TRUE(t.od->set<std::uint8_t>(0x6000, 4, 0x5A).ok());
  t.seg.pollSlaves(0);  // the firmware runs between frames and produces the inputs
  // Outputs 0x1600: 7000:01 (bit 0), 7000:02 (bits 1-3), gap (4-7), 7000:03 (bits 8-23).
  // 0xFB = 1111 1011: enable 1, mode 101 = 5, gap bits set by the master are ignored.
  auto r = one(t.seg, Command::kLrw, 0, {0xFB, 0x34, 0x12, 0, 0, 0, 0});
  EXPECT_EQ(r.wkc, 3);
  EXPECT_EQ(r.data[3], 0x17) << "1 | 0xB << 1";
  EXPECT_EQ(r.data[4], 0xFE);
  EXPECT_EQ(r.data[5], 0xFF);
  EXPECT_EQ(r.data[6], 0x5A);
  EXPECT_TRUE(t.od->get<bool>(0x7000, 1).value());
  EXPECT_EQ(t.od->get<std::uint8_t>(0x7000, 2).value(), 5);
  EXPECT_EQ(t.od->get<std::uint16_t>(0x7000, 3).value(), 0x1234);
  EXPECT_EQ(t.master->uploadValue<std::uint16_t>(0x7000, 3), 0x1234) << "SDO sees it too";
  // The next cycle carries a changed input.
  ASSERT_TRUE(t.od->set<std::uint8_t>(0x6000, 4, 0xA5).ok());
  t.seg.pollSlaves(0);
  r = one(t.seg, Command::kLrw, 0, {0x00, 0, 0, 0, 0, 0, 0});
  EXPECT_EQ(r.data[6], 0xA5);
  EXPECT_FALSE(t.od->get<bool>(0x7000, 1).value());
  requestState(t.seg, kStation, 0x0008);
  EXPECT_EQ(alStatus(t.seg, kStation), 0x0008);
}

TEST(CoePdo, NothingIsCopiedBeforeSafeOp) {
  CoeTestSlave t;
  ASSERT_TRUE(t.od->set<std::uint8_t>(0x6000, 4, 0x77).ok());
  one(t.seg, Command::kFpwr, phys(kStation, reg::smChannel(3)),
      smRegisterBytes(kSm3Start, 4, 0x20));
  auto r = one(t.seg, Command::kFprd, phys(kStation, kSm3Start), {0, 0, 0, 0});
  EXPECT_EQ(r.data[3], 0) << "PREOP: inputs not produced";
}

class CountingApplication final : public slavesim::Application {
 public:
  void step(slavesim::coe::ObjectDictionary& od, AlState state, SimTime /*now*/) override {
    if (state != AlState::kOp) return;
    // Echo: inputs 6000:03 = outputs 7000:03 + 1.
    const auto setpoint = od.getOr<std::uint16_t>(0x7000, 3, 0);
    (void)od.set<std::int16_t>(0x6000, 3, static_cast<std::int16_t>(setpoint + 1));
    ++steps;
  }
  int steps{0};
};

TEST(CoePdo, ApplicationRunsBetweenTheCopies) {
  CoeTestSlave t;
  auto app = std::make_unique<CountingApplication>();
  CountingApplication* a = app.get();
  t.device->setApplication(std::move(app));
  ASSERT_EQ(t.toSafeOp(), 0x0004);
  one(t.seg, Command::kLrw, 0, {0, 0x10, 0x00, 0, 0, 0, 0});
  requestState(t.seg, kStation, 0x0008);
  ASSERT_EQ(alStatus(t.seg, kStation), 0x0008);
  auto r = one(t.seg, Command::kLrw, 0, {0, 0x20, 0x00, 0, 0, 0, 0});
  EXPECT_EQ(readLe16(r.data, 4), 0x0011) << "answer to the previous cycle's outputs";
  r = one(t.seg, Command::kLrw, 0, {0, 0x20, 0x00, 0, 0, 0, 0});
  EXPECT_EQ(readLe16(r.data, 4), 0x0021);
  EXPECT_GT(a->steps, 0);
}

}  // namespace
}  // namespace ecsim::testing
