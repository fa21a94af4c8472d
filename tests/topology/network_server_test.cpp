// NetworkServer on an in-memory link: frames answered in place, malformed frames dropped and
// counted, and in paced mode the answer held until the modelled return time has come.
#include "topology/network_server.hpp"

#include <gtest/gtest.h>

#include "link/memory_link.hpp"
#include "support/test_network.hpp"

namespace ecsim::testing {
namespace {

std::size_t brdFrame(std::array<std::uint8_t, kMaxFrameSize>& buf) {
  FrameBuilder b(buf, EthernetHeader{});
  (void)b.add(Command::kBrd, 9, 0, 2);
  return *b.finish();
}

TEST(NetworkServer, AnswersAndDropsMalformedFrames) {
  topology::Segment seg;
  buildLine(seg, 3);
  auto [master, network] = MemoryLink::makePair();
  VirtualClock clock;
  topology::NetworkServer server(network, seg, clock);
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  std::size_t len = brdFrame(buf);
  ASSERT_TRUE(master.send(ConstBytes(buf.data(), len)).ok());
  ASSERT_TRUE(server.step().ok());
  auto got = master.receive(buf, std::chrono::milliseconds(10));
  ASSERT_TRUE(got.ok());
  ASSERT_EQ(*got, len);
  EXPECT_EQ(readLe16(buf, 14 + 2 + 10 + 2), 3) << "WKC";
  std::vector<std::uint8_t> junk(40, 0xEE);
  junk[12] = 0x88;
  junk[13] = 0xA4;
  ASSERT_TRUE(master.send(junk).ok());
  ASSERT_TRUE(server.step().ok());
  EXPECT_EQ(server.counters().framesDropped, 1u);
  auto none = master.receive(buf, std::chrono::milliseconds(5));
  ASSERT_TRUE(none.ok());
  EXPECT_EQ(*none, 0u) << "a malformed frame is not answered";
}

TEST(NetworkServer, PacedModeHoldsTheAnswerUntilTheModelledReturnTime) {
  topology::Segment seg;
  buildLine(seg, 500);  // about 1 ms round trip
  auto [master, network] = MemoryLink::makePair();
  RealClock clock;
  topology::ServerOptions options;
  options.paced = true;
  topology::NetworkServer server(network, seg, clock, options);
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  std::size_t len = brdFrame(buf);
  const SimTime sent = clock.now();
  ASSERT_TRUE(master.send(ConstBytes(buf.data(), len)).ok());
  ASSERT_TRUE(server.step().ok());
  auto got = master.receive(buf, std::chrono::milliseconds(100));
  const SimTime back = clock.now();
  ASSERT_TRUE(got.ok());
  ASSERT_EQ(*got, len);
  const SimTime modelled = server.counters().lastRoundTrip;
  EXPECT_GT(modelled, 900 * kNsPerUs);
  EXPECT_GE(back - sent, modelled) << "not before the modelled return time";
}

}  // namespace
}  // namespace ecsim::testing
