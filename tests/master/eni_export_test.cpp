// eniFromMaster (what `ecmaster xml` writes): the demo network scanned and configured, written
// as ENI, read back by config/eni and used by a second master to bring the same network to OP
// (round trip); the wiring of a tree in PreviousPort.
#include "master/eni_export.hpp"

#include <gtest/gtest.h>

#include "tests/master/bring_up.hpp"
#include "tests/master/test_slaves.hpp"

namespace ecsim::testing {
namespace {

using master::Master;

void addDemoSlaves(topology::Segment& segment) {
  segment.addSlave(makeDemoSlave(0x1100, "Coupler"));
  segment.addSlave(makeDemoSlave(0x1008, "DI1"));
  segment.addSlave(makeDemoSlave(0x2008, "DO1"));
  segment.addSlave(makeDemoSlave(0x3102, "AI1"));
  segment.addSlave(makeDemoSlave(0x7201, "Drive1"));
  segment.addSlave(makeDemoSlave(0x7201, "Drive2"));
  segment.wireLine();
}

TEST(EniExportTest, ScannedDemoNetworkRoundTripsThroughEni) {
  std::string xml;
  master::ProcessImageLayout firstLayout;
  {
    SimNetwork net;
    addDemoSlaves(net.segment());
    net.start();
    Master m(net.masterLink(), net.bus());
    ASSERT_TRUE(m.scan().ok());
    ASSERT_TRUE(m.bringTo(AlState::kPreOp).ok());
    ASSERT_TRUE(m.configureProcessData().ok());
    firstLayout = m.layout();
    xml = formatEni(master::eniFromMaster(m));
  }
  auto eni = parseEni(xml, "scanned.xml");
  ASSERT_TRUE(eni.ok()) << eni.error().message() << "\n" << xml;
  ASSERT_EQ(eni->slaves.size(), 6u);
  const std::uint32_t products[] = {0x1100, 0x1008, 0x2008, 0x3102, 0x7201, 0x7201};
  for (std::size_t i = 0; i < 6; ++i) {
    const EniSlave& s = eni->slaves[i];
    EXPECT_EQ(s.vendorId, kTestVendor);
    EXPECT_EQ(s.productCode, products[i]);
    EXPECT_EQ(s.revisionNo, 0x00010000u);
    EXPECT_EQ(s.physAddr, 0x1001 + i);
    EXPECT_EQ(s.autoIncAddr, -static_cast<int>(i));
    if (i > 0) {
      ASSERT_NE(s.previousPort(), nullptr);
      EXPECT_EQ(s.previousPort()->physAddr, 0x1000 + i);
      EXPECT_EQ(s.previousPort()->port, 1u);
    }
  }
  // Mailboxes as the SII gives them; the drives ask for SYNC0.
  ASSERT_TRUE(eni->slaves[3].mailbox);
  EXPECT_EQ(eni->slaves[3].mailbox->sendStart, 0x1000);
  EXPECT_TRUE(eni->slaves[3].mailbox->has("CoE"));
  EXPECT_FALSE(eni->slaves[1].mailbox);
  EXPECT_TRUE(eni->slaves[4].dcCapable);
  EXPECT_FALSE(eni->slaves[1].dcCapable);
  // Process data: the drive's 13/15 bytes and its PDO entries with names and types.
  const EniSlave& drive = eni->slaves[4];
  ASSERT_EQ(drive.processData.send.size(), 1u);
  EXPECT_EQ(drive.processData.send[0].bitStart, firstLayout.slaves[4].outputOffset * 8);
  EXPECT_EQ(drive.processData.send[0].bitLength, 13u * 8u);
  EXPECT_EQ(drive.processData.recv[0].bitLength, 15u * 8u);
  ASSERT_FALSE(drive.processData.rxPdos.empty());
  EXPECT_EQ(drive.processData.rxPdos[0].entries.at(0).index, 0x6040);
  // Cyclic frames and image as the master laid them out.
  ASSERT_EQ(eni->cyclic.size(), 1u);
  const auto& cmds = eni->cyclic[0].frames.at(0).cmds;
  ASSERT_EQ(cmds.size(), firstLayout.datagrams.size());
  EXPECT_EQ(cmds[0].cmd, 12);
  EXPECT_EQ(cmds[0].dataLength, firstLayout.datagrams[0].length);
  EXPECT_EQ(cmds[0].cnt, firstLayout.datagrams[0].expectedWkc);
  EXPECT_EQ(cmds[0].outputOffs, 26u);  // 14 Ethernet + 2 EtherCAT + 10 datagram header
  EXPECT_EQ(eni->processImage.outputByteSize, firstLayout.outputBytes);
  EXPECT_EQ(eni->processImage.inputByteSize, firstLayout.inputBytes);
  ASSERT_FALSE(eni->processImage.inputs.empty());
  EXPECT_EQ(eni->processImage.inputs.back().bitOffs + eni->processImage.inputs.back().bitSize,
            firstLayout.size() * 8);

  // A second master configured from it brings the same network to OP.
  SimNetwork net;
  addDemoSlaves(net.segment());
  net.start();
  Master m(net.masterLink(), net.bus());
  m.setConfig(masterConfigFromEni(std::move(eni).value()));
  auto status = m.start();
  ASSERT_TRUE(status.ok()) << status.error().message();
  for (std::size_t i = 0; i < 6; ++i) EXPECT_EQ(net.segment().slave(i).state(), AlState::kOp);
  EXPECT_EQ(m.layout().outputBytes, firstLayout.outputBytes);
  EXPECT_EQ(m.layout().inputBytes, firstLayout.inputBytes);
  ASSERT_TRUE(m.stop().ok());
}

TEST(EniExportTest, TreeWiringIsWrittenAsPreviousPorts) {
  SimNetwork net;
  for (int i = 0; i < 4; ++i) {
    net.segment().addSlave(
        makeIoSlave("IO" + std::to_string(i), 0x50u + static_cast<unsigned>(i), 1, 1));
  }
  // Junction port 3 -> A1 -> A2, junction port 1 -> B1 (tests/interop/dc_tree.xml's shape).
  ASSERT_TRUE(net.segment().connect(0, 3, 1, 0).ok());
  ASSERT_TRUE(net.segment().connect(1, 1, 2, 0).ok());
  ASSERT_TRUE(net.segment().connect(0, 1, 3, 0).ok());
  net.start();
  Master m(net.masterLink(), net.bus());
  ASSERT_TRUE(m.scan().ok());
  EniConfig eni = master::eniFromMaster(m);
  ASSERT_EQ(eni.slaves.size(), 4u);
  EXPECT_EQ(eni.slaves[0].previousPort(), nullptr);
  ASSERT_NE(eni.slaves[1].previousPort(), nullptr);
  EXPECT_EQ(eni.slaves[1].previousPort()->physAddr, 0x1001);
  EXPECT_EQ(eni.slaves[1].previousPort()->port, 3u);
  EXPECT_EQ(eni.slaves[2].previousPort()->physAddr, 0x1002);
  EXPECT_EQ(eni.slaves[2].previousPort()->port, 1u);
  EXPECT_EQ(eni.slaves[3].previousPort()->physAddr, 0x1001);
  EXPECT_EQ(eni.slaves[3].previousPort()->port, 1u);
  EXPECT_TRUE(eni.cyclic.empty()) << "no process data configured yet";
}

}  // namespace
}  // namespace ecsim::testing
