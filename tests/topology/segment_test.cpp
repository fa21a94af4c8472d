// Frame forwarding through the wiring (ESC datasheet section I §3: processing order
// 0->3->1->2, closed ports loop back), DL status bits as SOEM reads them, and the timing model
// (wire time 80 ns/byte, 5 ns/m cable, per-ESC delay) feeding the DC receive-time latches.
#include <gtest/gtest.h>

#include "support/test_network.hpp"

namespace ecsim::testing {
namespace {

TEST(Segment, DlStatusOfALine) {
  topology::Segment seg;
  buildLine(seg, 3);
  // Last slave: port 0 link + communication, ports 1-3 closed (loop): 0x5611 as SOEM expects
  // from a single/last slave (notes/soem-interop.md §3.2).
  EXPECT_EQ(seg.slave(2).esc().reg16(0x0110), 0x5611);
  // Middle slave: ports 0 and 1 open with communication.
  EXPECT_EQ(seg.slave(1).esc().reg16(0x0110), 0x5A31);
}

TEST(Segment, TreeThroughAJunctionVisitsInPortOrder) {
  // Junction J (4 ports): port 3 -> A, port 1 -> B, port 2 -> C. Processing order:
  // J, A (via port 3), B (via port 1), C (via port 2): auto-increment positions follow it.
  topology::Segment seg;
  seg.addSlave(makeSlave("J", 1));
  seg.addSlave(makeSlave("A", 2));
  seg.addSlave(makeSlave("B", 3));
  seg.addSlave(makeSlave("C", 4));
  ASSERT_TRUE(seg.connect(0, 1, 2, 0).ok());
  ASSERT_TRUE(seg.connect(0, 3, 1, 0).ok());
  ASSERT_TRUE(seg.connect(0, 2, 3, 0).ok());
  for (std::uint16_t pos = 0; pos < 4; ++pos) {
    one(seg, Command::kApwr, phys(static_cast<std::uint16_t>(-pos), 0x0010),
        le16(static_cast<std::uint16_t>(0x100 + pos)));
  }
  EXPECT_EQ(seg.slave(0).esc().reg16(0x0010), 0x100);
  EXPECT_EQ(seg.slave(1).esc().reg16(0x0010), 0x101) << "A behind port 3 comes second";
  EXPECT_EQ(seg.slave(2).esc().reg16(0x0010), 0x102);
  EXPECT_EQ(seg.slave(3).esc().reg16(0x0010), 0x103);
}

TEST(Segment, CyclesAreRefused) {
  topology::Segment seg;
  buildLine(seg, 3);
  auto s = seg.connect(2, 1, 0, 2);
  EXPECT_FALSE(s.ok());
}

TEST(Segment, ClosedPortLoopsBackAndHidesTheRest) {
  topology::Segment seg;
  buildLine(seg, 3);
  // Close port 1 of slave 0 through DL control (0x0101 bits 2-3 = 11: always closed).
  one(seg, Command::kApwr, phys(0, 0x0101), {0x0C});
  EXPECT_EQ(one(seg, Command::kBrd, phys(0, 0x0000), {0}).wkc, 1);
  one(seg, Command::kApwr, phys(0, 0x0101), {0x00});
  EXPECT_EQ(one(seg, Command::kBrd, phys(0, 0x0000), {0}).wkc, 3);
}

TEST(Segment, PulledCableLosesTheSlavesBehindIt) {
  topology::Segment seg;
  buildLine(seg, 4);
  seg.setLinkUp(1, 1, false);
  EXPECT_EQ(one(seg, Command::kBrd, phys(0, 0x0000), {0}).wkc, 2);
  EXPECT_EQ(seg.slave(1).esc().reg8(0x0311), 1) << "lost link counter port 1";
  EXPECT_EQ(seg.slave(1).esc().reg16(0x0110) & 0x0C00, 0x0400) << "port 1 now loops";
  seg.setLinkUp(1, 1, true);
  EXPECT_EQ(one(seg, Command::kBrd, phys(0, 0x0000), {0}).wkc, 4);
}

TEST(Segment, ReturnTimeFollowsTheWireModel) {
  topology::Segment seg;
  buildLine(seg, 10);
  seg.setMasterCable(0.0);
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  FrameBuilder b(buf, EthernetHeader{});
  ASSERT_TRUE(b.add(Command::kBrd, 0, 0, 2).ok());
  auto len = b.finish();
  auto out = seg.processFrame(std::span(buf.data(), *len), 1000);
  ASSERT_TRUE(out.delivered);
  // A line of 10 with a 0 m master cable: forward, each slave's processing delay and a 1 m
  // cable to the next; back, each but the last forwards once and the cable again.
  const SimTime perEsc = slavesim::kEt1100.processingDelayNs;
  const SimTime fwd = slavesim::kEt1100.forwardingDelayNs;
  EXPECT_EQ(out.firstBitRoundTrip, 10 * perEsc + 9 * fwd + 2 * 9 * 5);
  EXPECT_GT(out.firstBitRoundTrip, 10 * perEsc);
  EXPECT_EQ(out.returnTime - 1000 - out.firstBitRoundTrip, (8 + 60 + 4) * 80)
      << "last bit arrives one frame wire time after the first";
}

// Issue #21: a wire fault's extra delay near the end of SimTime overflowed `t + extra`.
TEST(Segment, ExtraWireDelayIsBoundedAndNeverWraps) {
  topology::Segment seg;
  buildLine(seg, 3);
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  FrameBuilder b(buf, EthernetHeader{});
  ASSERT_TRUE(b.add(Command::kBrd, 0, 0, 2).ok());
  auto len = b.finish();
  const SimTime plain = seg.processFrame(std::span(buf.data(), *len), 0).firstBitRoundTrip;
  FixedWireDelay faults;
  seg.setWireFaults(&faults);
  for (SimTime extra : {kSimTimeMax, kSimTimeMin, SimTime{-5}}) {
    faults.extra = extra;
    const SimTime send = 1'000'000;
    auto out = seg.processFrame(std::span(buf.data(), *len), send);
    // Five cable arrivals in a line of 3 (three down, two back up), each delayed by at most
    // the bound; a negative extra delay is none.
    const SimTime expected = extra > 0 ? plain + 5 * topology::kMaxWireExtraDelay : plain;
    EXPECT_EQ(out.firstBitRoundTrip, expected) << extra;
    EXPECT_GT(out.returnTime, send) << extra;
  }
  seg.setWireFaults(nullptr);
}

TEST(Segment, DcLatchMeasuresTheDownstreamRoundTrip) {
  topology::Segment seg;
  buildLine(seg, 3);
  seg.setMasterCable(0.0);
  one(seg, Command::kBwr, phys(0, 0x0900), {0, 0, 0, 0}, 5000);
  auto t0 = seg.slave(0).esc().reg32(0x0900);
  auto t1 = seg.slave(0).esc().reg32(0x0904);
  auto s1t0 = seg.slave(1).esc().reg32(0x0900);
  auto s1t1 = seg.slave(1).esc().reg32(0x0904);
  auto s2t0 = seg.slave(2).esc().reg32(0x0900);
  EXPECT_EQ(t0, 5000u) << "arrival at port 0 of the first slave";
  EXPECT_EQ(s1t0 - t0, slavesim::kEt1100.processingDelayNs + 5u) << "ESC delay + 1 m cable";
  // What comes back to slave 0's port 1 has gone round slaves 1 and 2.
  EXPECT_GT(t1, s2t0);
  EXPECT_EQ((t1 - t0) - (s1t1 - s1t0), 2 * (slavesim::kEt1100.processingDelayNs + 5u) -
                                           slavesim::kEt1100.processingDelayNs +
                                           slavesim::kEt1100.forwardingDelayNs)
      << "difference of port round trips = twice the hop between the slaves";
}

}  // namespace
}  // namespace ecsim::testing

namespace ecsim::testing {
namespace {

struct Recorder : topology::CableObserver {
  struct Seen {
    std::vector<std::uint8_t> bytes;
    SimTime time;
    bool downstream;
  };
  std::vector<Seen> seen;
  void onFrame(ConstBytes frame, SimTime time, bool downstream) override {
    seen.push_back({std::vector<std::uint8_t>(frame.begin(), frame.end()), time, downstream});
  }
};

TEST(SegmentTaps, InnerCableSeesThePartiallyProcessedFrame) {
  topology::Segment seg;
  buildLine(seg, 4);
  seg.setMasterCable(0.0);
  Recorder master, inner;
  seg.setCableObserver(0, 0, &master);
  seg.setCableObserver(2, 0, &inner);  // the cable between slave 1 and slave 2
  auto r = one(seg, Command::kBrd, phys(0, 0x0000), {0, 0}, 10'000);
  EXPECT_EQ(r.wkc, 4);
  ASSERT_EQ(master.seen.size(), 2u);
  ASSERT_EQ(inner.seen.size(), 2u);
  const std::size_t wkcAt = 14 + 2 + 10 + 2;
  EXPECT_EQ(readLe16(master.seen[0].bytes, wkcAt), 0) << "as the master sent it";
  EXPECT_EQ(readLe16(inner.seen[0].bytes, wkcAt), 2) << "after slaves 0 and 1";
  EXPECT_TRUE(inner.seen[0].downstream);
  EXPECT_EQ(readLe16(inner.seen[1].bytes, wkcAt), 4) << "on its way back: all four";
  EXPECT_FALSE(inner.seen[1].downstream);
  EXPECT_EQ(readLe16(master.seen[1].bytes, wkcAt), 4);
  EXPECT_EQ(master.seen[0].time, 10'000);
  // Downstream on the inner cable: two ESC processing delays and one 1 m cable later.
  EXPECT_EQ(inner.seen[0].time, 10'000 + 2 * slavesim::kEt1100.processingDelayNs + 5);
  EXPECT_LT(inner.seen[0].time, inner.seen[1].time);
  EXPECT_LT(inner.seen[1].time, master.seen[1].time);
}

}  // namespace
}  // namespace ecsim::testing
