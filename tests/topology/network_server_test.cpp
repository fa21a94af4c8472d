// NetworkServer on an in-memory link: frames answered in place, malformed frames dropped and
// counted, and in paced mode the answer held until the modelled return time has come.
#include "topology/network_server.hpp"

#include <gtest/gtest.h>

#include <optional>

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
  // A well-formed frame that meets a pulled cable is lost, not malformed.
  seg.setLinkUp(0, 0, false);
  ASSERT_TRUE(master.send(ConstBytes(buf.data(), len)).ok());
  ASSERT_TRUE(server.step().ok());
  EXPECT_EQ(server.counters().framesDropped, 1u);
  EXPECT_EQ(server.counters().framesLost, 1u);
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

// A clock that moves on by `step` every time it is read, so a paced wait ends (or would, in
// the unbounded code of issue #21, after a few hundred million reads) without real waiting.
class SteppingClock final : public Clock {
 public:
  explicit SteppingClock(SimTime step) : step_(step) {}
  SimTime now() const override { return now_ += step_; }

 private:
  SimTime step_;
  mutable SimTime now_{0};
};

// A paced server on a line of two slaves whose cables all take `extra` longer, the clock
// moving on by `clockStep` per reading, with one frame from the master waiting.
struct PacedWithDelay {
  PacedWithDelay(SimTime extra, SimTime clockStep) : clock(clockStep) {
    buildLine(seg, 2);
    delay.extra = extra;
    seg.setWireFaults(&delay);
    std::array<std::uint8_t, kMaxFrameSize> buf{};
    const std::size_t len = brdFrame(buf);
    EXPECT_TRUE(links.first.send(ConstBytes(buf.data(), len)).ok());
  }
  ~PacedWithDelay() { seg.setWireFaults(nullptr); }
  topology::Segment seg;
  FixedWireDelay delay;
  std::pair<MemoryLink, MemoryLink> links = MemoryLink::makePair();
  SteppingClock clock;
  topology::NetworkServer server{links.second, seg, clock, paced()};

  static topology::ServerOptions paced() {
    topology::ServerOptions options;
    options.paced = true;
    return options;
  }
};

// Issue #21: with --paced, `delay ns=1e14` held one answer for 27.8 hours.
TEST(NetworkServer, PacedModeDoesNotHoldAnAnswerBeyondTheBound) {
  PacedWithDelay t(100'000 * kNsPerSecond, 10 * kNsPerMs);  // 1e14 ns per cable crossing
  ASSERT_TRUE(t.server.step().ok());
  EXPECT_EQ(t.server.counters().framesLate, 1u);
  EXPECT_EQ(t.server.counters().framesAnswered, 0u);
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  auto none = t.links.first.receive(buf, std::chrono::milliseconds(5));
  ASSERT_TRUE(none.ok());
  EXPECT_EQ(*none, 0u) << "a frame beyond the paced bound is not answered";
}

TEST(NetworkServer, PacedWaitEndsWhenStopIsRaised) {
  // Within the bound: the answer would be held about 0.6 s.
  PacedWithDelay t(200 * kNsPerMs, 10 * kNsPerUs);
  int calls = 0;
  ASSERT_TRUE(t.server.run([&] { return ++calls > 1; }).ok());  // raised during the wait
  EXPECT_EQ(t.server.counters().framesReceived, 1u);
  EXPECT_EQ(t.server.counters().framesAnswered, 0u) << "the wait ended without answering";
}

// Issue 18: with ServerOptions::firmwareSpacing, frames that come back to back are answered
// without running the firmware between them; the run put off follows as soon as the wait for
// the next frame ends. Observed through the AL state machine, which the firmware runs: an AL
// control write is acted on (AL status 0x0130 changes) only when the firmware has run (ESC
// datasheet section I: without device emulation the PDI side, not the ESC, acts on AL
// control).
struct FirmwareSpacing {
  explicit FirmwareSpacing(unsigned spacing) : clock(kNsPerUs) {
    // With a mailbox: a slave with firmware, no device emulation (test_network.hpp).
    seg.addSlave(makeSlave("s", 0x100, {}, makeSii(0x0000ABCD, 0x100, 0x1000, 128, 0x1080, 128)));
    seg.wireLine();
    topology::ServerOptions options;
    options.firmwareSpacing = spacing;
    options.idleWait = std::chrono::milliseconds(2);
    server.emplace(links.second, seg, clock, options);
  }
  void send(Command c, std::uint16_t reg, std::vector<std::uint8_t> data) {
    std::array<std::uint8_t, kMaxFrameSize> buf{};
    FrameBuilder b(buf, EthernetHeader{});
    (void)b.add(c, 1, phys(0, reg), data);
    EXPECT_TRUE(links.first.send(ConstBytes(buf.data(), *b.finish())).ok());
  }
  // The AL status in the answer to a BRD of it.
  std::uint16_t alStatusAnswer() {
    std::array<std::uint8_t, kMaxFrameSize> buf{};
    auto got = links.first.receive(buf, std::chrono::milliseconds(100));
    EXPECT_TRUE(got.ok() && *got > 0);
    return readLe16(buf, kEthernetHeaderSize + 2 + 10);
  }
  topology::Segment seg;
  std::pair<MemoryLink, MemoryLink> links = MemoryLink::makePair();
  SteppingClock clock;  // 1 µs per reading: a firmware run takes time on it
  std::optional<topology::NetworkServer> server;
};

TEST(NetworkServer, FirmwareSpacingAnswersBackToBackFramesBeforeTheFirmwareRuns) {
  const std::uint16_t kPreOp = 0x0002;
  const std::uint16_t init = 0x0001;
  std::uint16_t withoutSpacing = 0;
  {
    FirmwareSpacing t(0);
    ASSERT_TRUE(t.server->step().ok());  // idle: the firmware runs once
    t.send(Command::kBwr, reg::kAlControl.address, le16(kPreOp));
    t.send(Command::kBrd, reg::kAlStatus.address, le16(0));
    ASSERT_TRUE(t.server->step().ok());
    ASSERT_TRUE(t.server->step().ok());
    std::array<std::uint8_t, kMaxFrameSize> buf{};
    ASSERT_TRUE(t.links.first.receive(buf, std::chrono::milliseconds(100)).ok());  // the BWR
    withoutSpacing = t.alStatusAnswer();
    EXPECT_NE(withoutSpacing, init) << "the firmware ran between the two frames";
  }
  FirmwareSpacing t(1000);
  ASSERT_TRUE(t.server->step().ok());  // idle: the firmware runs once (and takes 1 µs)
  t.send(Command::kBwr, reg::kAlControl.address, le16(kPreOp));
  t.send(Command::kBrd, reg::kAlStatus.address, le16(0));
  ASSERT_TRUE(t.server->step().ok());
  ASSERT_TRUE(t.server->step().ok());
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  ASSERT_TRUE(t.links.first.receive(buf, std::chrono::milliseconds(100)).ok());  // the BWR
  EXPECT_EQ(t.alStatusAnswer(), init) << "answered before the firmware saw the AL control";
  ASSERT_TRUE(t.server->step().ok());  // no frame: the run put off happens
  t.send(Command::kBrd, reg::kAlStatus.address, le16(0));
  ASSERT_TRUE(t.server->step().ok());
  EXPECT_EQ(t.alStatusAnswer(), withoutSpacing) << "the firmware has acted on it now";
}

// The network end's link, noting the timeout of every receive() (the server's looks at it).
class NotingLink final : public Link {
 public:
  explicit NotingLink(Link& inner) : inner_(inner) {}
  Status send(ConstBytes frame) override { return inner_.send(frame); }
  Result<std::size_t> receive(Bytes buffer, std::chrono::nanoseconds timeout) override {
    timeouts.push_back(timeout);
    return inner_.receive(buffer, timeout);
  }
  int pollFd() const override { return inner_.pollFd(); }
  std::string describe() const override { return inner_.describe(); }
  std::vector<std::chrono::nanoseconds> timeouts;

 private:
  Link& inner_;
};

// prefetchWhileIdle (`ecsim serve --busy-poll`): after an answer the server fetches the ESCs
// ahead for the next frame 32 at a time, looking at the link (without waiting) between
// groups, and only then waits; a frame that came meanwhile is answered at once, as it would
// have been without the pass, and the answers are the same.
TEST(NetworkServer, PrefetchWhileIdleLooksAtTheLinkBetweenGroupsAndAnswersAlike) {
  std::vector<std::vector<std::uint8_t>> answers[2];
  std::size_t looksBeforeTheWait[2]{};
  for (int prefetch = 0; prefetch < 2; ++prefetch) {
    topology::Segment seg;
    buildLine(seg, 100);
    auto [master, network] = MemoryLink::makePair();
    NotingLink noting(network);
    VirtualClock clock;
    topology::ServerOptions options;
    options.prefetchWhileIdle = prefetch == 1;
    topology::NetworkServer server(noting, seg, clock, options);
    std::array<std::uint8_t, kMaxFrameSize> buf{};
    const std::size_t len = brdFrame(buf);
    ASSERT_TRUE(master.send(ConstBytes(buf.data(), len)).ok());
    ASSERT_TRUE(server.step().ok());
    auto got = master.receive(buf, std::chrono::milliseconds(10));
    ASSERT_TRUE(got.ok() && *got == len);
    answers[prefetch].emplace_back(buf.begin(), buf.begin() + static_cast<long>(len));
    // No frame: the pass, then the wait.
    noting.timeouts.clear();
    ASSERT_TRUE(server.step().ok());
    ASSERT_FALSE(noting.timeouts.empty());
    EXPECT_GT(noting.timeouts.back(), std::chrono::nanoseconds::zero()) << "it ends waiting";
    looksBeforeTheWait[prefetch] = noting.timeouts.size() - 1;
    for (std::size_t i = 0; i + 1 < noting.timeouts.size(); ++i) {
      EXPECT_EQ(noting.timeouts[i], std::chrono::nanoseconds::zero());
    }
    // A frame already there when the step begins is answered in it, pass or not.
    brdFrame(buf);
    ASSERT_TRUE(master.send(ConstBytes(buf.data(), len)).ok());
    ASSERT_TRUE(server.step().ok());
    got = master.receive(buf, std::chrono::milliseconds(10));
    ASSERT_TRUE(got.ok() && *got == len);
    answers[prefetch].emplace_back(buf.begin(), buf.begin() + static_cast<long>(len));
  }
  EXPECT_EQ(answers[0], answers[1]);
  EXPECT_EQ(looksBeforeTheWait[0], 0u);
  EXPECT_EQ(looksBeforeTheWait[1], 5u) << "100 ESCs, 32 at a time: a look before each group, "
                                          "one after the last";
}

}  // namespace
}  // namespace ecsim::testing
