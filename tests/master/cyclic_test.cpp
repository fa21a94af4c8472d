// The cyclic path: frames built once from the layout, only output bytes copied in and input
// bytes copied out, no heap allocation by the master per cycle (counted with a replaced
// global operator new, switched on only around the master's own calls).
#include "master/cyclic.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "master/master.hpp"
#include "tests/master/bring_up.hpp"
#include "tests/master/test_slaves.hpp"

#include "support/allocation_counter.hpp"

namespace ecsim::testing {
namespace {

class Counting {
 public:
  Counting() { gCounting = true; }
  ~Counting() { gCounting = false; }
};

TEST(CyclicTest, FramesAreBuiltOnceWithTheLayoutsDatagrams) {
  SimNetwork net;
  net.segment().addSlave(makeIoSlave("A", 0x10, 3, 2));
  net.segment().addSlave(makeIoSlave("B", 0x10, 0, 1));
  net.segment().wireLine();
  net.start();
  master::Master m(net.masterLink(), net.bus());
  ASSERT_TRUE(m.start().ok());
  master::CyclicExchange cyclic;
  ASSERT_TRUE(cyclic.build(m.layout(), {2, 0, 0, 0, 0, 9}).ok());
  ASSERT_EQ(cyclic.frameCount(), 1u);
  auto frame = ConstEtherCatFrame::parse(cyclic.frame(0).tx());
  ASSERT_TRUE(frame.ok());
  ASSERT_EQ(frame->datagramCount(), 1u);
  auto d = *frame->begin();
  EXPECT_EQ(d.command(), Command::kLrw);
  EXPECT_EQ(d.address(), 0u);
  EXPECT_EQ(d.length(), 3 + 4 + 2);
}

TEST(CyclicTest, NoAllocationPerCycleInTheMaster) {
  SimNetwork net;
  net.segment().addSlave(makeIoSlave("A", 0x10, 3, 2));
  net.segment().addSlave(makeCoeIoSlave("C", 0x51, 2, 2));
  net.segment().addSlave(makeDemoSlave(0x7201, "Drive"));
  net.segment().wireLine();
  net.start();
  master::Master m(net.masterLink(), net.bus());
  ASSERT_TRUE(m.start().ok());
  master::CyclicExchange cyclic;
  ASSERT_TRUE(cyclic.build(m.layout(), {2, 0, 0, 0, 0, 9}).ok());
  std::vector<std::uint8_t> image(m.layout().size(), 0);
  master::Transport& transport = m.transport();
  gAllocations = 0;
  std::uint64_t wkcErrors = 0;
  for (int cycle = 0; cycle < 200; ++cycle) {
    image[0] = static_cast<std::uint8_t>(cycle);
    {
      Counting on;
      ASSERT_TRUE(cyclic.send(transport, image, net.clock().now()).ok());
      transport.poll(net.clock().now());
    }
    while (cyclic.pending()) {
      net.bus().wait(net.clock().now() + transport.options().timeout);  // the simulator
      Counting on;
      transport.poll(net.clock().now());
    }
    Counting on;
    auto result = cyclic.finish(image);
    wkcErrors += result.wkcErrors + result.framesLost;
  }
  EXPECT_EQ(gAllocations.load(), 0u);
  EXPECT_EQ(wkcErrors, 0u);
  EXPECT_EQ(cyclic.statistics().cycles, 200u);
  EXPECT_EQ(net.segment().slave(0).esc().pdiOutputs(0)[0], 199);
}

// An FRMW of the reference's system time given by the layout (as an ENI's Cmd with a Cnt) is
// sent as a NOP while the distribution is held, its WKC then not checked; released, it is the
// FRMW again with its WKC checked.
TEST(CyclicTest, HeldDcDistributionGoesAsANopAndIsNotCounted) {
  SimNetwork net;
  net.segment().addSlave(makeDemoSlave(0x7201, "DriveA"));
  net.segment().addSlave(makeDemoSlave(0x7201, "DriveB"));
  net.segment().wireLine();
  net.start();
  master::Master m(net.masterLink(), net.bus());
  ASSERT_TRUE(m.start().ok());
  master::ProcessImageLayout layout = m.layout();
  master::LogicalDatagram frmw;
  frmw.command = Command::kFrmw;
  frmw.logicalStart = m.slaves()[0].station | std::uint32_t{reg::kSystemTime.address} << 16;
  frmw.length = 8;
  frmw.expectedWkc = 2;  // read at DriveA, written at DriveB
  frmw.slaves = {0, 1};
  frmw.contributions = {1, 1};
  layout.datagrams.push_back(frmw);
  master::CyclicExchange cyclic;
  ASSERT_TRUE(cyclic.build(layout, {2, 0, 0, 0, 0, 9}).ok());
  std::vector<std::uint8_t> image(layout.size(), 0);
  master::Transport& transport = m.transport();
  auto exchange = [&] {
    EXPECT_TRUE(cyclic.send(transport, image, net.clock().now()).ok());
    transport.poll(net.clock().now());
    while (cyclic.pending()) {
      net.bus().wait(net.clock().now() + transport.options().timeout);
      transport.poll(net.clock().now());
    }
    return cyclic.finish(image);
  };
  auto commandSent = [&] {
    auto frame = ConstEtherCatFrame::parse(cyclic.frame(0).tx());
    EXPECT_TRUE(frame.ok());
    Command last = Command::kLrw;
    for (auto d : *frame) last = d.command();  // the FRMW is the frame's last datagram
    return last;
  };
  const std::size_t index = layout.datagrams.size() - 1;

  auto result = exchange();
  EXPECT_EQ(result.wkcErrors, 0u);
  EXPECT_EQ(commandSent(), Command::kFrmw);
  EXPECT_EQ(cyclic.receivedWkc(index), std::optional<std::uint16_t>(2));
  EXPECT_TRUE(cyclic.dcSystemTime());

  cyclic.holdDcDistribution(true);
  result = exchange();
  EXPECT_EQ(commandSent(), Command::kNop);
  EXPECT_EQ(cyclic.receivedWkc(index), std::optional<std::uint16_t>(0)) << "no slave executes it";
  EXPECT_EQ(result.wkcErrors, 0u) << "a held datagram's WKC is not checked";
  EXPECT_FALSE(cyclic.dcSystemTime());

  cyclic.holdDcDistribution(false);
  result = exchange();
  EXPECT_EQ(commandSent(), Command::kFrmw);
  EXPECT_EQ(result.wkcErrors, 0u);
  EXPECT_EQ(cyclic.receivedWkc(index), std::optional<std::uint16_t>(2));
  // The check is back: the same FRMW with another expectation is an error again.
  cyclic.setExpectedWkc(index, 3, 3);
  EXPECT_EQ(exchange().wkcErrors, 1u);
}

// With DC the master adds an FRMW of the reference's system time (ESC datasheet section I, 9.1:
// the reference clock's 0x0910 read and written to the others) to the first frame. A process
// image that fills that frame (more than one frame's worth of data) left no room for it, and
// build() failed: "frame would be 1516 bytes" (found by the latency study with 45 drives). It
// now goes in a frame of its own; every frame stays within 1514 bytes.
TEST(CyclicTest, DcDistributionGetsAFrameOfItsOwnWhenTheFirstIsFull) {
  master::ProcessImageLayout layout;
  layout.logicalBase = 0x10000;
  master::LogicalDatagram lrw;
  lrw.command = Command::kLrw;
  lrw.logicalStart = layout.logicalBase;
  lrw.length = static_cast<std::uint16_t>(kMaxFrameSize - kEthernetHeaderSize -
                                          kEtherCatHeaderSize - kDatagramOverhead);
  lrw.frame = 0;
  layout.datagrams.push_back(lrw);
  layout.outputBytes = lrw.length;
  layout.frameCount = 1;
  master::CyclicExchange cyclic;
  cyclic.setDcReference(0x1001);
  ASSERT_TRUE(cyclic.build(layout, {2, 0, 0, 0, 0, 9}).ok());
  ASSERT_EQ(cyclic.frameCount(), 2u);
  std::vector<Command> commands;
  for (std::size_t f = 0; f < cyclic.frameCount(); ++f) {
    EXPECT_LE(cyclic.frame(f).tx().size(), kMaxFrameSize);
    auto frame = ConstEtherCatFrame::parse(cyclic.frame(f).tx());
    ASSERT_TRUE(frame.ok());
    for (auto d : *frame) commands.push_back(d.command());
  }
  EXPECT_EQ(commands, (std::vector<Command>{Command::kLrw, Command::kFrmw}));

  // With room in the first frame, the FRMW rides in it: one frame.
  layout.datagrams[0].length = 100;
  layout.outputBytes = 100;
  master::CyclicExchange small;
  small.setDcReference(0x1001);
  ASSERT_TRUE(small.build(layout, {2, 0, 0, 0, 0, 9}).ok());
  EXPECT_EQ(small.frameCount(), 1u);
}

TEST(CyclicTest, CounterCatchesAnAllocation) {
  // The counting itself works (so the test above can fail).
  gAllocations = 0;
  {
    Counting on;
    // A direct call: a new-expression may be elided by the compiler, this may not.
    void* p = ::operator new(16);
    ::operator delete(p);
  }
  EXPECT_EQ(gAllocations.load(), 1u);
}

}  // namespace
}  // namespace ecsim::testing
