// The scan against simulated slaves: slave count, station addresses, ESC registers, SII read
// through the EEPROM interface (4- and 8-byte reads) and parsed, names, topology.
#include "master/scan.hpp"

#include <gtest/gtest.h>

#include "master/state_change.hpp"
#include "tests/master/bring_up.hpp"
#include "tests/master/sim_network.hpp"
#include "tests/master/test_slaves.hpp"

namespace ecsim::testing {
namespace {

using master::ScanTask;
using master::SlaveInfo;
using master::Transport;

struct Scanned {
  Status status;
  std::vector<SlaveInfo> slaves;
};

Scanned scan(SimNetwork& net, master::ScanOptions options = {}) {
  Transport transport(net.masterLink());
  Scanned out;
  ScanTask task(transport, out.slaves, options);
  task.start(net.clock().now());
  auto run = master::runTask(task, transport, net.bus(), 10 * kNsPerSecond, "scan");
  out.status = run.ok() ? task.status() : run;
  return out;
}

// Issue 18: 1000 ET1100 generic slaves in a line, 1000 ns per passage out and back: the count
// frame's round trip is above SOEM's and our default 2 ms. The scan raises the timeout to
// twice the measured round trip plus a full frame's extra wire time (1454 bytes at 80 ns)
// before its per-slave frames go out; without adaptTimeout it only advises.
TEST(ScanTest, RaisesTheFrameTimeoutToWhatTheCountedLineNeeds) {
  for (const bool adapt : {true, false}) {
    SimNetwork net;
    for (std::uint32_t i = 0; i < 1000; ++i) {
      net.segment().addSlave(slavesim::makeGenericSlave("S" + std::to_string(i + 1), i + 1));
    }
    net.segment().wireLine();
    net.start();
    Transport transport(net.masterLink());
    ASSERT_EQ(transport.options().timeout, 2 * kNsPerMs);
    std::vector<SlaveInfo> slaves;
    master::ScanOptions options;
    options.adaptTimeout = adapt;
    options.adaptFramesInFlight = adapt;
    options.readSii = false;
    ScanTask task(transport, slaves, options);
    task.start(net.clock().now());
    ASSERT_TRUE(master::runTask(task, transport, net.bus(), 10 * kNsPerSecond).ok());
    ASSERT_TRUE(task.status().ok()) << task.status().error().message();
    ASSERT_TRUE(task.timeoutAdvice().has_value());
    const auto& advice = *task.timeoutAdvice();
    EXPECT_EQ(advice.slaves, 1000u);
    EXPECT_GT(advice.roundTrip, 2 * kNsPerMs);
    EXPECT_LT(advice.roundTrip, 3 * kNsPerMs);
    EXPECT_EQ(advice.needed, 2 * (advice.roundTrip + 1454 * 80));
    EXPECT_EQ(advice.before, 2 * kNsPerMs);
    EXPECT_EQ(advice.raised, adapt);
    EXPECT_EQ(transport.options().timeout, adapt ? advice.needed : 2 * kNsPerMs);
    // The round trip of over 2 ms holds 17 full frames (1514 bytes at 80 ns: 121.12 us each),
    // more than the 16 in flight by default.
    EXPECT_EQ(advice.framesFitting,
              static_cast<std::size_t>((advice.roundTrip + 1514 * 80 - 1) / (1514 * 80)));
    EXPECT_EQ(advice.framesFitting, 17u);
    EXPECT_EQ(advice.framesBefore, 16u);
    EXPECT_EQ(advice.framesRaised, adapt);
    EXPECT_EQ(transport.options().maxFramesInFlight, adapt ? 17u : 16u);
  }
}

// The scan's own timeout is meant for a network whose frames fit the default frame timeout:
// for a longer one it grows by the factor the needed frame timeout exceeds the default (a
// 65,535-slave line's SII alone takes minutes of bus time with 2 x 131 ms frame timeouts).
TEST(ScanTest, ItsOwnTimeoutGrowsWithTheFrameTimeoutTheLineNeeds) {
  for (const std::size_t n : {4u, 1000u}) {
    SimNetwork net;
    for (std::uint32_t i = 0; i < n; ++i) {
      net.segment().addSlave(slavesim::makeGenericSlave("S" + std::to_string(i + 1), i + 1));
    }
    net.segment().wireLine();
    net.start();
    Transport transport(net.masterLink());
    std::vector<SlaveInfo> slaves;
    master::ScanOptions options;
    options.readSii = false;
    ScanTask task(transport, slaves, options);
    EXPECT_EQ(task.timeoutScale(), 1.0);
    task.start(net.clock().now());
    ASSERT_TRUE(master::runTask(task, transport, net.bus(), 10 * kNsPerSecond).ok());
    const auto& advice = *task.timeoutAdvice();
    if (n == 4) {
      EXPECT_EQ(task.timeoutScale(), 1.0);
    } else {
      EXPECT_DOUBLE_EQ(task.timeoutScale(),
                       static_cast<double>(advice.needed) / static_cast<double>(2 * kNsPerMs));
      EXPECT_GT(task.timeoutScale(), 2.0);
    }
  }
}

// The reset asks every slave for its Explicit Device ID (AL control bit 5, ETG.1020 §22.2.2):
// Drive1 has one, AI1 none (its firmware reads AL control and shows nothing), a generic slave
// is an ESC in device emulation (it copies the request with the reset's error flag: no ID),
// and Drive2's firmware does not run (EEPROM checksum error: nothing reads AL control, 0x0220
// bit 0 stays set), which the scan waits for at most ScanOptions::identifyWait.
TEST(ScanTest, AsksForExplicitDeviceIdsAndWaitsBoundedForFirmwareThatNeverLooks) {
  SimTime took[2]{};
  for (const SimTime wait : {SimTime{100 * kNsPerMs}, SimTime{0}}) {
    SimNetwork net;
    net.segment().addSlave(makeDemoSlave(0x7201, "Drive1"));
    net.segment().addSlave(makeDemoSlave(0x3102, "AI1"));
    net.segment().addSlave(slavesim::makeGenericSlave("G", 1));
    net.segment().addSlave(makeDemoSlave(0x7201, "Drive2"));
    net.segment().wireLine();
    net.segment().slave(0).profile().explicitDeviceId = 7;
    auto& silent = net.segment().slave(3);
    constexpr std::size_t kChecksumByte = 14;  // SII word 7, low byte
    silent.esc().writeSiiByte(kChecksumByte,
                              static_cast<std::uint8_t>(silent.esc().sii()[kChecksumByte] ^ 1));
    net.start();
    silent.powerOff();  // on again with the broken EEPROM
    silent.powerOn(net.clock().now());
    ASSERT_FALSE(silent.firmwareRunning());
    ASSERT_FALSE(net.segment().slave(1).esc().deviceEmulation());
    ASSERT_TRUE(net.segment().slave(2).esc().deviceEmulation());
    const SimTime before = net.clock().now();
    master::ScanOptions options;
    options.identifyWait = wait;
    auto s = scan(net, options);
    ASSERT_TRUE(s.status.ok()) << s.status.error().message();
    took[wait == 0 ? 1 : 0] = net.clock().now() - before;
    EXPECT_EQ(s.slaves[0].deviceId, std::optional<std::uint16_t>(7));
    EXPECT_EQ(s.slaves[0].alStatusCode, 0) << "0x0134 held the ID, not an error";
    for (std::size_t i : {1, 2, 3}) EXPECT_FALSE(s.slaves[i].deviceId) << i;
  }
  EXPECT_GE(took[0] - took[1], 95 * kNsPerMs) << took[0] << " vs " << took[1];
  EXPECT_LE(took[0] - took[1], 105 * kNsPerMs) << took[0] << " vs " << took[1];
}

TEST(ScanTest, LeavesTheTimeoutOfAShortLineAlone) {
  SimNetwork net;
  for (std::uint32_t i = 0; i < 4; ++i) {
    net.segment().addSlave(slavesim::makeGenericSlave("S" + std::to_string(i + 1), i + 1));
  }
  net.segment().wireLine();
  net.start();
  Transport transport(net.masterLink());
  std::vector<SlaveInfo> slaves;
  ScanTask task(transport, slaves);
  task.start(net.clock().now());
  ASSERT_TRUE(master::runTask(task, transport, net.bus(), 10 * kNsPerSecond).ok());
  ASSERT_TRUE(task.timeoutAdvice().has_value());
  EXPECT_FALSE(task.timeoutAdvice()->raised);
  EXPECT_LT(task.timeoutAdvice()->needed, 2 * kNsPerMs);
  EXPECT_EQ(transport.options().timeout, 2 * kNsPerMs);
  EXPECT_FALSE(task.timeoutAdvice()->framesRaised);
  EXPECT_EQ(transport.options().maxFramesInFlight, 16u);
}

TEST(ScanTest, FindsGenericSlavesWithIdentityNamesAndAddresses) {
  SimNetwork net;
  for (std::uint32_t i = 0; i < 4; ++i) {
    net.segment().addSlave(slavesim::makeGenericSlave("Slave" + std::to_string(i + 1), 100 + i));
  }
  net.segment().wireLine();
  net.start();
  auto result = scan(net);
  ASSERT_TRUE(result.status.ok()) << result.status.error().message();
  ASSERT_EQ(result.slaves.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    const SlaveInfo& s = result.slaves[i];
    EXPECT_EQ(s.position, i);
    EXPECT_EQ(s.station, 0x1001 + i);
    // The simulated ESC now answers to that address.
    EXPECT_EQ(net.segment().slave(i).esc().reg16(reg::kConfiguredStationAddress.address),
              0x1001 + i);
    EXPECT_EQ(s.name, "Slave" + std::to_string(i + 1));
    EXPECT_EQ(s.identity().vendorId, slavesim::kEcsimVendorId);
    EXPECT_EQ(s.identity().productCode, slavesim::kGenericProductCode);
    EXPECT_EQ(s.identity().serial, 100 + i);
    EXPECT_EQ(s.escType, slavesim::kEt1100.typeRegister);
    EXPECT_EQ(s.fmmuCount, 8);
    EXPECT_EQ(s.syncManagerCount, 8);
    EXPECT_TRUE(s.hasDc());
    EXPECT_EQ(s.state(), AlState::kInit);
    EXPECT_FALSE(s.mailbox.has_value());
    EXPECT_FALSE(s.siiDamage.has_value());
    // Line: each slave's parent is the one before it.
    EXPECT_EQ(s.parent, static_cast<int>(i) - 1);
    EXPECT_EQ(s.activePorts, i + 1 < 4 ? 0x03 : 0x01);
    // The SII bytes read are the slave's EEPROM up to the END category.
    const auto& eeprom = net.segment().slave(i).esc().sii();
    ASSERT_LE(s.sii.size(), eeprom.size());
    EXPECT_TRUE(std::equal(s.sii.begin(), s.sii.end(), eeprom.begin()));
  }
}

TEST(ScanTest, NothingConnectedSaysNoSlavesFound) {
  SimNetwork net;
  net.start();  // an empty segment answers nothing, as an unplugged port
  auto result = scan(net);
  ASSERT_FALSE(result.status.ok());
  EXPECT_EQ(result.status.error().code, ErrorCode::kTimeout);
  EXPECT_NE(result.status.error().context.find("no slaves found"), std::string::npos)
      << result.status.error().context;
  EXPECT_TRUE(result.slaves.empty());
}

TEST(ScanTest, SiiCategoriesParsedWithFourAndEightByteReads) {
  SimNetwork net;
  const SiiContents io = ioSii("IO4", 0x2004, 4, 2, 77);
  slavesim::EscType fourBytes = slavesim::kEt1100;
  fourBytes.siiRead8Bytes = false;
  slavesim::EscType eightBytes = slavesim::kEt1100;
  eightBytes.siiRead8Bytes = true;
  net.segment().addSlave(makeSiiSlave("IO4", io, {}, fourBytes));
  net.segment().addSlave(makeSiiSlave("IO4b", io, {}, eightBytes));
  net.segment().wireLine();
  net.start();
  auto result = scan(net);
  ASSERT_TRUE(result.status.ok()) << result.status.error().message();
  ASSERT_EQ(result.slaves.size(), 2u);
  EXPECT_FALSE(result.slaves[0].siiReads8Bytes);
  EXPECT_TRUE(result.slaves[1].siiReads8Bytes);
  for (const auto& s : result.slaves) {
    EXPECT_EQ(s.name, "IO4");
    const SiiContents& c = s.siiContents;
    EXPECT_EQ(c.identity, io.identity);
    EXPECT_EQ(c.strings, io.strings);
    EXPECT_EQ(c.general, io.general);
    EXPECT_EQ(c.fmmus, io.fmmus);
    EXPECT_EQ(c.syncManagers, io.syncManagers);
    EXPECT_EQ(c.rxPdos, io.rxPdos);
    EXPECT_EQ(c.txPdos, io.txPdos);
  }
}

TEST(ScanTest, MailboxFromSiiHeaderAndSmCategory) {
  SimNetwork net;
  SiiContents c = ioSii("Mbx", 0x3000, 0, 1);
  c.standardMailbox = {0x1800, 128, 0x1880, 64};
  c.mailboxProtocols = SiiMailboxProtocol::kCoe | SiiMailboxProtocol::kFoe;
  c.syncManagers.insert(c.syncManagers.begin(),
                        {{0x1800, 128, 0x26, 0, 1, SiiSyncManagerType::kMailboxOut},
                         {0x1880, 64, 0x22, 0, 1, SiiSyncManagerType::kMailboxIn}});
  net.segment().addSlave(makeSiiSlave("Mbx", c));
  net.segment().wireLine();
  net.start();
  auto result = scan(net);
  ASSERT_TRUE(result.status.ok()) << result.status.error().message();
  const auto& s = result.slaves.at(0);
  ASSERT_TRUE(s.mailbox.has_value());
  EXPECT_EQ(s.mailbox->outStart, 0x1800);
  EXPECT_EQ(s.mailbox->outSize, 128);
  EXPECT_EQ(s.mailbox->inStart, 0x1880);
  EXPECT_EQ(s.mailbox->inSize, 64);
  EXPECT_EQ(s.mailbox->outControl, 0x26);
  EXPECT_EQ(s.mailbox->inControl, 0x22);
  EXPECT_TRUE(s.hasCoe());
}

TEST(ScanTest, TreeTopologyFromDlStatus) {
  // A junction with a branch on port 3 (visited first) and the line continuing on port 1.
  SimNetwork net;
  for (int i = 0; i < 4; ++i) {
    net.segment().addSlave(slavesim::makeGenericSlave("S" + std::to_string(i), 0));
  }
  ASSERT_TRUE(net.segment().connect(0, 3, 1, 0).ok());
  ASSERT_TRUE(net.segment().connect(0, 1, 2, 0).ok());
  ASSERT_TRUE(net.segment().connect(2, 1, 3, 0).ok());
  net.segment().refreshLinkStatus();
  net.start();
  auto result = scan(net);
  ASSERT_TRUE(result.status.ok()) << result.status.error().message();
  ASSERT_EQ(result.slaves.size(), 4u);
  EXPECT_EQ(result.slaves[0].activePorts, 0x0B);  // ports 0, 1, 3
  EXPECT_EQ(result.slaves[0].parent, -1);
  EXPECT_EQ(result.slaves[1].parent, 0);
  EXPECT_EQ(result.slaves[2].parent, 0);
  EXPECT_EQ(result.slaves[3].parent, 2);
  EXPECT_EQ(result.slaves[1].name, "S1");
}

TEST(ScanTest, SiiReadErrorsNameTheSlave) {
  SimNetwork net;
  net.segment().addSlave(slavesim::makeGenericSlave("A", 1));
  net.segment().wireLine();
  net.start();
  // Every frame after the register reads is lost: the SII read, sent again for its busy
  // timeout (20 ms: 4 times 3 tries of 2 ms), times out and says where.
  for (std::uint64_t n = 5; n < 100; ++n) net.fault().dropSend.insert(n);
  auto result = scan(net);
  ASSERT_FALSE(result.status.ok());
  EXPECT_EQ(result.status.error().code, ErrorCode::kTimeout);
  EXPECT_NE(result.status.error().context.find("slave 0 (0x1001)"), std::string::npos)
      << result.status.error().context;
  EXPECT_NE(result.status.error().context.find("SII read of word 0x0000"), std::string::npos)
      << result.status.error().context;
}

TEST(ScanTest, ScanWithoutResetLeavesTheStatesAlone) {
  SimNetwork net;
  for (int i = 0; i < 2; ++i) net.segment().addSlave(slavesim::makeGenericSlave("G", 0));
  net.segment().wireLine();
  net.start();
  Transport transport(net.masterLink());
  std::vector<SlaveInfo> slaves;
  master::ScanTask first(transport, slaves);
  first.start(0);
  ASSERT_TRUE(master::runTask(first, transport, net.bus(), kNsPerSecond).ok());
  master::StateChangeTask preop(transport, slaves);
  preop.start(AlState::kPreOp, net.clock().now());
  ASSERT_TRUE(master::runTask(preop, transport, net.bus(), kNsPerSecond).ok());
  ASSERT_TRUE(preop.status().ok());

  master::ScanOptions look;
  look.resetToDefaults = false;
  auto again = scan(net, look);
  ASSERT_TRUE(again.status.ok()) << again.status.error().message();
  EXPECT_EQ(again.slaves[1].state(), AlState::kPreOp);
  EXPECT_EQ(again.slaves[1].name, "G");
  EXPECT_EQ(net.segment().slave(1).state(), AlState::kPreOp);
  // A start-up scan resets them.
  auto reset = scan(net);
  ASSERT_TRUE(reset.status.ok());
  EXPECT_EQ(net.segment().slave(1).state(), AlState::kInit);
}

}  // namespace
}  // namespace ecsim::testing
