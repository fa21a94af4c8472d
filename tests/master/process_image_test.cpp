// The process image layout, SM/FMMU settings and LRW datagram plan, computed from slave
// descriptions alone (no network): offsets, FMMUs, expected WKCs and the slaves behind them,
// splitting at the frame limit.
#include "master/process_image.hpp"

#include <gtest/gtest.h>

#include "tests/master/test_slaves.hpp"

namespace ecsim::testing {
namespace {

using master::LayoutOptions;
using master::SlaveInfo;
using master::SlaveProcessData;

SlaveInfo ioSlave(std::size_t position, std::uint16_t outBytes, std::uint16_t inWords,
                  std::uint8_t fmmus = 8) {
  SlaveInfo s;
  s.position = position;
  s.station = static_cast<std::uint16_t>(0x1001 + position);
  s.fmmuCount = fmmus;
  s.siiContents = ioSii("S" + std::to_string(position), 0x10, outBytes, inWords);
  s.name = "S" + std::to_string(position);
  return s;
}

struct Bus {
  std::vector<SlaveInfo> slaves;
  std::vector<SlaveProcessData> data;
  void add(SlaveInfo s) {
    data.push_back(master::processDataFromSii(s));
    slaves.push_back(std::move(s));
  }
};

TEST(ProcessImageTest, OutputsThenInputsByteAlignedPerSlave) {
  Bus bus;
  bus.add(ioSlave(0, 4, 2));  // 4 bytes out, 4 bytes in
  bus.add(ioSlave(1, 2, 0));  // out only
  bus.add(ioSlave(2, 0, 3));  // in only, 6 bytes
  auto layout = master::planProcessImage(bus.slaves, bus.data);
  ASSERT_TRUE(layout.ok()) << layout.error().message();
  EXPECT_EQ(layout->outputBytes, 6u);
  EXPECT_EQ(layout->inputBytes, 10u);
  const auto& a = layout->slaves[0];
  EXPECT_EQ(a.outputOffset, 0u);
  EXPECT_EQ(a.outputBytes, 4u);
  EXPECT_EQ(a.inputOffset, 6u);
  EXPECT_EQ(a.inputBytes, 4u);
  EXPECT_EQ(layout->slaves[1].outputOffset, 4u);
  EXPECT_EQ(layout->slaves[2].inputOffset, 10u);
  EXPECT_EQ(layout->slaves[2].inputBytes, 6u);
  // SMs from the SII (start, control), lengths from the mapping.
  ASSERT_EQ(a.sms.size(), 2u);
  EXPECT_EQ(a.sms[0].setting, master::syncManagerChannel(kIoOutputSm, 4, 0x64, true));
  EXPECT_EQ(a.sms[1].setting, master::syncManagerChannel(kIoInputSm, 4, 0x20, true));
  // An SM without data stays disabled.
  EXPECT_FALSE(layout->slaves[1].sms[1].setting.activate.enable);
  // FMMUs: outputs first.
  ASSERT_EQ(a.fmmus.size(), 2u);
  EXPECT_EQ(a.fmmus[0].logicalStart, 0u);
  EXPECT_EQ(a.fmmus[0].length, 4);
  EXPECT_EQ(a.fmmus[0].physicalStart, kIoOutputSm);
  EXPECT_TRUE(a.fmmus[0].write && !a.fmmus[0].read);
  EXPECT_EQ(a.fmmus[1].logicalStart, 6u);
  EXPECT_TRUE(a.fmmus[1].read && !a.fmmus[1].write);
  // One LRW over everything: WKC 3 + 2 + 1.
  ASSERT_EQ(layout->datagrams.size(), 1u);
  EXPECT_EQ(layout->datagrams[0].length, 16);
  EXPECT_EQ(layout->datagrams[0].expectedWkc, 6);
  EXPECT_EQ(layout->datagrams[0].slaves, (std::vector<std::size_t>{0, 1, 2}));
  EXPECT_EQ(layout->frameCount, 1u);
}

TEST(ProcessImageTest, LogicalBaseShiftsAddressesNotOffsets) {
  Bus bus;
  bus.add(ioSlave(0, 1, 1));
  LayoutOptions options;
  options.logicalBase = 0x00010000;
  auto layout = master::planProcessImage(bus.slaves, bus.data, options);
  ASSERT_TRUE(layout.ok());
  EXPECT_EQ(layout->slaves[0].fmmus[0].logicalStart, 0x00010000u);
  EXPECT_EQ(layout->slaves[0].fmmus[1].logicalStart, 0x00010001u);
  EXPECT_EQ(layout->datagrams[0].logicalStart, 0x00010000u);
  EXPECT_EQ(layout->slaves[0].inputOffset, 1u);
}

TEST(ProcessImageTest, DatagramsSplitAtAreaBoundariesWithTheirOwnWkc) {
  Bus bus;
  bus.add(ioSlave(0, 4, 2));
  bus.add(ioSlave(1, 2, 0));
  bus.add(ioSlave(2, 0, 3));
  LayoutOptions options;
  options.maxDatagramData = 8;
  auto layout = master::planProcessImage(bus.slaves, bus.data, options);
  ASSERT_TRUE(layout.ok());
  const auto& d = layout->datagrams;
  ASSERT_EQ(d.size(), 3u);
  // [0,6) outputs of 0 and 1; [6,10) inputs of 0; [10,16) inputs of 2.
  EXPECT_EQ(d[0].logicalStart, 0u);
  EXPECT_EQ(d[0].length, 6);
  EXPECT_EQ(d[0].expectedWkc, 4);
  EXPECT_EQ(d[0].slaves, (std::vector<std::size_t>{0, 1}));
  EXPECT_EQ(d[1].logicalStart, 6u);
  EXPECT_EQ(d[1].expectedWkc, 1);
  EXPECT_EQ(d[1].slaves, (std::vector<std::size_t>{0}));
  EXPECT_EQ(d[2].logicalStart, 10u);
  EXPECT_EQ(d[2].length, 6);
  EXPECT_EQ(d[2].slaves, (std::vector<std::size_t>{2}));
  EXPECT_EQ(layout->frameCount, 1u);  // small datagrams still share one frame
}

TEST(ProcessImageTest, LargeImageSplitsIntoFullFrames) {
  Bus bus;
  bus.add(ioSlave(0, 1000, 0));
  bus.add(ioSlave(1, 1000, 0));
  bus.add(ioSlave(2, 0, 500));  // 1000 bytes in
  auto layout = master::planProcessImage(bus.slaves, bus.data);
  ASSERT_TRUE(layout.ok());
  const auto& d = layout->datagrams;
  ASSERT_EQ(d.size(), 3u);  // one slave area each: two never fit one datagram
  for (const auto& dg : d) EXPECT_LE(dg.length, master::Transport::kMaxDatagramData);
  EXPECT_EQ(d[0].expectedWkc, 2);
  EXPECT_EQ(d[2].expectedWkc, 1);
  EXPECT_EQ(layout->frameCount, 3u);
  // An area larger than a datagram is cut inside.
  Bus big;
  big.add(ioSlave(0, 3000, 0));
  auto one = master::planProcessImage(big.slaves, big.data);
  ASSERT_TRUE(one.ok());
  ASSERT_EQ(one->datagrams.size(), 3u);
  EXPECT_EQ(one->datagrams[0].length, master::Transport::kMaxDatagramData);
  EXPECT_EQ(one->datagrams[2].length, 3000 - 2 * master::Transport::kMaxDatagramData);
  for (const auto& dg : one->datagrams) EXPECT_EQ(dg.expectedWkc, 2);
}

TEST(ProcessImageTest, TooFewFmmusIsAnErrorNamingTheSlave) {
  Bus bus;
  bus.add(ioSlave(0, 1, 1, 1));
  auto layout = master::planProcessImage(bus.slaves, bus.data);
  ASSERT_FALSE(layout.ok());
  EXPECT_NE(layout.error().context.find("slave 0 (0x1001 'S0'): needs 2 FMMUs, its ESC has 1"),
            std::string::npos)
      << layout.error().context;
}

TEST(ProcessImageTest, SmMissingFromTheSiiIsAnError) {
  Bus bus;
  bus.add(ioSlave(0, 1, 1));
  bus.data[0].sms.push_back({5, true, {}});
  auto layout = master::planProcessImage(bus.slaves, bus.data);
  ASSERT_FALSE(layout.ok());
  EXPECT_NE(layout.error().context.find("SM5"), std::string::npos);
}

TEST(ProcessImageTest, VariablesCarryPdoAndEntryNamesAndBitOffsets) {
  Bus bus;
  bus.add(ioSlave(0, 2, 1));
  auto layout = master::planProcessImage(bus.slaves, bus.data);
  ASSERT_TRUE(layout.ok());
  auto vars = master::processVariables(*layout);
  ASSERT_EQ(vars.size(), 3u);
  EXPECT_EQ(vars[0].bitOffset, 0u);
  EXPECT_EQ(vars[0].index, 0x7000);
  EXPECT_EQ(vars[0].subindex, 1);
  EXPECT_EQ(vars[0].pdoName, "Outputs");
  EXPECT_EQ(vars[0].entryName, "Out");
  EXPECT_EQ(vars[1].bitOffset, 8u);
  EXPECT_EQ(vars[2].bitOffset, 16u);
  EXPECT_FALSE(vars[2].output);
  EXPECT_EQ(vars[2].bitLength, 16);
}

TEST(ProcessImageTest, SetupBatchWritesSmsAndEveryFmmu) {
  Bus bus;
  bus.add(ioSlave(0, 2, 1, 3));
  auto layout = master::planProcessImage(bus.slaves, bus.data);
  ASSERT_TRUE(layout.ok());
  master::DatagramBatch batch;
  master::addProcessDataSetup(batch, *layout);
  ASSERT_EQ(batch.size(), 3u);  // SM0, SM1, FMMUs
  EXPECT_EQ(batch[0].ado(), reg::smChannel(0));
  EXPECT_EQ(batch[1].ado(), reg::smChannel(1));
  EXPECT_EQ(batch[2].ado(), reg::fmmuChannel(0));
  EXPECT_EQ(batch[2].length(), 3 * reg::kFmmuSize);  // the third, unused, is cleared
  EXPECT_EQ(batch[2].data()[reg::kFmmuSize + reg::fmmu::kType.address], reg::fmmu::kTypeRead);
  EXPECT_EQ(batch[2].data()[2 * reg::kFmmuSize + reg::fmmu::kActivate.address], 0);
}

}  // namespace
}  // namespace ecsim::testing
