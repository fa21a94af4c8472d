// A network built from a topology file: wiring, delays, clocks and cable names as written.
#include "topology/network_builder.hpp"

#include <gtest/gtest.h>

#include "slavesim/esi_slave.hpp"
#include "slavesim/soe/soe_server.hpp"
#include "support/fifo.hpp"
#include "support/test_network.hpp"

namespace ecsim::testing {
namespace {

TEST(NetworkBuilder, ExampleTreeIsWiredAsWritten) {
  auto cfg = loadTopologyFile(std::filesystem::path(ECSIM_SOURCE_DIR) /
                              "examples/topologies/tree-generic.xml");
  ASSERT_TRUE(cfg.ok()) << cfg.error().message();
  auto net = topology::buildNetwork(*cfg);
  ASSERT_TRUE(net.ok()) << net.error().message();
  auto& seg = *net->segment;
  ASSERT_EQ(seg.size(), 4u);
  // Processing order: Junction, then branch A behind port 3 (A1, A2), then branch B (port 1).
  for (std::uint16_t pos = 0; pos < 4; ++pos) {
    one(seg, Command::kApwr, phys(static_cast<std::uint16_t>(-pos), 0x0010),
        le16(static_cast<std::uint16_t>(0x2000 + pos)));
  }
  EXPECT_EQ(seg.slave(1).esc().reg16(0x0010), 0x2001) << "A1";
  EXPECT_EQ(seg.slave(2).esc().reg16(0x0010), 0x2002) << "A2";
  EXPECT_EQ(seg.slave(3).esc().reg16(0x0010), 0x2003) << "B1";
  ASSERT_NE(net->findCable("branchB"), nullptr);
  EXPECT_EQ(net->findCable("branchB")->slave, 3u);
  EXPECT_NE(net->findCable("A1:1-A2:0"), nullptr) << "unnamed links get SLAVE:PORT-SLAVE:PORT";
  EXPECT_NE(net->findCable("master"), nullptr);
  EXPECT_NEAR(seg.slave(2).esc().dcClock().ratePpm(), 35.0, 1e-9);
  EXPECT_EQ(seg.slave(2).esc().dcClock().localTime(0), 250000);
  EXPECT_EQ(seg.ports(0)[1].cableMetres, 20.0);
}

TEST(NetworkBuilder, UnknownEscTypeNamesTheSlave) {
  auto cfg = parseTopology("<Topology>\n<Slave name=\"X\" esc=\"ET9999\"/>\n</Topology>", "t.xml");
  ASSERT_TRUE(cfg.ok());
  auto net = topology::buildNetwork(*cfg);
  ASSERT_FALSE(net.ok());
  EXPECT_NE(net.error().context.find("slave 'X'"), std::string::npos) << net.error().context;
  EXPECT_NE(net.error().context.find("ET9999"), std::string::npos);
}

// alias= is written into the EEPROM (word 4, checksum renewed) and loaded into 0x0012;
// deviceId= is the ID the firmware shows for an ID request (AL control bit 5).
TEST(NetworkBuilder, AliasAndExplicitDeviceIdReachTheDevice) {
  // A: a drive with firmware (a generic slave runs in device emulation and is refused a
  // deviceId: AnEk1101ShowsItsIdSwitchAtItsIdentificationAdo).
  auto cfg = parseTopology("<Topology>\n<Slave name=\"A\" esi=\"" + std::string(ECSIM_SOURCE_DIR) +
                               "/examples/esi/ecsim_devices.xml\" product=\"#x00007201\" "
                               "alias=\"0x0203\" deviceId=\"12\"/>\n<Slave name=\"B\"/>\n"
                               "</Topology>",
                           "t.xml");
  ASSERT_TRUE(cfg.ok()) << cfg.error().message();
  auto net = topology::buildNetwork(*cfg);
  ASSERT_TRUE(net.ok()) << net.error().message();
  auto& seg = *net->segment;
  EXPECT_EQ(readLe16(one(seg, Command::kAprd, phys(0, 0x0012), {0, 0}).data, 0), 0x0203);
  EXPECT_EQ(readLe16(seg.slave(0).esc().sii(), 8), 0x0203);
  EXPECT_EQ(seg.slave(0).esc().sii()[14], siiChecksum(seg.slave(0).esc().sii()));
  EXPECT_EQ(seg.slave(0).profile().explicitDeviceId, std::optional<std::uint16_t>(12));
  EXPECT_EQ(seg.slave(1).esc().reg16(0x0012), 0);
  EXPECT_FALSE(seg.slave(1).profile().explicitDeviceId);
  auto wide =
      parseTopology("<Topology>\n<Slave name=\"A\" deviceId=\"70000\"/>\n</Topology>", "t.xml");
  ASSERT_FALSE(wide.ok());
  EXPECT_NE(wide.error().message().find("line 2"), std::string::npos) << wide.error().message();
}

// An EK1101 (../shared/esi/Beckhoff_EK11xx.xml line 268: Info/IdentificationAdo #x1000, no
// IdentificationReg134; ConfigData 0401...: a digital I/O PDI, device emulation, no
// microcontroller) keeps its ID switch where its ESI says a master reads it: at 0x1000, in any
// state and after a power cycle, and in its input PDO entry "ID" (0x6000:01, TxPDO 0x1A00 of
// the input SM at 0x1000). It has no firmware to answer in 0x0134. An EK1100 (no ID switch,
// no IdentificationAdo) given a deviceId is refused: it would show nowhere.
TEST(NetworkBuilder, AnEk1101ShowsItsIdSwitchAtItsIdentificationAdo) {
  const auto esi = sharedDir() / "esi" / "Beckhoff_EK11xx.xml";
  ECSIM_REQUIRE_SHARED(esi);
  auto topology = [&](const std::string& product) {
    return parseTopology("<Topology>\n<Slave name=\"EK\" esi=\"" + esi.string() + "\" product=\"" +
                             product + "\" deviceId=\"7\"/>\n</Topology>",
                         "t.xml");
  };
  auto cfg = topology("#x044d2c52");
  ASSERT_TRUE(cfg.ok()) << cfg.error().message();
  auto net = topology::buildNetwork(*cfg);
  ASSERT_TRUE(net.ok()) << net.error().message();
  auto& seg = *net->segment;
  seg.pollSlaves(0);
  auto id = [&] { return readLe16(one(seg, Command::kAprd, phys(0, 0x1000), {0, 0}).data, 0); };
  EXPECT_EQ(id(), 7);
  EXPECT_FALSE(seg.slave(0).profile().explicitDeviceId);
  const auto* od = slavesim::objectDictionaryOf(seg.slave(0));
  ASSERT_NE(od, nullptr);
  const auto* entry = od->findEntry(0x6000, 1);
  ASSERT_NE(entry, nullptr);
  EXPECT_EQ(readLe16(entry->value, 0), 7);
  seg.slave(0).powerOff();
  seg.slave(0).powerOn(0);
  EXPECT_EQ(id(), 7) << "after a power cycle";

  auto coupler = topology("#x044c2c52");
  ASSERT_TRUE(coupler.ok()) << coupler.error().message();
  auto refused = topology::buildNetwork(*coupler);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message().find("line 2, slave 'EK': deviceId on a device whose ESC "
                                           "runs in device emulation"),
            std::string::npos)
      << refused.error().message();
}

TEST(NetworkBuilder, PortBeyondTheEscIsRefused) {
  auto cfg = parseTopology(
      "<Topology>\n<Slave name=\"A\" esc=\"LAN9252\"/>\n<Slave name=\"B\"/>\n"
      "<Link from=\"A:3\" to=\"B:0\"/>\n</Topology>",
      "t.xml");
  ASSERT_TRUE(cfg.ok());
  auto net = topology::buildNetwork(*cfg);
  ASSERT_FALSE(net.ok());
  EXPECT_NE(net.error().context.find("line 4"), std::string::npos) << net.error().context;
}

// Issue #21 item 9: a configuration filled in by a program is checked as a file is.
TEST(NetworkBuilder, MoreSlavesThanTheAddressSpaceAreRefused) {
  TopologyConfig cfg;
  cfg.file = "big.xml";
  cfg.slaves.resize(65'536);
  for (auto& s : cfg.slaves) s.builtin = "generic";
  auto net = topology::buildNetwork(cfg);
  ASSERT_FALSE(net.ok());
  EXPECT_NE(net.error().context.find("65536 slaves, more than 65535"), std::string::npos)
      << net.error().context;
}

// An EEPROM image must be a regular file of at most 1 MiB: a device or a FIFO named there is
// refused with its path, not read without end or waited on.
TEST(NetworkBuilder, EepromImageThatIsNotARegularFileIsRefused) {
  auto zero =
      parseTopology("<Topology>\n<Slave name=\"E\" eeprom=\"/dev/zero\"/>\n</Topology>", "t.xml");
  ASSERT_TRUE(zero.ok()) << zero.error().message();
  auto net = topology::buildNetwork(*zero);
  ASSERT_FALSE(net.ok());
  EXPECT_NE(net.error().context.find("/dev/zero: is a character device, not a regular file"),
            std::string::npos)
      << net.error().context;

  const auto fifo = std::filesystem::temp_directory_path() /
                    ("ecsim-eeprom-fifo-" + std::to_string(::getpid()) + ".bin");
  ASSERT_TRUE(makeFifo(fifo));
  auto cfg = parseTopology(
      "<Topology>\n<Slave name=\"E\" eeprom=\"" + fifo.string() + "\"/>\n</Topology>", "t.xml");
  ASSERT_TRUE(cfg.ok()) << cfg.error().message();
  auto built = readWithoutHanging(fifo, [&] { return topology::buildNetwork(*cfg); });
  std::filesystem::remove(fifo);
  ASSERT_FALSE(built.ok());
  EXPECT_NE(built.error().context.find(fifo.string() + ": is a FIFO, not a regular file"),
            std::string::npos)
      << built.error().context;
}

}  // namespace
}  // namespace ecsim::testing

namespace ecsim::testing {
namespace {

// SoE drives (docs/devices.md#soe-drives): the topology names the EtherCATDict file with a
// drive's IDNs; the slave's mailbox gets an SoE server with them.
TEST(NetworkBuilder, SoeDriveServesTheDictionaryItsTopologyNames) {
  auto cfg = loadTopologyFile(std::filesystem::path(ECSIM_SOURCE_DIR) /
                              "examples/topologies/soe_drive.xml");
  ASSERT_TRUE(cfg.ok()) << cfg.error().message();
  auto net = topology::buildNetwork(*cfg);
  ASSERT_TRUE(net.ok()) << net.error().message();
  EXPECT_TRUE(net->warnings.empty()) << net->warnings.front();
  auto* coe = slavesim::coeServerOf(net->segment->slave(1));
  ASSERT_NE(coe, nullptr);
  auto* soe = dynamic_cast<slavesim::soe::SoeServer*>(coe->protocol(MailboxType::kSoe));
  ASSERT_NE(soe, nullptr);
  ASSERT_EQ(soe->driveCount(), 1u) << "<SoE ChannelCount=\"1\">";
  EXPECT_EQ(soe->drive(0).size(), 20u);
  ASSERT_NE(soe->drive(0).find(47), nullptr);
  EXPECT_EQ(soe->drive(0).find(47)->name, "Position command value");
  EXPECT_EQ(coe->protocol(MailboxType::kSoe), soe);
  EXPECT_EQ(slavesim::coeServerOf(net->segment->slave(0)), nullptr) << "the coupler has none";
}

TEST(NetworkBuilder, SoeDictionaryNeedsAnSoeDeviceAndAnEtherCatDictFile) {
  const auto file = std::filesystem::path(ECSIM_SOURCE_DIR) / "examples/topologies/t.xml";
  auto build = [&](const std::string& slave) {
    auto cfg = parseTopology("<Topology>\n" + slave + "\n</Topology>", file);
    if (!cfg.ok()) return Result<topology::Network>(cfg.takeError());
    return topology::buildNetwork(*cfg);
  };
  auto coupler = build(
      "<Slave name=\"C\" esi=\"../esi/ecsim_devices.xml\" product=\"#x00001100\" "
      "soeDictionary=\"../esi/soe/ecs5101_dict.xml\"/>");
  ASSERT_FALSE(coupler.ok());
  EXPECT_NE(coupler.error().context.find("has no <SoE>"), std::string::npos)
      << coupler.error().context;
  auto notDict = build(
      "<Slave name=\"A\" esi=\"../esi/ecsim_soe_drive.xml\" product=\"#x00005101\" "
      "soeDictionary=\"../esi/ecsim_devices.xml\"/>");
  ASSERT_FALSE(notDict.ok());
  EXPECT_NE(notDict.error().context.find("is no EtherCATDict file"), std::string::npos)
      << notDict.error().context;
  auto noEsi = build("<Slave name=\"G\" soeDictionary=\"../esi/soe/ecs5101_dict.xml\"/>");
  ASSERT_FALSE(noEsi.ok());
  EXPECT_NE(noEsi.error().context.find("line 2"), std::string::npos) << noEsi.error().context;
  // Without a dictionary the drive has the lists every drive derives, and a warning says so.
  auto bare =
      build("<Slave name=\"A\" esi=\"../esi/ecsim_soe_drive.xml\" product=\"#x00005101\"/>");
  ASSERT_TRUE(bare.ok()) << bare.error().message();
  ASSERT_EQ(bare->warnings.size(), 1u);
  EXPECT_NE(bare->warnings[0].find("no SoE dictionary"), std::string::npos) << bare->warnings[0];
}

}  // namespace
}  // namespace ecsim::testing
