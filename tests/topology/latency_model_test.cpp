// The modelled cycle of a given network against figures computed by hand from the timing
// model's sources (docs/timing.md): 80 ns per byte at 100 Mbit/s and 8 bytes of preamble + SFD,
// 4 of FCS and 12 of inter-frame gap per frame (ESC datasheet section I §9.3; IEEE 802.3),
// 5 ns per metre of cable (section I §9.3), and 1000 ns per ESC passage, the 100BASE-TX figure
// of section I §9.3 ("≈1 µs per slave").
#include "topology/latency_model.hpp"

#include <gtest/gtest.h>

#include "protocol/registers.hpp"
#include "slavesim/generic_slave.hpp"

namespace ecsim::topology {
namespace {

constexpr SimTime kPassageNs = 1000;

// Two slaves in a line: master -1 m- slave 0 -2 m- slave 1.
void twoSlaves(Segment& seg) {
  seg.addSlave(slavesim::makeGenericSlave("A", 1));
  seg.addSlave(slavesim::makeGenericSlave("B", 2));
  seg.setDelays(0, kPassageNs, kPassageNs);
  seg.setDelays(1, kPassageNs, kPassageNs);
  ASSERT_TRUE(seg.connect(0, 1, 1, 0, 2.0).ok());
  seg.setMasterCable(1.0);
}

ModelDatagram lrw(std::uint32_t address, std::uint16_t length) {
  return {Command::kLrw, address, length};
}
ModelDatagram frmwSystemTime() {
  return {Command::kFrmw, DatagramHeader::physical(0x1001, reg::kSystemTime.address), 8};
}

// First bit out and back: master cable 5, A's processing 1000, cable 10, B's processing 1000
// (B's other ports are closed and loop back inside), cable 10, A's forwarding 1000, master
// cable 5 = 3030 ns.
constexpr SimTime kFirstBitRoundTrip = 5 + 1000 + 10 + 1000 + 10 + 1000 + 5;

TEST(LatencyModel, OneFrameOfTwoSlavesIsTheHandComputedFigure) {
  Segment seg;
  twoSlaves(seg);
  // 14 Ethernet + 2 EtherCAT + (10 + 20 + 2) LRW + (10 + 8 + 2) FRMW = 68 bytes.
  auto cycle = modelCycle(seg, {{lrw(0, 20), frmwSystemTime()}}, 1'000'000, 1.0);
  ASSERT_TRUE(cycle.ok()) << cycle.error().message();
  EXPECT_EQ(cycle->frames, 1u);
  EXPECT_EQ(cycle->frameBytes, 68u);
  // + the frame's own wire time (8 + 68 + 4) * 80 = 6400 ns.
  EXPECT_EQ(cycle->roundTripNs, kFirstBitRoundTrip + 6400);  // 9430 ns
  // B's port 0 sees the first bit at 5 + 1000 + 10 = 1015 ns and the FCS 6400 ns later.
  EXPECT_EQ(cycle->outputsCompleteNs, 1015 + 6400);
  EXPECT_EQ(cycle->wireNs, (8 + 68 + 4 + 12) * 80);
  EXPECT_EQ(cycle->minCycleNs(), cycle->roundTripNs);
}

TEST(LatencyModel, SecondFrameLeavesAfterTheFirstOnTheWire) {
  Segment seg;
  twoSlaves(seg);
  // Frame 1: 14 + 2 + 12 + 1400 = 1428 bytes; frame 2: 14 + 2 + 112 + 20 = 148 bytes.
  auto cycle = modelCycle(seg, {{lrw(0, 1400)}, {lrw(1400, 100), frmwSystemTime()}}, 0, 1.0);
  ASSERT_TRUE(cycle.ok()) << cycle.error().message();
  EXPECT_EQ(cycle->frames, 2u);
  EXPECT_EQ(cycle->frameBytes, 1428u + 148u);
  const SimTime first = (8 + 1428 + 4 + 12) * 80;  // 116,160 ns until frame 2's first bit
  const SimTime secondOwn = (8 + 148 + 4) * 80;    // 12,800 ns
  EXPECT_EQ(cycle->roundTripNs, first + kFirstBitRoundTrip + secondOwn);  // 131,990 ns
  EXPECT_EQ(cycle->outputsCompleteNs, first + 1015 + secondOwn);          // 129,975 ns
  EXPECT_EQ(cycle->wireNs, first + (8 + 148 + 4 + 12) * 80);
}

TEST(LatencyModel, ShortFramesArePaddedToTheEthernetMinimum) {
  Segment seg;
  twoSlaves(seg);
  // 14 + 2 + 12 + 4 = 32 bytes, padded to 60.
  auto cycle = modelCycle(seg, {{lrw(0, 4)}}, 0, 1.0);
  ASSERT_TRUE(cycle.ok()) << cycle.error().message();
  EXPECT_EQ(cycle->frameBytes, 60u);
  EXPECT_EQ(cycle->roundTripNs, kFirstBitRoundTrip + (8 + 60 + 4) * 80);
}

TEST(LatencyModel, AFrameBeyondTheEthernetMaximumIsRefused) {
  Segment seg;
  twoSlaves(seg);
  // 16 + 12 + 1487 = 1515 bytes: one more than an untagged frame carries.
  auto cycle = modelCycle(seg, {{lrw(0, 1487)}}, 0, 1.0);
  ASSERT_FALSE(cycle.ok());
  EXPECT_EQ(cycle.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(cycle.error().message().find("cyclic frame 1"), std::string::npos)
      << cycle.error().message();
}

}  // namespace
}  // namespace ecsim::topology
