// Loop control 0x0101 and DL control 0x0100 (ESC datasheet section I §3.1 "Loop control and
// loop state", §3.7 "Special functions of port 0"; section II ESC DL Control): "open" is open
// whatever the link, so a frame sent into a port without a link is lost; "closed" receives
// nothing; bit 1 of 0x0100 makes the loop setting temporary (about 1 s, then the previous
// setting is back); reset value: forwarding rule set, RX FIFO size 7.
#include <gtest/gtest.h>

#include "support/test_network.hpp"

namespace ecsim::testing {
namespace {

// Sends a BRD of 0x0000 at `now`; returns its working counter, or -1 when the frame is lost.
int brd(topology::Segment& seg, SimTime now) {
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  FrameBuilder b(
      buf, EthernetHeader{kBroadcastMac, {1, 1, 1, 1, 1, 1}, std::nullopt, kEtherTypeEtherCat});
  EXPECT_TRUE(b.add(Command::kBrd, 0, phys(0, 0x0000), std::vector<std::uint8_t>{0}).ok());
  auto len = b.finish();
  EXPECT_TRUE(len.ok());
  auto outcome = seg.processFrame(std::span(buf.data(), *len), now);
  seg.pollSlaves(now);
  if (!outcome.delivered) return -1;
  auto frame = EtherCatFrame::parse(std::span(buf.data(), *len));
  return frame.ok() ? (*frame->begin()).wkc() : -2;
}

TEST(LoopControl, DlControlResetValue) {
  topology::Segment seg;
  buildLine(seg, 1);
  const auto r = one(seg, Command::kBrd, phys(0, 0x0100), {0, 0, 0, 0});
  EXPECT_EQ(readLe32(r.data, 0), 0x00070001u) << "forwarding rule 1, RX FIFO size 7";
}

TEST(LoopControl, OpenWithoutLinkLosesTheFrame) {
  topology::Segment seg;
  buildLine(seg, 2);
  // Port 1 of the last slave: "open" (10b in bits 2-3 of 0x0101) with nothing connected.
  one(seg, Command::kApwr, phys(0xFFFF, 0x0101), {0x08});
  EXPECT_EQ(brd(seg, 0), -1) << "sent out of an open port without link: lost";
  EXPECT_EQ(seg.slave(1).esc().read(reg::kDlStatus) & reg::dl_status::loopPort(1), 0)
      << "DL status shows port 1 open";
}

TEST(LoopControl, OpenWithLinkBehavesAsAuto) {
  topology::Segment seg;
  buildLine(seg, 2);
  one(seg, Command::kApwr, phys(0, 0x0101), {0x08});
  EXPECT_EQ(brd(seg, 0), 2);
}

TEST(LoopControl, ClosedPort0ReceivesNothing) {
  topology::Segment seg;
  buildLine(seg, 3);
  // The middle slave: port 0 closed while its port 1 is open (so section I §3.7 does not
  // reopen port 0).
  one(seg, Command::kApwr, phys(0xFFFF, 0x0101), {0x03});
  EXPECT_EQ(brd(seg, 0), -1) << "the frame is not received at slave 1's closed port 0";
}

TEST(LoopControl, Port0StaysOpenWhenEveryOtherPortIsClosed) {
  // Section I §3.7: port 0's loop state is open if all other ports are closed.
  topology::Segment seg;
  buildLine(seg, 1);
  one(seg, Command::kApwr, phys(0, 0x0101), {0x03});
  EXPECT_EQ(brd(seg, 0), 1);
}

TEST(LoopControl, TemporarySettingRevertsAfterAboutOneSecond) {
  topology::Segment seg;
  buildLine(seg, 2);
  // DL control: forwarding rule, temporary (bit 1), port 1 closed (0x0C in 0x0101).
  one(seg, Command::kApwr, phys(0, 0x0100), {0x03, 0x0C, 0x07, 0x00}, 0);
  EXPECT_EQ(brd(seg, 500 * kNsPerMs), 1) << "port 1 closed for now";
  EXPECT_EQ(brd(seg, 1100 * kNsPerMs), 2) << "back to auto after about 1 s";
  EXPECT_EQ(seg.slave(0).esc().read(reg::kDlControl) & 0xFF00u, 0u);
}

TEST(LoopControl, PermanentSettingStays) {
  topology::Segment seg;
  buildLine(seg, 2);
  one(seg, Command::kApwr, phys(0, 0x0100), {0x01, 0x0C, 0x07, 0x00}, 0);
  EXPECT_EQ(brd(seg, 2 * kNsPerSecond), 1);
}

}  // namespace
}  // namespace ecsim::testing
