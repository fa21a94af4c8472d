// The SSI encoder interface terminal (slavesim/devices/encoder_terminal.hpp): ecsim's ECS5001
// (examples/esi/ecsim_encoders.xml) through frames, its fault model (status bits, frozen
// position, toggle, recovery), a power cycle and a restart with a state file; and the real
// Beckhoff EJ5002 from its ESI (../shared/esi/Beckhoff_EJ5xxx.xml, revision 0x00110000).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <numbers>

#include "config/topology_file.hpp"
#include "slavesim/devices/device_models.hpp"
#include "tests/slavesim/drive_test_support.hpp"
#include "tests/support/test_network.hpp"
#include "topology/faults.hpp"
#include "topology/network_builder.hpp"

namespace ecsim::testing {
namespace {

namespace ef = dev::encoder_fault;
constexpr double kTurn = 2.0 * std::numbers::pi;
constexpr double kCpr = 131072.0;  // the encoder's default resolution
constexpr std::uint32_t kEcs5001 = 0x00005001;

// A shaft angle half a count above `counts`, so the reading is `counts` whatever the rounding.
double angleFor(double counts) {
  return (counts + 0.5) / kCpr * kTurn;
}
std::uint32_t asCounter(double counts) {
  return static_cast<std::uint32_t>(static_cast<std::int32_t>(counts));
}

// The SM0 image of the ECS5001 (its TxPDO 0x1A00, the layout of EJ5002 rev 0x00110000 TxPDO
// 0x1A00 in ../shared/esi/Beckhoff_EJ5xxx.xml): a 16-bit status word, then the counter value.
constexpr std::uint16_t kImageBytes = 6;
constexpr std::uint16_t kDataError = 1u << 0, kFrameError = 1u << 1, kPowerFailure = 1u << 2,
                        kTxPdoState = 1u << 14, kTxPdoToggle = 1u << 15;
constexpr std::size_t kStatus = 0, kCounter = 2;

const EsiFile& encodersEsi() {
  static const EsiFile file = [] {
    auto f = loadEsiFile(std::filesystem::path(ECSIM_SOURCE_DIR) / "examples" / "esi" /
                         "ecsim_encoders.xml");
    EXPECT_TRUE(f.ok()) << (f.ok() ? "" : f.error().message());
    return f.ok() ? std::move(f).value() : EsiFile{};
  }();
  return file;
}

std::unique_ptr<slavesim::Slave> makeEncoder(slavesim::EsiSlaveOptions options = {}) {
  for (const auto& d : encodersEsi().devices) {
    if (d.productCode != kEcs5001) continue;
    auto slave = slavesim::makeSlaveFromEsi(encodersEsi(), d, "Encoder1", options);
    EXPECT_TRUE(slave.ok()) << (slave.ok() ? "" : slave.error().message());
    return slave.ok() ? std::move(slave).value() : nullptr;
  }
  ADD_FAILURE() << "no ECS5001 in ecsim_encoders.xml";
  return nullptr;
}

struct EncoderNet {
  topology::Segment seg;
  CyclicExchange x{seg, 0, kImageBytes};
  dev::SsiEncoderTerminal* terminal() { return dev::encoderTerminalOf(seg.slave(0)); }
  std::uint16_t status() const { return x.in16(kStatus); }
  std::uint32_t counter() const { return static_cast<std::uint32_t>(x.in32(kCounter)); }
  void toOp() {
    OpSlave op = bringToOp(seg, {{0, false, kImageBytes}}, x.now);
    ASSERT_EQ(op.inBytes, kImageBytes);
    x.cycle();
    x.cycle();
    ASSERT_EQ(x.wkc, 1);
  }
};

TEST(EncoderTerminal, Ecs5001PublishesThePositionWithValidStatusAndAToggle) {
  EncoderNet n;
  n.seg.addSlave(makeEncoder());
  ASSERT_NE(n.terminal(), nullptr) << "makeSlaveFromEsi attached the encoder model";
  EXPECT_EQ(n.terminal()->channels(), 1u);
  n.terminal()->setShaftAngle(1, angleFor(-3.25 * kCpr));  // 3.25 turns backwards
  n.toOp();
  EXPECT_EQ(n.counter(), asCounter(-3.25 * kCpr)) << "multi-turn, signed, in 32 bits";
  EXPECT_EQ(n.status() & (kDataError | kFrameError | kPowerFailure | kTxPdoState), 0);
  // The toggle flips with each reading (each firmware step): over a few cycles both values show.
  unsigned toggles = 0;
  for (int i = 0; i < 8; ++i) {
    n.x.cycle();
    toggles |= (n.status() & kTxPdoToggle) != 0 ? 2u : 1u;
  }
  EXPECT_EQ(toggles, 3u) << "the toggle moves while the data are valid";
}

TEST(EncoderTerminal, DataErrorFreezesThePositionAndTheToggleUntilCleared) {
  EncoderNet n;
  n.seg.addSlave(makeEncoder());
  n.terminal()->setShaftAngle(1, 1.0 * kTurn);
  n.toOp();
  ASSERT_EQ(n.counter(), 131072u);
  n.terminal()->setFault(1, ef::kData);
  n.x.cycle();
  n.x.cycle();
  EXPECT_EQ(n.status() & (kDataError | kTxPdoState), kDataError | kTxPdoState);
  EXPECT_EQ(n.status() & (kFrameError | kPowerFailure), 0);
  n.terminal()->setShaftAngle(1, 2.0 * kTurn);  // the shaft moves on, unseen
  const std::uint16_t toggle = n.status() & kTxPdoToggle;
  for (int i = 0; i < 3; ++i) n.x.cycle();
  EXPECT_EQ(n.counter(), 131072u) << "frozen at the last valid reading";
  EXPECT_EQ(n.status() & kTxPdoToggle, toggle) << "no new data: the toggle stands still";
  n.terminal()->setFault(1, ef::kNone);
  n.x.cycle();
  n.x.cycle();
  EXPECT_EQ(n.status() & (kDataError | kTxPdoState), 0);
  EXPECT_EQ(n.counter(), 262144u) << "valid again: the shaft where it is now";
}

TEST(EncoderTerminal, PowerFailureAlsoMeansNoDataAndFrameErrorStandsAlone) {
  EncoderNet n;
  n.seg.addSlave(makeEncoder());
  n.toOp();
  n.terminal()->setFault(1, ef::kPower);
  n.x.cycle();
  n.x.cycle();
  EXPECT_EQ(n.status() & (kDataError | kFrameError | kPowerFailure | kTxPdoState),
            kDataError | kPowerFailure | kTxPdoState);
  n.terminal()->setFault(1, ef::kFrame);
  n.x.cycle();
  n.x.cycle();
  EXPECT_EQ(n.status() & (kDataError | kFrameError | kPowerFailure | kTxPdoState),
            kFrameError | kTxPdoState);
}

// A power cycle of the terminal: the multi-turn position (the shaft did not move) and the
// fault (outside the terminal) are still there; a script keeps driving the shaft.
TEST(EncoderTerminal, PowerCycleKeepsMultiTurnPositionFaultAndScript) {
  EncoderNet n;
  n.seg.addSlave(makeEncoder());
  slavesim::Slave& slave = n.seg.slave(0);
  n.terminal()->setShaftAngle(1, angleFor(5.75 * kCpr));
  n.toOp();
  ASSERT_EQ(n.counter(), asCounter(5.75 * kCpr));
  n.terminal()->setFault(1, ef::kPower);
  slave.powerOff();
  slave.powerOn(n.x.now);
  ASSERT_TRUE(slave.coldStartStatus().ok()) << slave.coldStartStatus().error().message();
  ASSERT_NE(n.terminal(), nullptr);
  EXPECT_EQ(slave.state(), AlState::kInit);
  EXPECT_EQ(n.terminal()->fault(1), ef::kPower);
  n.terminal()->setFault(1, ef::kNone);
  n.x.now += kNsPerMs;
  n.toOp();
  EXPECT_EQ(n.counter(), asCounter(5.75 * kCpr)) << "absolute: kept";

  n.terminal()->setScript(1, dev::Signal::constant(angleFor(-1.5 * kCpr) / kTurn));  // turns
  slave.powerOff();
  slave.powerOn(n.x.now);
  n.x.now += kNsPerMs;
  n.toOp();
  EXPECT_EQ(n.counter(), asCounter(-1.5 * kCpr)) << "the script drives the new terminal";
}

TEST(EncoderTerminal, IncrementalEncoderCountsFromZeroAfterAPowerCycle) {
  slavesim::EsiSlaveOptions options;
  options.models.drive.encoder.kind = dev::EncoderKind::kIncremental;
  EncoderNet n;
  n.seg.addSlave(makeEncoder(options));
  n.toOp();
  n.terminal()->setShaftAngle(1, 0.5 * kTurn);
  n.x.cycle();
  n.x.cycle();
  EXPECT_EQ(n.counter(), 65536u);
  n.seg.slave(0).powerOff();
  n.seg.slave(0).powerOn(n.x.now);
  n.x.now += kNsPerMs;
  n.toOp();
  EXPECT_EQ(n.counter(), 0u) << "an incremental encoder's zero is where it was switched on";
}

TEST(EncoderTerminal, StateFileKeepsThePositionAcrossARestart) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("ecsim-encoder-state-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  slavesim::EsiSlaveOptions options;
  options.stateFile = dir / "encoder.state";
  {
    EncoderNet n;
    n.seg.addSlave(makeEncoder(options));
    n.terminal()->setShaftAngle(1, angleFor(-12.125 * kCpr));
  }  // the simulator exits: the terminal writes its state file
  EncoderNet n;
  n.seg.addSlave(makeEncoder(options));
  n.toOp();
  EXPECT_EQ(n.counter(), asCounter(-12.125 * kCpr));
  std::filesystem::remove_all(dir);
}

// The scenario action `encoder-fault` on the encoder terminal of
// examples/topologies/encoder_line.xml: kinds, clearing, errors; the topology's shaft angle.
TEST(EncoderTerminal, EncoderFaultActionSetsAndClearsTheTerminalsFaults) {
  auto config = loadTopologyFile(std::filesystem::path(ECSIM_SOURCE_DIR) / "examples" /
                                 "topologies" / "encoder_line.xml");
  ASSERT_TRUE(config.ok()) << config.error().message();
  auto net = topology::buildNetwork(*config);
  ASSERT_TRUE(net.ok()) << net.error().message();
  topology::FaultInjector faults(*net, 1);
  auto index = faults.slaveIndex("Encoder1");
  ASSERT_TRUE(index.ok());
  slavesim::Slave& slave = net->segment->slave(*index);
  dev::SsiEncoderTerminal* t = dev::encoderTerminalOf(slave);
  ASSERT_NE(t, nullptr);
  net->segment->pollSlaves(kNsPerMs);
  EXPECT_EQ(*slavesim::objectDictionaryOf(slave)->get<std::uint32_t>(0x6000, 0x11), 327680u)
      << "2.5 turns (drive.initialShaftAngle in the topology)";
  auto apply = [&](const std::string& line) -> Result<std::string> {
    auto fault = topology::parseFaultLine(line);  // kind=noise is refused here
    if (!fault.ok()) return fault.takeError();
    return faults.apply(*fault, kNsPerMs);
  };
  ASSERT_TRUE(apply("encoder-fault slave=Encoder1").ok());
  EXPECT_EQ(t->fault(1), ef::kData) << "data is the default kind";
  ASSERT_TRUE(apply("encoder-fault slave=Encoder1 kind=frame").ok());
  EXPECT_EQ(t->fault(1), ef::kData | ef::kFrame);
  ASSERT_TRUE(apply("encoder-fault slave=Encoder1 kind=data on=0").ok());
  EXPECT_EQ(t->fault(1), ef::kFrame);
  EXPECT_FALSE(apply("encoder-fault slave=Encoder1 kind=noise").ok());
  EXPECT_FALSE(apply("encoder-fault slave=Encoder1 channel=2").ok()) << "one channel";
  EXPECT_FALSE(apply("encoder-fault slave=DO1").ok()) << "neither encoder nor drive";
  ASSERT_TRUE(apply("power-cycle slave=Encoder1").ok());
  t = dev::encoderTerminalOf(slave);
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->fault(1), ef::kFrame) << "the fault is outside the terminal";
  ASSERT_TRUE(apply("input slave=Encoder1 channel=1 signal=-1").ok()) << "the shaft, in turns";
  net->segment->pollSlaves(2 * kNsPerMs);
  ASSERT_TRUE(apply("encoder-fault slave=Encoder1 kind=frame on=0").ok());
  net->segment->pollSlaves(3 * kNsPerMs);
  EXPECT_EQ(*slavesim::objectDictionaryOf(slave)->get<std::uint32_t>(0x6000, 0x11),
            asCounter(-kCpr));
}

// The real EJ5002 (two SSI channels): its ESI gives the dictionary, our model fills it.
TEST(EncoderTerminal, RealEj5002FromItsEsiGetsTheModelOnBothChannels) {
  const auto path = sharedDir() / "esi" / "Beckhoff_EJ5xxx.xml";
  ECSIM_REQUIRE_SHARED(path);
  auto file = loadEsiFile(path);
  ASSERT_TRUE(file.ok()) << file.error().message();
  const EsiDevice* device = nullptr;
  for (const auto& d : file->devices) {
    if (d.productCode == 0x138A2852 && d.revision == 0x00110000) device = &d;
  }
  ASSERT_NE(device, nullptr) << "EJ5002 revision 0x00110000";
  auto slave = slavesim::makeSlaveFromEsi(*file, *device, "EJ5002");
  ASSERT_TRUE(slave.ok()) << slave.error().message();
  dev::SsiEncoderTerminal* t = dev::encoderTerminalOf(**slave);
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->channels(), 2u);
  t->setShaftAngle(2, 0.25 * kTurn);
  t->setFault(1, ef::kFrame);
  (*slave)->poll(kNsPerMs);
  const auto* od = slavesim::objectDictionaryOf(**slave);
  EXPECT_EQ(*od->get<std::uint8_t>(0x6000, 0x02), 1u) << "channel 1 frame error";
  EXPECT_EQ(*od->get<std::uint8_t>(0x6000, 0x0F), 1u) << "channel 1 TxPDO State";
  EXPECT_EQ(*od->get<std::uint8_t>(0x6010, 0x02), 0u);
  EXPECT_EQ(*od->get<std::uint8_t>(0x6010, 0x0F), 0u);
  EXPECT_EQ(*od->get<std::uint32_t>(0x6010, 0x11), 32768u);
}

}  // namespace
}  // namespace ecsim::testing
