// Cable redundancy (issue #20 item 4): the far end of the line wired back to the master's
// second port. A frame passes an ESC's processing unit only when it arrives at port 0 (or loops
// back to it); arriving at port 1 it goes to port 2 and out of port 0 unprocessed (ESC
// datasheet section I §3.2, Table 10: 0 -> EPU -> 3 -> 1 -> 2 -> 0). So on a whole ring the
// primary's frame is processed by every ESC and comes out at the second port, and a frame
// sent from the second port passes every ESC unprocessed and comes out at the primary; with the
// ring broken each side's frame is processed by the ESCs on its side and comes back where it
// was sent, and the primary's result sent again from the second port collects the rest: the
// working counter of a whole ring (SOEM's ecx_waitinframe_red relies on exactly this).
#include <gtest/gtest.h>

#include "support/test_network.hpp"

namespace ecsim::testing {
namespace {

using topology::MasterPort;

struct Sent {
  topology::FrameOutcome outcome;
  std::vector<std::uint8_t> frame;
  std::uint16_t wkc(std::size_t datagram = 0) {
    auto parsed = EtherCatFrame::parse(std::span(frame.data(), frame.size()));
    std::size_t i = 0;
    for (auto d : *parsed) {
      if (i++ == datagram) return d.wkc();
    }
    return 0xFFFF;
  }
};

Sent send(topology::Segment& seg, std::vector<std::uint8_t> frame, MasterPort from) {
  Sent s;
  s.outcome = seg.processFrame(std::span(frame.data(), frame.size()), 0, from);
  s.frame = std::move(frame);
  return s;
}

// Six slaves in a line, the last one's port 1 wired to the master's second port.
class Ring : public ::testing::Test {
 protected:
  void SetUp() override {
    buildLine(seg_, 6);
    ASSERT_TRUE(seg_.setRedundantPort(5, 1).ok());
  }
  void breakBetween(std::size_t a, std::size_t b) {
    seg_.setLinkUp(a, 1, false);
    seg_.setLinkUp(b, 0, false);
  }
  std::vector<std::uint8_t> brd() { return buildFrame({{Command::kBrd, 0, {0, 0}}}); }
  topology::Segment seg_;
};

TEST_F(Ring, WholeRingPrimaryFrameGoesRoundAndSecondaryPassesUnprocessed) {
  Sent primary = send(seg_, brd(), MasterPort::kPrimary);
  ASSERT_TRUE(primary.outcome.delivered);
  EXPECT_EQ(primary.outcome.exit, MasterPort::kSecondary);
  EXPECT_EQ(primary.wkc(), 6) << "every ESC processed it";
  Sent secondary = send(seg_, brd(), MasterPort::kSecondary);
  ASSERT_TRUE(secondary.outcome.delivered);
  EXPECT_EQ(secondary.outcome.exit, MasterPort::kPrimary);
  EXPECT_EQ(secondary.wkc(), 0) << "entering at port 1, no ESC's processing unit saw it";
  // The last slave's port 1 has a link and communication (DL status 0x0110 bits 5 and 11).
  const auto dl = seg_.slave(5).esc().read(reg::kDlStatus);
  EXPECT_NE(dl & reg::dl_status::physicalLink(1), 0u);
  EXPECT_NE(dl & reg::dl_status::communication(1), 0u);
  // Round trip of the way round: longer than the line's with port 1 closed.
  topology::Segment line;
  buildLine(line, 6);
  auto f = brd();
  const auto back = line.processFrame(std::span(f.data(), f.size()), 0);
  EXPECT_GT(primary.outcome.firstBitRoundTrip, 0);
  EXPECT_NE(primary.outcome.firstBitRoundTrip, back.firstBitRoundTrip);
}

TEST_F(Ring, BrokenRingEachSideProcessesItsOwnAndTheResentFrameCollectsTheRest) {
  breakBetween(2, 3);
  Sent primary = send(seg_, brd(), MasterPort::kPrimary);
  ASSERT_TRUE(primary.outcome.delivered);
  EXPECT_EQ(primary.outcome.exit, MasterPort::kPrimary) << "looped back at slave 2";
  EXPECT_EQ(primary.wkc(), 3);
  Sent secondary = send(seg_, brd(), MasterPort::kSecondary);
  ASSERT_TRUE(secondary.outcome.delivered);
  EXPECT_EQ(secondary.outcome.exit, MasterPort::kSecondary) << "looped back at slave 3";
  EXPECT_EQ(secondary.wkc(), 3) << "slaves 3, 4, 5 (after the loop at slave 3's port 0)";
  // SOEM's way: the primary's result sent again from the second port.
  Sent combined = send(seg_, primary.frame, MasterPort::kSecondary);
  ASSERT_TRUE(combined.outcome.delivered);
  EXPECT_EQ(combined.wkc(), 6) << "the working counter of the whole ring";
}

TEST_F(Ring, AutoIncrementCountsOnAcrossTheBreak) {
  breakBetween(2, 3);
  // APWR of the station address to position 4: slaves 0-2 count the ADP from -4 to -1; the
  // frame sent again from the second port passes 5, 4, 3 unprocessed, loops at slave 3, whose
  // processing unit counts it to 0, so slave 4 writes.
  const auto apwr =
      buildFrame({{Command::kApwr, phys(static_cast<std::uint16_t>(-4), 0x0010), le16(0x1234)}});
  Sent primary = send(seg_, apwr, MasterPort::kPrimary);
  EXPECT_EQ(primary.wkc(), 0);
  Sent combined = send(seg_, primary.frame, MasterPort::kSecondary);
  EXPECT_EQ(combined.wkc(), 1);
  EXPECT_EQ(seg_.slave(4).esc().stationAddress(), 0x1234);
  for (std::size_t i : {0u, 1u, 2u, 3u, 5u}) EXPECT_EQ(seg_.slave(i).esc().stationAddress(), 0);
}

TEST_F(Ring, SecondCablePulledTheLineWorksFromThePrimaryAlone) {
  seg_.setLinkUp(5, 1, false);
  Sent primary = send(seg_, brd(), MasterPort::kPrimary);
  ASSERT_TRUE(primary.outcome.delivered);
  EXPECT_EQ(primary.outcome.exit, MasterPort::kPrimary);
  EXPECT_EQ(primary.wkc(), 6);
  EXPECT_FALSE(send(seg_, brd(), MasterPort::kSecondary).outcome.delivered)
      << "no link at the second port: nothing received";
  seg_.setLinkUp(5, 1, true);  // healed
  EXPECT_EQ(send(seg_, brd(), MasterPort::kPrimary).outcome.exit, MasterPort::kSecondary);
}

TEST(RedundantPort, RefusedWhereACableIsAndDroppedWithoutOne) {
  topology::Segment seg;
  buildLine(seg, 3);
  EXPECT_FALSE(seg.setRedundantPort(1, 1).ok()) << "slave 1 port 1 is wired to slave 2";
  EXPECT_FALSE(seg.setRedundantPort(0, 0).ok()) << "the primary's own port";
  EXPECT_FALSE(seg.setRedundantPort(3, 1).ok()) << "no such slave";
  auto f = buildFrame({{Command::kBrd, 0, {0, 0}}});
  EXPECT_FALSE(seg.processFrame(std::span(f.data(), f.size()), 0, MasterPort::kSecondary).delivered)
      << "a master without redundancy has no second port";
  EXPECT_EQ(seg.counters().framesMalformed, 0u);
}

}  // namespace
}  // namespace ecsim::testing
