// The DC latch unit (slavesim/esc_latch.cpp), through frames. ESC datasheet section II:
//  - 0x0980 cyclic unit control bits 4/5: latch unit 0/1 controlled by ECAT (0) or PDI (1);
//  - 0x09A8/0x09A9 latch control, bit 0 positive edge / bit 1 negative edge: 0 continuous,
//    1 single event (only the first event active); written by the unit's owner;
//  - 0x09AE/0x09AF latch status: bit 0/1 positive/negative edge event ("single event mode
//    only", cleared by reading the edge's latch time), bit 2 the pin state;
//  - 0x09B0/0x09B8 (unit 0) and 0x09C0/0x09C8 (unit 1): the system time at the positive or
//    negative edge;
//  - 0x0210 bit 0 DC latch event: "at least one change on DC latch inputs", cleared by reading
//    the latch times from ECAT for ECAT-controlled units; 0x0220 bit 1 likewise for the PDI.
#include <gtest/gtest.h>

#include "support/test_network.hpp"
#include "topology/faults.hpp"
#include "topology/network_builder.hpp"

namespace ecsim::testing {
namespace {

std::vector<std::uint8_t> bytes(std::size_t n) {
  return std::vector<std::uint8_t>(n, 0);
}

class Latch : public ::testing::Test {
 protected:
  void SetUp() override { buildLine(seg_, 1); }
  slavesim::Slave& slave() { return seg_.slave(0); }
  slavesim::Esc& esc() { return slave().esc(); }
  DatagramResult aprd(std::uint16_t ado, std::size_t n, SimTime now = 0) {
    return one(seg_, Command::kAprd, phys(0, ado), bytes(n), now);
  }
  DatagramResult apwr(std::uint16_t ado, std::vector<std::uint8_t> data) {
    return one(seg_, Command::kApwr, phys(0, ado), std::move(data));
  }
  std::uint64_t time(std::uint16_t ado) { return readLe64(aprd(ado, 8).data, 0); }
  std::uint8_t status(unsigned unit) {
    return aprd(static_cast<std::uint16_t>(reg::kLatch0Status.address + unit), 1).data[0];
  }
  topology::Segment seg_;
};

TEST_F(Latch, ContinuousModeStoresEveryEdgeAndShowsNoEvent) {
  // Reset: 0x09A8 = 0, both edges continuous.
  apwr(reg::kEcatEventMask.address, le16(reg::ecat_event::kDcLatch));
  slave().setLatchSignal(0, true, 1'000);
  EXPECT_EQ(time(reg::kLatch0TimePositiveEdge.address), 1'000u);
  EXPECT_EQ(status(0), reg::latch::kStatusPin) << "pin high, no event in continuous mode";
  slave().setLatchSignal(0, false, 2'500);
  EXPECT_EQ(time(reg::kLatch0TimeNegativeEdge.address), 2'500u);
  EXPECT_EQ(status(0), 0);
  slave().setLatchSignal(0, true, 4'000);
  EXPECT_EQ(time(reg::kLatch0TimePositiveEdge.address), 4'000u) << "every edge overwrites";
  slave().setLatchSignal(0, true, 5'000);
  EXPECT_EQ(time(reg::kLatch0TimePositiveEdge.address), 4'000u) << "no edge, no latch";
  EXPECT_EQ(aprd(0, 1).irq, 0x0000);
  EXPECT_EQ(esc().read(reg::kEcatEventRequest) & reg::ecat_event::kDcLatch, 0);
}

TEST_F(Latch, SingleEventKeepsTheFirstEdgeUntilTheMasterReadsItsTime) {
  EXPECT_EQ(apwr(reg::kLatch0Control.address, {reg::latch::kControlSinglePositive}).wkc, 1);
  apwr(reg::kEcatEventMask.address, le16(reg::ecat_event::kDcLatch));
  slave().setLatchSignal(0, true, 1'000);
  EXPECT_EQ(status(0), reg::latch::kStatusPin | reg::latch::kStatusPositiveEvent);
  EXPECT_EQ(aprd(0, 1).irq, reg::ecat_event::kDcLatch) << "0x0210 bit 0 into the IRQ field";
  slave().setLatchSignal(0, false, 2'000);
  slave().setLatchSignal(0, true, 3'000);
  // Reading the status or the negative edge's time does not clear the positive edge's event.
  aprd(reg::kLatch0TimeNegativeEdge.address, 8);
  EXPECT_EQ(status(0), reg::latch::kStatusPin | reg::latch::kStatusPositiveEvent);
  const auto r = aprd(reg::kLatch0TimePositiveEdge.address, 8);
  EXPECT_EQ(readLe64(r.data, 0), 1'000u) << "only the first event";
  EXPECT_EQ(r.irq, reg::ecat_event::kDcLatch) << "the header passed before the read";
  EXPECT_EQ(status(0), reg::latch::kStatusPin) << "cleared by reading the time";
  EXPECT_EQ(aprd(0, 1).irq, 0x0000);
  EXPECT_EQ(esc().read(reg::kEcatEventRequest) & reg::ecat_event::kDcLatch, 0);
  slave().setLatchSignal(0, false, 4'000);
  slave().setLatchSignal(0, true, 5'000);
  EXPECT_EQ(time(reg::kLatch0TimePositiveEdge.address), 5'000u) << "armed again";
}

TEST_F(Latch, NegativeEdgeOfUnit1AndSwitchingToContinuousMode) {
  apwr(reg::kLatch1Control.address, {reg::latch::kControlSingleNegative});
  slave().setLatchSignal(1, true, 100);
  EXPECT_EQ(status(1), reg::latch::kStatusPin) << "positive edge continuous: no event";
  slave().setLatchSignal(1, false, 700);
  EXPECT_EQ(status(1), reg::latch::kStatusNegativeEvent);
  EXPECT_EQ(status(0), 0) << "unit 0 untouched";
  EXPECT_NE(esc().read(reg::kEcatEventRequest) & reg::ecat_event::kDcLatch, 0);
  aprd(reg::kLatch1TimePositiveEdge.address, 8);
  EXPECT_EQ(status(1), reg::latch::kStatusNegativeEvent) << "the other edge's time";
  // Status bit 1: "0: negative edge not detected or continuous mode".
  apwr(reg::kLatch1Control.address, {0x00});
  EXPECT_EQ(status(1), 0);
  EXPECT_EQ(esc().read(reg::kEcatEventRequest) & reg::ecat_event::kDcLatch, 0);
  EXPECT_EQ(time(reg::kLatch1TimeNegativeEdge.address), 700u);
}

TEST_F(Latch, TimesAreSystemTimeAtTheEdge) {
  // System time = local time + offset 0x0920 (section I, distributed clocks).
  const std::uint64_t offset = 0x0000'1234'0000'0000;
  std::vector<std::uint8_t> o(8);
  writeLe64(o, 0, offset);
  apwr(reg::kSystemTimeOffset.address, o);
  slave().setLatchSignal(0, true, 123'456);
  EXPECT_EQ(time(reg::kLatch0TimePositiveEdge.address), offset + 123'456);
}

TEST_F(Latch, PdiOwnedUnitEventGoesToThePdiAndOnlyItsReadClears) {
  apwr(reg::kCyclicUnitControl.address, {reg::latch::kPdiControlledUnit0});
  apwr(reg::kEcatEventMask.address, le16(reg::ecat_event::kDcLatch));
  // Section II 0x09A8: written by ECAT only while the unit is ECAT-controlled.
  EXPECT_EQ(apwr(reg::kLatch0Control.address, {reg::latch::kControlSinglePositive}).wkc, 0);
  EXPECT_EQ(esc().read(reg::kLatch0Control), 0);
  esc().pdiWrite(reg::kLatch0Control, reg::latch::kControlSinglePositive);
  slave().setLatchSignal(0, true, 9'000);
  EXPECT_EQ(status(0), reg::latch::kStatusPin | reg::latch::kStatusPositiveEvent);
  EXPECT_EQ(aprd(0, 1).irq, 0x0000) << "not an ECAT event";
  EXPECT_NE(esc().read(reg::kAlEventRequest) & reg::al_event::kDcLatch, 0u);
  aprd(reg::kLatch0TimePositiveEdge.address, 8);
  EXPECT_EQ(status(0), reg::latch::kStatusPin | reg::latch::kStatusPositiveEvent)
      << "the master's read does not clear the PDI's event";
  EXPECT_EQ(esc().pdiReadLatchTime(0, false), 9'000u);
  EXPECT_EQ(status(0), reg::latch::kStatusPin);
  EXPECT_EQ(esc().read(reg::kAlEventRequest) & reg::al_event::kDcLatch, 0u);
  // Handing the unit back to ECAT with an event pending moves it to 0x0210.
  slave().setLatchSignal(0, false, 9'500);
  slave().setLatchSignal(0, true, 10'000);
  EXPECT_EQ(apwr(reg::kCyclicUnitControl.address, {0x00}).wkc, 1);
  EXPECT_EQ(aprd(0, 1).irq, reg::ecat_event::kDcLatch);
  EXPECT_EQ(esc().read(reg::kAlEventRequest) & reg::al_event::kDcLatch, 0u);
}

TEST_F(Latch, NoLatchUnitWithoutFullDistributedClocks) {
  esc().setDcUnit(slavesim::Esc::DcUnit::kDelayOnly);
  slave().setLatchSignal(0, true, 1'000);
  EXPECT_FALSE(esc().latchInput(0));
  EXPECT_EQ(esc().read(reg::kLatch0TimePositiveEdge), 0u);
}

TEST(LatchAction, ScenarioAndControlActionDriveTheLatchInput) {
  topology::Network net;
  net.segment = std::make_unique<topology::Segment>();
  buildLine(*net.segment, 1);
  net.cables.push_back({"master", 0, 0});
  topology::FaultInjector faults(net, 1);
  auto& esc = net.segment->slave(0).esc();
  esc.pdiWrite(reg::kLatch0Control, reg::latch::kControlSingleNegative);
  auto action = [](std::string_view text) { return topology::parseFaultLine(text).value(); };
  const std::string name = net.segment->slave(0).name();
  ASSERT_TRUE(faults.apply(action("latch slave=" + name + " unit=0 level=1"), 2'000).ok());
  EXPECT_TRUE(esc.latchInput(0));
  EXPECT_EQ(esc.read(reg::kLatch0TimePositiveEdge), 2'000u);
  ASSERT_TRUE(faults.apply(action("latch slave=" + name + " unit=0 level=0"), 7'000).ok());
  EXPECT_EQ(esc.read(reg::kLatch0TimeNegativeEdge), 7'000u);
  EXPECT_EQ(esc.read(reg::kLatch0Status), reg::latch::kStatusNegativeEvent);
  const auto bad = topology::parseFaultLine("latch slave=" + name + " unit=2 level=0");
  ASSERT_FALSE(bad.ok()) << "refused when parsed, before anything is applied";
  EXPECT_NE(bad.error().context.find("unit"), std::string::npos);
}

}  // namespace
}  // namespace ecsim::testing
