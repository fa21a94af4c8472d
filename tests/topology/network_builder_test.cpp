// A network built from a topology file: wiring, delays, clocks and cable names as written.
#include "topology/network_builder.hpp"

#include <gtest/gtest.h>

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
  auto zero = parseTopology("<Topology>\n<Slave name=\"E\" eeprom=\"/dev/zero\"/>\n</Topology>",
                            "t.xml");
  ASSERT_TRUE(zero.ok()) << zero.error().message();
  auto net = topology::buildNetwork(*zero);
  ASSERT_FALSE(net.ok());
  EXPECT_NE(net.error().context.find("/dev/zero: is a character device, not a regular file"),
            std::string::npos)
      << net.error().context;

  const auto fifo = std::filesystem::temp_directory_path() /
                    ("ecsim-eeprom-fifo-" + std::to_string(::getpid()) + ".bin");
  ASSERT_TRUE(makeFifo(fifo));
  auto cfg = parseTopology("<Topology>\n<Slave name=\"E\" eeprom=\"" + fifo.string() +
                               "\"/>\n</Topology>",
                           "t.xml");
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
