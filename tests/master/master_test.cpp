// The master API end to end against the in-process simulator: start() on a mixed network
// (coupler, SII-only I/O, CoE I/O, ecsim's demo devices), identity check against a config
// file, a refusing slave, 1000 cycles with outputs reaching the simulated ESCs' SM buffers and
// inputs coming back, a large image over several frames, a lost frame, a WKC error naming the
// slave, stop().
#include "master/master.hpp"

#include <gtest/gtest.h>

#include <numeric>

#include "tests/master/bring_up.hpp"
#include "tests/master/test_slaves.hpp"

namespace ecsim::testing {
namespace {

using master::Master;

class MasterTest : public ::testing::Test {
 protected:
  void build() {
    net_.segment().wireLine();
    net_.start();
    master_ = std::make_unique<Master>(net_.masterLink(), net_.bus());
  }
  slavesim::Slave& sim(std::size_t i) { return net_.segment().slave(i); }

  SimNetwork net_;
  std::unique_ptr<Master> master_;
};

// Positions of the mixed network.
enum : std::size_t { kCoupler, kIo, kCoeIo, kDi, kDo, kAi, kDrive, kCount };

class MixedNetworkTest : public MasterTest {
 protected:
  void SetUp() override {
    net_.segment().addSlave(makeDemoSlave(0x1100, "Coupler"));
    net_.segment().addSlave(makeIoSlave("IO", 0x2004, 2, 1));
    net_.segment().addSlave(makeCoeIoSlave("CoeIO", 0x51, 2, 3));
    net_.segment().addSlave(makeDemoSlave(0x1008, "DI1"));
    net_.segment().addSlave(makeDemoSlave(0x2008, "DO1"));
    net_.segment().addSlave(makeDemoSlave(0x3102, "AI1"));
    net_.segment().addSlave(makeDemoSlave(0x7201, "Drive1"));
    build();
  }
};

TEST_F(MixedNetworkTest, StartBringsEverySlaveToOpWithTheRightImage) {
  auto status = master_->start();
  ASSERT_TRUE(status.ok()) << status.error().message();
  ASSERT_EQ(master_->slaves().size(), kCount);
  for (std::size_t i = 0; i < kCount; ++i) {
    EXPECT_EQ(sim(i).state(), AlState::kOp) << master_->slaves()[i].label();
    EXPECT_EQ(master_->slaves()[i].state(), AlState::kOp);
  }
  const auto& layout = master_->layout();
  // Outputs: IO 2, CoeIO 4, DO1 1, Drive1 13 (examples/README.md); inputs: IO 2, CoeIO 6,
  // DI1 1, AI1 8, Drive1 15.
  EXPECT_EQ(layout.outputBytes, 2u + 4u + 1u + 13u);
  EXPECT_EQ(layout.inputBytes, 2u + 6u + 1u + 8u + 15u);
  EXPECT_EQ(master_->processData()[kCoeIo].source, master::PdoSource::kCoe);
  EXPECT_EQ(master_->processData()[kIo].source, master::PdoSource::kSii);
  EXPECT_EQ(master_->processData()[kDi].source, master::PdoSource::kSii);
  EXPECT_EQ(layout.datagrams.size(), 1u);
  EXPECT_EQ(layout.datagrams[0].expectedWkc, 3 + 3 + 1 + 2 + 1 + 3);
  EXPECT_TRUE(master_->stop().ok());
  for (std::size_t i = 0; i < kCount; ++i) EXPECT_EQ(sim(i).state(), AlState::kInit);
}

TEST_F(MixedNetworkTest, ThousandCyclesCarryOutputsAndInputsWithoutWkcErrors) {
  ASSERT_TRUE(master_->start().ok());
  const auto& io = master_->layout().slaves[kIo];
  const auto& coe = master_->layout().slaves[kCoeIo];
  auto* od = slavesim::objectDictionaryOf(sim(kCoeIo));
  for (std::uint32_t cycle = 0; cycle < 1000; ++cycle) {
    const std::array<std::uint8_t, 2> out{static_cast<std::uint8_t>(cycle),
                                          static_cast<std::uint8_t>(cycle >> 8)};
    ASSERT_TRUE(master_->writeData(io.outputOffset, out).ok());
    std::array<std::uint8_t, 4> coeOut{};
    writeLe32(coeOut, 0, cycle * 3);
    ASSERT_TRUE(master_->writeData(coe.outputOffset, coeOut).ok());
    // The simulated devices produce inputs for this cycle.
    std::array<std::uint8_t, 2> in{static_cast<std::uint8_t>(~cycle), 0x5A};
    ASSERT_TRUE(sim(kIo).esc().pdiWriteInputs(1, in));
    if (od != nullptr) {
      ASSERT_TRUE(od->set<std::uint16_t>(0x6000, 2, static_cast<std::uint16_t>(cycle)).ok());
    }
    auto status = master_->exchange();
    ASSERT_TRUE(status.ok()) << "cycle " << cycle << ": " << status.error().message();
    // Outputs are in the ESC's SM buffer (SII I/O) and in the dictionary (CoE device).
    ConstBytes got = sim(kIo).esc().pdiOutputs(0);
    ASSERT_EQ(got.size(), 2u);
    EXPECT_EQ(got[0], out[0]);
    EXPECT_EQ(got[1], out[1]);
    // Inputs came back in the process image.
    std::array<std::uint8_t, 2> read{};
    ASSERT_TRUE(master_->readData(io.inputOffset, read).ok());
    EXPECT_EQ(read, in);
  }
  // The CoE device's firmware copied the last outputs into its objects and its inputs out.
  ASSERT_NE(od, nullptr);
  EXPECT_EQ(od->get<std::uint16_t>(0x7000, 1).valueOr(0), static_cast<std::uint16_t>(999 * 3));
  std::array<std::uint8_t, 6> coeIn{};
  ASSERT_TRUE(master_->readData(coe.inputOffset, coeIn).ok());
  EXPECT_GE(readLe16(coeIn, 2), 998);  // the device runs one firmware step behind the frame
  const auto& stats = master_->statistics();
  EXPECT_GE(stats.cycles, 1000u);
  EXPECT_EQ(stats.wkcErrors, 0u);
  EXPECT_EQ(stats.framesLost, 0u);
  EXPECT_GT(stats.roundTripMin, 0);
  EXPECT_LE(stats.roundTripMin, stats.roundTripMean());
  EXPECT_LE(stats.roundTripMean(), stats.roundTripMax);
}

TEST_F(MixedNetworkTest, IdentityMismatchNamesPositionAndWhatDiffers) {
  master::MasterConfig config;
  auto parsed = master::parseMasterConfig(R"(<?xml version="1.0"?>
<EcsimMaster>
  <Slave name="Coupler" vendor="#x00000E5C" product="#x00001100"/>
  <Slave name="IO" vendor="#x00000E5C" product="#x00002004"/>
  <Slave name="CoeIO" vendor="#x00000E5C" product="#x00000051"/>
  <Slave name="DO1" vendor="#x00000E5C" product="#x00002008"/>
  <Slave name="DO1" vendor="#x00000E5C" product="#x00002008"/>
  <Slave name="AI1" vendor="#x00000E5C" product="#x00003102" revision="#x00020000"/>
  <Slave name="Drive1" vendor="#x00000E5C" product="#x00007201"/>
</EcsimMaster>)",
                                          "bus.xml");
  ASSERT_TRUE(parsed.ok()) << parsed.error().message();
  master_->setConfig(*parsed);
  auto status = master_->start();
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().code, ErrorCode::kInvalidArgument);
  const std::string& text = status.error().context;
  EXPECT_NE(text.find("slave 3 (0x1004 '"), std::string::npos) << text;
  EXPECT_NE(text.find("configured as 'DO1', bus.xml line 6: product code 0x00001008 "
                      "(expected 0x00002008)"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("revision 0x00010000 (expected 0x00020000)"), std::string::npos) << text;
  EXPECT_EQ(text.find("slave 4"), std::string::npos) << text;
  // Nothing was configured: the slaves stay in INIT.
  EXPECT_EQ(sim(kDo).state(), AlState::kInit);
}

TEST_F(MasterTest, SlaveCountMismatchAndConfigErrors) {
  net_.segment().addSlave(slavesim::makeGenericSlave("A", 1));
  build();
  master::MasterConfig config;
  config.file = "two.xml";
  config.slaves = {{"A", slavesim::kEcsimVendorId, slavesim::kGenericProductCode, {}, {}, 2},
                   {"B", slavesim::kEcsimVendorId, slavesim::kGenericProductCode, {}, {}, 3}};
  master_->setConfig(config);
  auto status = master_->start();
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().context, "two.xml expects 2 slaves, the bus has 1");

  auto bad = master::parseMasterConfig("<EcsimMaster>\n  <Slave vendor=\"#x1\"/>\n</EcsimMaster>",
                                       "bad.xml");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().context, "bad.xml, line 2: <Slave> needs vendor and product");
  auto notNumber = master::parseMasterConfig(
      "<EcsimMaster><Slave vendor=\"x\" product=\"1\"/></EcsimMaster>", "n.xml");
  ASSERT_FALSE(notNumber.ok());
  EXPECT_NE(notNumber.error().context.find("attribute vendor"), std::string::npos);
  EXPECT_FALSE(master_->loadConfig("/nonexistent/bus.xml").ok());
}

TEST_F(MasterTest, RefusingSlaveStopsStartWithItsAlStatusCode) {
  net_.segment().addSlave(makeIoSlave("Good", 0x10, 1, 1));
  // The firmware expects 4 output bytes on SM0, the SII maps 2: PREOP->SAFEOP gets 0x001D.
  slavesim::SlaveProfile wrong;
  wrong.processData.push_back({0, true, 4});
  net_.segment().addSlave(makeSiiSlave("Bad", ioSii("Bad", 0x11, 2, 0), wrong));
  build();
  auto status = master_->start();
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().code, ErrorCode::kAborted);
  const std::string& text = status.error().context;
  EXPECT_NE(text.find("slave 1 (0x1002 'Bad') refused SAFEOP: AL status code 0x001D (" +
                      std::string(alStatusCodeText(0x001D)) + "), stays PREOP"),
            std::string::npos)
      << text;
  ASSERT_EQ(master_->lastRefusals().size(), 1u);
  EXPECT_EQ(master_->lastRefusals()[0].alStatusCode, 0x001D);
  EXPECT_EQ(sim(0).state(), AlState::kSafeOp);
}

TEST_F(MasterTest, LargeImageTravelsInSeveralFrames) {
  for (int i = 0; i < 3; ++i) {
    net_.segment().addSlave(makeIoSlave("Big" + std::to_string(i), 0x20, 1000, 0));
  }
  build();
  ASSERT_TRUE(master_->start().ok());
  EXPECT_EQ(master_->layout().frameCount, 3u);
  std::vector<std::uint8_t> out(3000);
  for (int cycle = 0; cycle < 50; ++cycle) {
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = static_cast<std::uint8_t>(i * 7 + cycle);
    ASSERT_TRUE(master_->writeData(0, out).ok());
    auto status = master_->exchange();
    ASSERT_TRUE(status.ok()) << status.error().message();
    for (std::size_t s = 0; s < 3; ++s) {
      ConstBytes got = sim(s).esc().pdiOutputs(0);
      ASSERT_EQ(got.size(), 1000u);
      EXPECT_TRUE(std::equal(got.begin(), got.end(), out.begin() + static_cast<long>(s * 1000)));
    }
  }
  for (std::size_t size : net_.fault().sentSizes) EXPECT_LE(size, kMaxFrameSize);
}

TEST_F(MasterTest, LostCyclicFrameIsDetectedAndCounted) {
  net_.segment().addSlave(makeIoSlave("IO", 0x10, 2, 2));
  build();
  ASSERT_TRUE(master_->start().ok());
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(master_->exchange().ok());
  net_.fault().dropSend = {net_.fault().sentCount() + 1};
  auto lost = master_->exchange();
  ASSERT_FALSE(lost.ok());
  EXPECT_EQ(lost.error().code, ErrorCode::kTimeout);
  EXPECT_EQ(master_->lastCycle().framesLost, 1u);
  EXPECT_EQ(master_->statistics().framesLost, 1u);
  EXPECT_EQ(master_->transport().counters().framesLost, 1u);
  EXPECT_EQ(master_->transport().counters().framesResent, 0u);  // cyclic: never resent
  ASSERT_TRUE(master_->exchange().ok());
}

TEST_F(MasterTest, WorkingCounterErrorNamesTheSlavesConcerned) {
  net_.segment().addSlave(makeIoSlave("A", 0x10, 1, 1));
  net_.segment().addSlave(makeIoSlave("B", 0x10, 1, 1));
  build();
  ASSERT_TRUE(master_->start().ok());
  ASSERT_TRUE(master_->exchange().ok());
  // Slave B loses its FMMUs: it no longer takes part in the LRW.
  std::vector<std::uint8_t> zero(2 * reg::kFmmuSize, 0);
  ASSERT_TRUE(master_->writeRegisters(1, reg::fmmuChannel(0), zero).ok());
  auto status = master_->exchange();
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().code, ErrorCode::kWorkingCounter);
  EXPECT_EQ(status.error().context,
            "LRW 0x00000000+6: working counter 3, expected 6; slaves concerned: slave 0 "
            "(0x1001 'A'), slave 1 (0x1002 'B')");
  EXPECT_EQ(master_->statistics().wkcErrors, 1u);
}

TEST_F(MasterTest, WriteAndReadDataCheckTheirRange) {
  net_.segment().addSlave(makeIoSlave("IO", 0x10, 2, 1));
  build();
  ASSERT_TRUE(master_->start().ok());
  std::array<std::uint8_t, 2> two{};
  EXPECT_TRUE(master_->writeData(0, two).ok());
  EXPECT_FALSE(master_->writeData(1, two).ok());  // runs into the inputs
  EXPECT_TRUE(master_->readData(2, two).ok());
  EXPECT_FALSE(master_->readData(3, two).ok());
}

TEST_F(MasterTest, SdoServicesThroughTheApi) {
  net_.segment().addSlave(makeCoeIoSlave("CoeIO", 0x51, 1, 1));
  build();
  ASSERT_TRUE(master_->scan().ok());
  ASSERT_TRUE(master_->bringTo(AlState::kPreOp).ok());
  auto vendor = master_->sdoUpload(0, 0x1018, 1);
  ASSERT_TRUE(vendor.ok()) << vendor.error().message();
  EXPECT_EQ(readLe32(*vendor, 0), kTestVendor);
  auto list = master_->readOdList(0);
  ASSERT_TRUE(list.ok());
  EXPECT_FALSE(list->indexes.empty());
  auto entry = master_->readEntryDescription(0, 0x1018, 2);
  ASSERT_TRUE(entry.ok());
  EXPECT_EQ(entry->bitLength, 32);
  auto missing = master_->sdoUpload(5, 0x1018, 1);
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().code, ErrorCode::kNotFound);
}

}  // namespace
}  // namespace ecsim::testing
