// SimulatedNetwork: built from the demo topology (examples/topologies/demo.xml), driven in
// virtual time, slaves reached by name from the PDI side; a master is our own, in-process.
#include "embed/simulated_network.hpp"

#include <gtest/gtest.h>

#include <array>

#include "link/memory_link.hpp"
#include "master/bus.hpp"
#include "master/master.hpp"
#include "protocol/registers.hpp"
#include "slavesim/generic_slave.hpp"

namespace ecsim::embed {
namespace {

const std::filesystem::path kDemo = ECSIM_SOURCE_DIR "/examples/topologies/demo.xml";

std::unique_ptr<SimulatedNetwork> demo() {
  auto net = SimulatedNetwork::fromTopologyFile(kDemo);
  EXPECT_TRUE(net.ok()) << (net.ok() ? "" : net.error().message());
  return net.ok() ? std::move(net).value() : nullptr;
}

TEST(SimulatedNetwork, BuildsTheDemoTopologyAndFindsSlavesByName) {
  auto net = demo();
  ASSERT_NE(net, nullptr);
  EXPECT_EQ(net->slaveCount(), 6u);  // Coupler, DI1, DO1, AI1, Drive1, Drive2 in demo.xml
  EXPECT_EQ(net->findSlave("DO1"), std::optional<std::size_t>(2));
  auto drive = net->slave("Drive2");
  ASSERT_TRUE(drive.ok());
  EXPECT_EQ(drive->position(), 5u);
  EXPECT_EQ(drive->state(), AlState::kInit);
  EXPECT_EQ(drive->alStatusCode(), 0u);
  auto missing = net->slave("Nobody");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().code, ErrorCode::kNotFound);
  EXPECT_NE(missing.error().context.find("Nobody"), std::string::npos);
  EXPECT_FALSE(net->slave(6).ok());
}

TEST(SimulatedNetwork, MissingTopologyFileIsAnErrorNamingTheFile) {
  auto net = SimulatedNetwork::fromTopologyFile("/nonexistent/topology.xml");
  ASSERT_FALSE(net.ok());
  EXPECT_NE(net.error().context.find("/nonexistent/topology.xml"), std::string::npos);
}

TEST(SimulatedNetwork, ReadsAndWritesDictionaryEntriesWithoutAMaster) {
  auto net = demo();
  ASSERT_NE(net, nullptr);
  auto di = net->slave("DI1");
  ASSERT_TRUE(di.ok());
  // demo.xml sets 0x6000:01 and 0x6000:03 to 1 and leaves 0x6000:02 at 0.
  EXPECT_EQ(di->read<bool>(0x6000, 1).valueOr(false), true);
  EXPECT_EQ(di->read<bool>(0x6000, 2).valueOr(true), false);
  EXPECT_EQ(di->read<bool>(0x6000, 3).valueOr(false), true);
  ASSERT_TRUE(di->write<bool>(0x6000, 2, true).ok());
  EXPECT_EQ(di->read<bool>(0x6000, 2).valueOr(false), true);
  // Identity from the ESI (0x1018:02 product code of the DI8 terminal, 0x00001008).
  EXPECT_EQ(di->read<std::uint32_t>(0x1018, 2).valueOr(0), 0x00001008u);
  auto raw = di->readEntry(0x1018, 2);
  ASSERT_TRUE(raw.ok());
  EXPECT_EQ(*raw, (std::vector<std::uint8_t>{0x08, 0x10, 0x00, 0x00}));
  EXPECT_FALSE(di->readEntry(0x5FFF, 0).ok());
}

TEST(SimulatedNetwork, RegistersFromThePdiSide) {
  auto net = demo();
  ASSERT_NE(net, nullptr);
  auto coupler = net->slave("Coupler");
  ASSERT_TRUE(coupler.ok());
  auto status = coupler->readRegister16(reg::kAlStatus.address);
  ASSERT_TRUE(status.ok());
  EXPECT_EQ(*status & 0x0F, 0x01);  // INIT
  const std::array<std::uint8_t, 2> code{0x1D, 0x00};
  ASSERT_TRUE(coupler->writeRegisters(reg::kAlStatusCode.address, code).ok());
  EXPECT_EQ(coupler->alStatusCode(), 0x001Du);
  EXPECT_FALSE(coupler->readRegisters(0xFFFF, 2).ok());
}

TEST(SimulatedNetwork, RunForAdvancesVirtualTimeOnly) {
  auto net = demo();
  ASSERT_NE(net, nullptr);
  ASSERT_NE(net->virtualClock(), nullptr);
  EXPECT_EQ(net->now(), 0);
  ASSERT_TRUE(net->runFor(5 * kNsPerMs).ok());
  EXPECT_EQ(net->now(), 5 * kNsPerMs);
}

TEST(SimulatedNetwork, AnswersFramesOnAnAttachedLink) {
  auto net = demo();
  ASSERT_NE(net, nullptr);
  auto [masterEnd, networkEnd] = MemoryLink::makePair(16);
  net->attach(networkEnd);
  // A BRD of the AL status (0x0130): every one of the 6 slaves increments the WKC.
  std::array<std::uint8_t, 64> frame{};
  const std::size_t n = [&] {
    FrameBuilder b(frame, EthernetHeader{});
    // ADP 0 in the low half of the address, ADO (the register) in the high half.
    (void)b.add(Command::kBrd, 0, std::uint32_t{reg::kAlStatus.address} << 16, 2);
    return b.finish().valueOr(std::size_t{0});
  }();
  ASSERT_GT(n, 0u);
  ASSERT_TRUE(masterEnd.send(ConstBytes(frame.data(), n)).ok());
  ASSERT_TRUE(net->runFor(kNsPerMs).ok());
  std::array<std::uint8_t, kMaxFrameSize> back{};
  auto got = masterEnd.receive(back, std::chrono::nanoseconds(0));
  ASSERT_TRUE(got.ok());
  ASSERT_EQ(*got, n);
  auto parsed = EtherCatFrame::parse(Bytes(back.data(), *got));
  ASSERT_TRUE(parsed.ok());
  ASSERT_EQ(parsed->datagramCount(), 1u);
  EXPECT_EQ((*parsed->begin()).wkc(), 6u);
  EXPECT_EQ(net->serverCounters().framesAnswered, 1u);
}

TEST(SimulatedNetwork, OurMasterReachesOpAndTheTestSeesItsOutputs) {
  auto net = demo();
  ASSERT_NE(net, nullptr);
  auto [masterEnd, networkEnd] = MemoryLink::makePair(256);
  net->attach(networkEnd);
  master::VirtualBus bus(*net->virtualClock(), [&](SimTime) { return net->serveOne(); });
  master::Master m(masterEnd, bus);
  ASSERT_TRUE(m.start().ok());
  for (std::size_t i = 0; i < net->slaveCount(); ++i) {
    EXPECT_EQ(net->slave(i)->state(), AlState::kOp) << net->slave(i)->name();
  }
  // DO1's outputs: the master writes the first output byte of the DO terminal.
  std::optional<std::size_t> doByte;
  std::optional<std::size_t> diByte;
  for (const auto& v : master::processVariables(m.layout())) {
    if (v.output && v.index == 0x7000 && v.subindex == 1) doByte = v.bitOffset / 8;
    // DI1 (position 1); AI1 has a 0x6000:01 too (16 bits, its first channel).
    if (!v.output && v.position == 1 && v.index == 0x6000 && v.subindex == 1) {
      diByte = v.bitOffset / 8;
    }
  }
  ASSERT_TRUE(doByte.has_value());
  ASSERT_TRUE(diByte.has_value());
  const std::uint8_t pattern = 0x05;  // channels 1 and 3
  ASSERT_TRUE(m.writeData(*doByte, ConstBytes(&pattern, 1)).ok());
  // An input the test sets on DI1 reaches the master's process image.
  ASSERT_TRUE(net->slave("DI1")->write<bool>(0x6000, 2, true).ok());
  for (int c = 0; c < 3; ++c) {
    ASSERT_TRUE(m.exchange().ok());
    net->virtualClock()->advance(kNsPerMs);
  }
  auto out = net->slave("DO1");
  EXPECT_EQ(out->read<bool>(0x7000, 1).valueOr(false), true);
  EXPECT_EQ(out->read<bool>(0x7000, 2).valueOr(true), false);
  EXPECT_EQ(out->read<bool>(0x7000, 3).valueOr(false), true);
  // The same outputs as the raw SM buffer the master wrote (DO1 has one output SM).
  std::optional<std::vector<std::uint8_t>> buffer;
  for (unsigned sm = 0; sm < 8 && !buffer; ++sm) {
    if (auto b = out->outputBuffer(sm); b.ok()) buffer = *b;
  }
  ASSERT_TRUE(buffer.has_value());
  ASSERT_EQ(buffer->size(), 1u);
  EXPECT_EQ((*buffer)[0], 0x05);
  EXPECT_EQ(out->outputBuffer(7).error().code, ErrorCode::kNotFound);
  const std::uint8_t junk = 0xFF;
  EXPECT_EQ(out->writeInputBuffer(7, ConstBytes(&junk, 1)).error().code, ErrorCode::kState);
  std::uint8_t in = 0;
  ASSERT_TRUE(m.readData(*diByte, Bytes(&in, 1)).ok());
  EXPECT_EQ(in & 0x07, 0x07);  // 1 and 3 from demo.xml, 2 from the test
  EXPECT_TRUE(m.stop().ok());
}

TEST(SimulatedNetwork, RealTimeRunForTakesRealTimeAndServeStopsWhenAsked) {
  NetworkOptions options;
  options.time = TimeMode::kRealTime;
  options.idleWait = kNsPerMs;
  auto net = SimulatedNetwork::fromTopologyFile(kDemo, options);
  ASSERT_TRUE(net.ok());
  EXPECT_EQ((*net)->virtualClock(), nullptr);
  const SimTime before = (*net)->now();
  ASSERT_TRUE((*net)->runFor(20 * kNsPerMs).ok());
  EXPECT_GE((*net)->now() - before, 20 * kNsPerMs);
  int steps = 0;
  ASSERT_TRUE((*net)->serve([&] { return ++steps > 3; }).ok());
  EXPECT_EQ(steps, 4);
}

TEST(SimulatedNetwork, WrapsANetworkBuiltInCode) {
  topology::Network network;
  network.segment = std::make_unique<topology::Segment>();
  network.segment->addSlave(slavesim::makeGenericSlave("G1", 1));
  network.segment->addSlave(slavesim::makeGenericSlave("G2", 2));
  network.segment->wireLine();
  auto net = SimulatedNetwork::fromNetwork(std::move(network));
  EXPECT_EQ(net->slaveCount(), 2u);
  auto g2 = net->slave("G2");
  ASSERT_TRUE(g2.ok());
  EXPECT_FALSE(g2->hasDictionary());
  EXPECT_EQ(g2->read<int>(0x1000, 0).error().code, ErrorCode::kNotFound);
}

}  // namespace
}  // namespace ecsim::embed
