// The datagram transport: packing, splitting at the frame limit, index matching, retries with
// the same index, lost / late / unexpected frames, cached (cyclic) frames.
#include "master/transport.hpp"

#include <gtest/gtest.h>

#include <array>
#include <deque>

#include "master/batch.hpp"
#include "master/bus.hpp"
#include "protocol/registers.hpp"
#include "slavesim/generic_slave.hpp"
#include "tests/master/sim_network.hpp"

namespace ecsim::testing {
namespace {

using master::Datagram;
using master::DatagramState;
using master::Transport;

void addGenericSlaves(SimNetwork& net, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    net.segment().addSlave(
        slavesim::makeGenericSlave("Slave" + std::to_string(i + 1), static_cast<std::uint32_t>(i)));
  }
  net.segment().wireLine();
  net.start();
}

TEST(TransportTest, BroadcastReadCountsSlaves) {
  SimNetwork net;
  addGenericSlaves(net, 3);
  Transport transport(net.masterLink());
  Datagram brd;
  brd.prepare(Command::kBrd, DatagramHeader::physical(0, reg::kType.address), 2, 3);
  transport.queue(brd);
  EXPECT_EQ(brd.state(), DatagramState::kQueued);
  WaitTask wait({&brd});
  ASSERT_TRUE(master::runTask(wait, transport, net.bus(), kNsPerSecond).ok());
  EXPECT_EQ(brd.state(), DatagramState::kReceived);
  EXPECT_EQ(brd.wkc(), 3);
  EXPECT_TRUE(brd.check().ok());
  EXPECT_EQ(brd.data()[0], 0x11);  // ET1100 type register, ORed over three ET1100s
  EXPECT_EQ(transport.counters().framesSent, 1u);
  EXPECT_EQ(transport.counters().framesAnswered, 1u);
  EXPECT_TRUE(transport.idle());
}

// Frames in flight together pass the slaves together (a line forwards each frame as its bits
// arrive, so the second follows the first by its wire time, not by a round trip): on the
// VirtualBus both come back after one round trip. Serving them one round trip apiece made
// the 16th frame of a 1000-slave scan return after 16 x 2.1 ms, long after its timeout.
TEST(TransportTest, FramesInFlightTogetherReturnAfterOneRoundTrip) {
  SimNetwork net;
  addGenericSlaves(net, 200);
  Transport transport(net.masterLink());
  Datagram first;
  Datagram second;
  first.prepare(Command::kBrd, DatagramHeader::physical(0, reg::kType.address), 2, 200);
  second.prepare(Command::kBrd, DatagramHeader::physical(0, reg::kAlStatus.address), 2, 200);
  const SimTime start = net.clock().now();
  transport.queue(first);
  transport.flush(start);  // a frame of its own
  transport.queue(second);
  transport.flush(start);
  ASSERT_EQ(transport.framesInFlight(), 2u);
  WaitTask wait({&first, &second});
  ASSERT_TRUE(master::runTask(wait, transport, net.bus(), kNsPerSecond).ok());
  ASSERT_TRUE(first.received());
  ASSERT_TRUE(second.received());
  const SimTime roundTrip = net.server().counters().lastRoundTrip;
  EXPECT_GT(roundTrip, 200 * kNsPerUs);  // 200 ET1100 passages out and back
  EXPECT_EQ(first.receivedAt() - start, roundTrip);
  EXPECT_EQ(second.receivedAt() - start, roundTrip);
}

TEST(TransportTest, WrongWorkingCounterIsReportedWithRegisterName) {
  SimNetwork net;
  addGenericSlaves(net, 2);
  Transport transport(net.masterLink());
  Datagram brd;
  brd.prepare(Command::kBrd, DatagramHeader::physical(0, reg::kAlStatus.address), 2, 3);
  transport.queue(brd);
  WaitTask wait({&brd});
  ASSERT_TRUE(master::runTask(wait, transport, net.bus(), kNsPerSecond).ok());
  auto status = brd.check();
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().code, ErrorCode::kWorkingCounter);
  EXPECT_NE(status.error().context.find("AL Status"), std::string::npos) << status.error().context;
  EXPECT_NE(status.error().context.find("working counter 2, expected 3"), std::string::npos)
      << status.error().context;
}

TEST(TransportTest, ManySmallDatagramsShareFramesInOrder) {
  SimNetwork net;
  addGenericSlaves(net, 2);
  Transport transport(net.masterLink());
  // 300 BRDs of 2 bytes: 14 bytes each on the wire, at most 107 per 1498-byte frame.
  std::deque<Datagram> datagrams(300);
  std::vector<Datagram*> all;
  for (auto& d : datagrams) {
    d.prepare(Command::kBrd, DatagramHeader::physical(0, reg::kAlStatus.address), 2, 2);
    transport.queue(d);
    all.push_back(&d);
  }
  WaitTask wait(all);
  ASSERT_TRUE(master::runTask(wait, transport, net.bus(), kNsPerSecond).ok());
  for (auto& d : datagrams) {
    ASSERT_TRUE(d.check().ok()) << d.check().error().message();
    EXPECT_EQ(d.data()[0], 0x01);  // INIT
  }
  EXPECT_EQ(transport.counters().framesSent, 3u);  // 107 + 107 + 86
  for (std::size_t size : net.fault().sentSizes) EXPECT_LE(size, kMaxFrameSize);
  EXPECT_EQ(net.fault().sentSizes[0], 14u + 2u + 107u * 14u);
}

TEST(TransportTest, LargeDatagramsAreSplitAcrossFramesNeverTruncated) {
  SimNetwork net;
  addGenericSlaves(net, 1);
  Transport transport(net.masterLink());
  std::deque<Datagram> datagrams(4);
  // Reads of the register file: 1000 + 1000 + 1486 bytes, then one byte too many.
  datagrams[0].prepare(Command::kBrd, 0, 1000, 1);
  datagrams[1].prepare(Command::kBrd, 0, 1000, 1);
  datagrams[2].prepare(Command::kBrd, 0, static_cast<std::uint16_t>(Transport::kMaxDatagramData),
                       1);
  datagrams[3].prepare(Command::kBrd, 0,
                       static_cast<std::uint16_t>(Transport::kMaxDatagramData + 1), 1);
  std::vector<Datagram*> all;
  for (auto& d : datagrams) {
    transport.queue(d);
    all.push_back(&d);
  }
  WaitTask wait(all);
  ASSERT_TRUE(master::runTask(wait, transport, net.bus(), kNsPerSecond).ok());
  EXPECT_TRUE(datagrams[0].check().ok());
  EXPECT_TRUE(datagrams[1].check().ok());
  EXPECT_TRUE(datagrams[2].check().ok());
  EXPECT_EQ(datagrams[3].state(), DatagramState::kError);
  EXPECT_EQ(transport.counters().datagramsRefused, 1u);
  ASSERT_EQ(net.fault().sentSizes.size(), 3u);
  EXPECT_EQ(net.fault().sentSizes[0], 14u + 2u + 1012u);
  EXPECT_EQ(net.fault().sentSizes[2], kMaxFrameSize);  // exactly full
  EXPECT_EQ(datagrams[2].data()[0], 0x11);
}

TEST(TransportTest, LostFrameIsResentWithTheSameIndex) {
  SimNetwork net;
  addGenericSlaves(net, 2);
  Transport transport(net.masterLink());
  net.fault().dropSend = {1};
  Datagram brd;
  brd.prepare(Command::kBrd, 0, 2, 2);
  transport.queue(brd);
  WaitTask wait({&brd});
  const SimTime start = net.clock().now();
  ASSERT_TRUE(master::runTask(wait, transport, net.bus(), kNsPerSecond).ok());
  EXPECT_TRUE(brd.check().ok());
  EXPECT_EQ(transport.counters().framesResent, 1u);
  EXPECT_EQ(transport.counters().framesLost, 0u);
  EXPECT_EQ(net.fault().droppedSends, 1u);
  // The answer came after one timeout.
  EXPECT_GE(net.clock().now() - start, transport.options().timeout);
}

TEST(TransportTest, FrameLostOnEveryTryTimesOut) {
  SimNetwork net;
  addGenericSlaves(net, 1);
  Transport transport(net.masterLink());
  net.fault().dropAllSends = true;
  Datagram brd;
  brd.prepare(Command::kBrd, 0, 2, 1);
  transport.queue(brd);
  WaitTask wait({&brd});
  ASSERT_TRUE(master::runTask(wait, transport, net.bus(), kNsPerSecond).ok());
  EXPECT_EQ(brd.state(), DatagramState::kTimedOut);
  EXPECT_EQ(brd.check().error().code, ErrorCode::kTimeout);
  EXPECT_EQ(transport.counters().framesSent, 1u);
  EXPECT_EQ(transport.counters().framesResent, transport.options().retries);
  EXPECT_EQ(transport.counters().framesLost, 1u);
  EXPECT_EQ(net.fault().droppedSends, 1u + transport.options().retries);
}

// The test plays the network by hand on the other end of a MemoryLink.
class ManualPeerTest : public ::testing::Test {
 protected:
  ManualPeerTest() : links_(MemoryLink::makePair()) {}
  std::size_t take(std::array<std::uint8_t, kMaxFrameSize>& buffer) {
    auto r = links_.second.receive(buffer, std::chrono::nanoseconds(0));
    EXPECT_TRUE(r.ok());
    return r.ok() ? *r : 0;
  }
  void answer(std::array<std::uint8_t, kMaxFrameSize>& buffer, std::size_t length,
              std::uint16_t wkc) {
    auto frame = EtherCatFrame::parse(Bytes(buffer.data(), length));
    ASSERT_TRUE(frame.ok());
    for (auto d : *frame) d.setWkc(wkc);
    ASSERT_TRUE(links_.second.send(ConstBytes(buffer.data(), length)).ok());
  }
  std::pair<MemoryLink, MemoryLink> links_;
};

TEST_F(ManualPeerTest, AnswerAfterGivingUpCountsAsLate) {
  master::TransportOptions options;
  options.retries = 0;
  Transport transport(links_.first, options);
  Datagram d;
  d.prepare(Command::kBrd, 0, 2, 1);
  transport.queue(d);
  transport.poll(0);
  std::array<std::uint8_t, kMaxFrameSize> buffer{};
  const std::size_t length = take(buffer);
  ASSERT_GT(length, 0u);
  transport.poll(options.timeout);  // gives up
  EXPECT_EQ(d.state(), DatagramState::kTimedOut);
  EXPECT_EQ(transport.counters().framesLost, 1u);
  answer(buffer, length, 1);
  transport.poll(options.timeout + 1);
  // The network did return it: late, no longer lost; the datagram stays given up.
  EXPECT_EQ(transport.counters().framesLate, 1u);
  EXPECT_EQ(transport.counters().framesLost, 0u);
  EXPECT_EQ(d.state(), DatagramState::kTimedOut);
  answer(buffer, length, 1);  // a duplicate of that answer is only late again
  transport.poll(options.timeout + 2);
  EXPECT_EQ(transport.counters().framesLate, 2u);
  EXPECT_EQ(transport.counters().framesLost, 0u);
}

TEST_F(ManualPeerTest, DuplicateAnswerCountsAsLateAndForeignFrameAsUnexpected) {
  Transport transport(links_.first);
  Datagram d;
  d.prepare(Command::kBrd, 0, 2, 1);
  transport.queue(d);
  transport.poll(0);
  std::array<std::uint8_t, kMaxFrameSize> buffer{};
  const std::size_t length = take(buffer);
  answer(buffer, length, 1);
  answer(buffer, length, 1);
  transport.poll(10);
  EXPECT_TRUE(d.check().ok());
  EXPECT_EQ(transport.counters().framesAnswered, 1u);
  EXPECT_EQ(transport.counters().framesLate, 1u);
  // An index never used.
  auto frame = EtherCatFrame::parse(Bytes(buffer.data(), length));
  ASSERT_TRUE(frame.ok());
  (*frame->begin()).bytes()[1] = 200;
  answer(buffer, length, 1);
  // Not EtherCAT at all.
  std::array<std::uint8_t, 60> junk{};
  junk[12] = 0x08;
  ASSERT_TRUE(links_.second.send(junk).ok());
  transport.poll(20);
  EXPECT_EQ(transport.counters().framesUnexpected, 2u);
}

TEST_F(ManualPeerTest, AnswerWithOtherContentDoesNotComplete) {
  Transport transport(links_.first);
  Datagram d;
  d.prepare(Command::kFprd, DatagramHeader::physical(0x1001, reg::kAlStatus.address), 2, 1);
  transport.queue(d);
  transport.poll(0);
  std::array<std::uint8_t, kMaxFrameSize> buffer{};
  const std::size_t length = take(buffer);
  auto frame = EtherCatFrame::parse(Bytes(buffer.data(), length));
  ASSERT_TRUE(frame.ok());
  (*frame->begin()).setAddress(DatagramHeader::physical(0x1002, reg::kAlStatus.address));
  answer(buffer, length, 1);
  transport.poll(10);
  EXPECT_EQ(transport.counters().framesUnexpected, 1u);
  EXPECT_EQ(d.state(), DatagramState::kSent);
}

TEST_F(ManualPeerTest, CancelledDatagramIgnoresItsAnswer) {
  Transport transport(links_.first);
  Datagram a;
  Datagram b;
  a.prepare(Command::kBrd, 0, 2, 1);
  b.prepare(Command::kBrd, 0, 2, 1);
  transport.queue(a);
  transport.queue(b);
  transport.poll(0);
  transport.cancel(a);
  EXPECT_EQ(a.state(), DatagramState::kIdle);
  std::array<std::uint8_t, kMaxFrameSize> buffer{};
  const std::size_t length = take(buffer);
  answer(buffer, length, 1);
  transport.poll(10);
  EXPECT_EQ(a.state(), DatagramState::kIdle);
  EXPECT_TRUE(b.check().ok());
}

// Withdrawing queued datagrams (head, middle, tail; the queue is linked both ways so a
// scan of thousands of slaves does not walk it for each) leaves the others in their order,
// and a datagram queued again goes to the end.
TEST_F(ManualPeerTest, WithdrawnQueuedDatagramsLeaveTheRestInOrder) {
  Transport transport(links_.first);
  std::array<Datagram, 5> d;
  for (std::size_t i = 0; i < d.size(); ++i) {
    d[i].prepare(Command::kFprd,
                 DatagramHeader::physical(static_cast<std::uint16_t>(0x1001 + i),
                                          reg::kAlStatus.address),
                 2, 1);
    transport.queue(d[i]);
  }
  transport.cancel(d[0]);
  transport.cancel(d[2]);
  transport.cancel(d[4]);
  transport.queue(d[0]);
  transport.poll(0);
  std::array<std::uint8_t, kMaxFrameSize> buffer{};
  const std::size_t length = take(buffer);
  auto frame = EtherCatFrame::parse(Bytes(buffer.data(), length));
  ASSERT_TRUE(frame.ok());
  std::vector<std::uint16_t> stations;
  for (auto it = frame->begin(); it != frame->end(); ++it) stations.push_back((*it).adp());
  EXPECT_EQ(stations, (std::vector<std::uint16_t>{0x1002, 0x1004, 0x1001}));
  EXPECT_EQ(d[2].state(), DatagramState::kIdle);
  EXPECT_EQ(d[4].state(), DatagramState::kIdle);
  EXPECT_EQ(d[3].state(), DatagramState::kSent);
}

// A batch remembers its first pending datagram; one of its datagrams queued again alone
// (the health monitor sends its status reads again each interval) is pending again until
// its answer comes. Here no answer comes: with the memo left behind, pending() said false
// and the monitor read working counter 0 from every slave over veth.
TEST_F(ManualPeerTest, BatchDatagramQueuedAgainAloneIsPendingUntilAnswered) {
  Transport transport(links_.first);
  master::DatagramBatch batch;
  for (std::uint16_t i = 0; i < 2; ++i) {
    batch.add().fprd(static_cast<std::uint16_t>(0x1001 + i), reg::kAlStatus);
  }
  batch.queueAll(transport);
  transport.cancel(batch[0]);
  transport.cancel(batch[1]);
  EXPECT_FALSE(batch.pending());
  batch.queue(0, transport);
  EXPECT_TRUE(batch.pending());
  transport.poll(0);
  std::array<std::uint8_t, kMaxFrameSize> buffer{};
  EXPECT_GT(take(buffer), 0u);
  EXPECT_EQ(batch[0].state(), DatagramState::kSent);
  EXPECT_TRUE(batch.pending());
}

TEST_F(ManualPeerTest, CachedFrameGetsAFreshIndexEachTimeAndIsNeverRetried) {
  Transport transport(links_.first);
  master::CachedFrame cached;
  EthernetHeader eth{kBroadcastMac, {2, 0, 0, 0, 0, 1}, std::nullopt, kEtherTypeEtherCat};
  FrameBuilder builder(cached.buildBuffer(), eth);
  ASSERT_TRUE(builder.add(Command::kLrw, 0, 0, 8).ok());
  ASSERT_TRUE(builder.add(Command::kLrw, 0, 8, 8).ok());
  auto length = builder.finish();
  ASSERT_TRUE(length.ok());
  ASSERT_TRUE(cached.commit(*length).ok());
  EXPECT_EQ(cached.datagramCount(), 2u);

  std::array<std::uint8_t, kMaxFrameSize> buffer{};
  ASSERT_TRUE(transport.send(cached, 0).ok());
  EXPECT_FALSE(transport.send(cached, 0).ok());  // still in flight
  std::size_t n = take(buffer);
  const std::uint8_t firstIndex = buffer[16 + 1];
  EXPECT_EQ(buffer[16 + 12 + 8 + 1], firstIndex);  // both datagrams carry it
  answer(buffer, n, 3);
  transport.poll(5);
  EXPECT_EQ(cached.state(), DatagramState::kReceived);
  EXPECT_EQ(cached.rxWkc(0), 3);
  EXPECT_EQ(cached.rxWkc(1), 3);

  ASSERT_TRUE(transport.send(cached, 10).ok());
  n = take(buffer);
  EXPECT_NE(buffer[16 + 1], firstIndex);
  transport.poll(10 + transport.options().timeout);  // no retry for cyclic frames
  EXPECT_EQ(cached.state(), DatagramState::kTimedOut);
  EXPECT_EQ(transport.counters().framesResent, 0u);
  EXPECT_EQ(transport.counters().framesLost, 1u);

  ASSERT_TRUE(transport.send(cached, 20).ok());
  transport.abandon(cached);
  EXPECT_EQ(transport.counters().framesLost, 2u);
  EXPECT_TRUE(transport.idle());
}

// A peer that answers inside send(): the answer is already waiting on the link (its eventfd
// readable) before the master's loop gets to wait.
class InstantPeerLink final : public Link {
 public:
  InstantPeerLink() : links_(MemoryLink::makePair()) {}
  Status send(ConstBytes frame) override {
    ECSIM_TRY(links_.first.send(frame));
    std::array<std::uint8_t, kMaxFrameSize> buffer{};
    auto n = links_.second.receive(buffer, std::chrono::nanoseconds(0));
    if (!n.ok() || *n == 0) return okStatus();
    auto parsed = EtherCatFrame::parse(Bytes(buffer.data(), *n));
    if (parsed.ok()) {
      for (auto d : *parsed) d.setWkc(1);
    }
    return links_.second.send(ConstBytes(buffer.data(), *n));
  }
  Result<std::size_t> receive(Bytes buffer, std::chrono::nanoseconds timeout) override {
    return links_.first.receive(buffer, timeout);
  }
  int pollFd() const override { return links_.first.pollFd(); }
  std::string describe() const override { return "instant peer"; }

 private:
  std::pair<MemoryLink, MemoryLink> links_;
};

TEST(RunTaskTest, RealTimeLoopDoesNotSleepOnAnAnswerAlreadyReceived) {
  InstantPeerLink link;
  RealClock clock;
  master::RealTimeBus bus(link, clock);
  Transport transport(link);
  std::deque<Datagram> datagrams(20);
  std::size_t next = 0;
  // Each answered datagram makes the task queue the next one.
  class Chain final : public master::Task {
   public:
    Chain(Transport& t, std::deque<Datagram>& d, std::size_t& n) : t_(t), d_(d), n_(n) {}
    bool step(SimTime) override {
      if (n_ > 0 && d_[n_ - 1].pending()) return true;
      if (n_ == d_.size()) return false;
      d_[n_].prepare(Command::kBrd, 0, 2, 1);
      t_.queue(d_[n_++]);
      return true;
    }

   private:
    Transport& t_;
    std::deque<Datagram>& d_;
    std::size_t& n_;
  } chain(transport, datagrams, next);
  // The first one is queued before the loop starts (as ScanTask::start() does): the loop's
  // first poll sends it, and its answer is back before the loop gets to wait.
  datagrams[0].prepare(Command::kBrd, 0, 2, 1);
  transport.queue(datagrams[0]);
  next = 1;
  const SimTime start = clock.now();
  ASSERT_TRUE(master::runTask(chain, transport, bus, 20 * kNsPerSecond).ok());
  // 20 round trips through memory: far below one second (a wait until the task deadline
  // after each answer would take 20 x 20 s).
  EXPECT_LT(clock.now() - start, kNsPerSecond);
  for (auto& d : datagrams) EXPECT_TRUE(d.check().ok());
}

}  // namespace
}  // namespace ecsim::testing
