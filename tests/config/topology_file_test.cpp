// Topology files: slaves, devices, wiring, cables, clocks and inputs read into plain structs;
// every error names the file and the line (docs/topology.md).
#include "config/topology_file.hpp"

#include <gtest/gtest.h>

namespace ecsim {
namespace {

const std::filesystem::path kFile = "/some/dir/net.xml";

TEST(TopologyFile, LineWhenNoLinksAreGiven) {
  auto t = parseTopology(R"(<Topology name="line">
  <Slave name="A"/>
  <Slave name="B"/>
  <Slave name="C"/>
</Topology>)",
                         kFile);
  ASSERT_TRUE(t.ok()) << t.error().message();
  EXPECT_EQ(t->name, "line");
  ASSERT_EQ(t->slaves.size(), 3u);
  EXPECT_EQ(t->slaves[0].builtin, "generic");
  ASSERT_EQ(t->links.size(), 2u);
  EXPECT_EQ(t->links[1].fromSlave, 1u);
  EXPECT_EQ(t->links[1].fromPort, 1u);
  EXPECT_EQ(t->links[1].toSlave, 2u);
  EXPECT_EQ(t->links[1].toPort, 0u);
  EXPECT_EQ(t->links[1].name, "B:1-C:0");
  EXPECT_FALSE(t->explicitLinks);
}

TEST(TopologyFile, DevicesWiringClocksAndInputs) {
  auto t = parseTopology(R"(<Topology>
  <Master cable="2.5"/>
  <Slave name="J" esi="../esi/devices.xml" product="#x04622C52" esc="ET1100"
         processingDelayNs="320" forwardingDelayNs="280"/>
  <Slave name="DI" esi="../esi/devices.xml" product="0x03F03052" revision="#x00100000">
    <Clock offsetNs="-1500" driftPpm="42.5"/>
    <Input entry="#x6000:1" value="1"/>
  </Slave>
  <Slave name="Drive" device="generic" stateFile="drive.state"/>
  <Link name="c1" from="J:3" to="DI:0" cable="10"/>
  <Link from="J:1" to="Drive:0"/>
</Topology>)",
                         kFile);
  ASSERT_TRUE(t.ok()) << t.error().message();
  EXPECT_DOUBLE_EQ(t->masterCableMetres, 2.5);
  const auto& j = t->slaves[0];
  EXPECT_EQ(j.esiFile, std::filesystem::path("/some/dir/../esi/devices.xml"));
  EXPECT_EQ(j.productCode, 0x04622C52u);
  EXPECT_EQ(j.processingDelayNs, 320);
  EXPECT_EQ(j.forwardingDelayNs, 280);
  const auto& di = t->slaves[1];
  EXPECT_EQ(di.revision, 0x00100000u);
  EXPECT_EQ(di.clockOffsetNs, -1500);
  EXPECT_DOUBLE_EQ(di.driftPpm, 42.5);
  ASSERT_EQ(di.inputs.size(), 1u);
  EXPECT_EQ(di.inputs[0].index, 0x6000);
  EXPECT_EQ(di.inputs[0].subIndex, 1);
  EXPECT_EQ(di.inputs[0].value, 1);
  EXPECT_EQ(t->slaves[2].stateFile, std::filesystem::path("/some/dir/drive.state"));
  ASSERT_EQ(t->links.size(), 2u);
  EXPECT_EQ(t->links[0].name, "c1");
  EXPECT_EQ(t->links[0].fromPort, 3u);
  EXPECT_DOUBLE_EQ(t->links[0].cableMetres, 10.0);
  EXPECT_EQ(t->links[1].name, "J:1-Drive:0");
}

TEST(TopologyFile, ModulesOfAModularDevice) {
  auto t = parseTopology(R"(<Topology>
  <Slave name="Station" esi="Weidmueller_UR20_FBC.xml" product="#x4F911C30"
         modules="Weidmueller_UR20_IO.xml">
    <Module type="UR20-4DI-P"/>
    <Module ident="#x01012FA0"/>
  </Slave>
</Topology>)",
                         kFile);
  ASSERT_TRUE(t.ok()) << t.error().message();
  const TopologySlave& s = t->slaves.at(0);
  EXPECT_EQ(s.moduleFile, std::filesystem::path("/some/dir/Weidmueller_UR20_IO.xml"));
  ASSERT_EQ(s.modules.size(), 2u);
  EXPECT_EQ(s.modules[0].type, "UR20-4DI-P");
  EXPECT_FALSE(s.modules[0].ident.has_value());
  EXPECT_EQ(s.modules[1].ident, 0x01012FA0u);
  EXPECT_EQ(s.modules[1].line, 5);
}

struct BadCase {
  const char* xml;
  const char* expect;  // part of the message, including the line
};

class TopologyFileErrors : public ::testing::TestWithParam<BadCase> {};

TEST_P(TopologyFileErrors, NameFileAndLine) {
  auto t = parseTopology(GetParam().xml, kFile);
  ASSERT_FALSE(t.ok());
  EXPECT_NE(t.error().context.find("/some/dir/net.xml"), std::string::npos) << t.error().context;
  EXPECT_NE(t.error().context.find(GetParam().expect), std::string::npos) << t.error().context;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, TopologyFileErrors,
    ::testing::Values(
        BadCase{"<Topology>\n<Slave name=\"A\">\n</Topology>", "line 2"},
        BadCase{"<Network/>", "root element must be <Topology>"},
        BadCase{"<Topology>\n</Topology>", "no <Slave>"},
        BadCase{"<Topology>\n<Slave/>\n</Topology>", "line 2: Slave needs a name"},
        BadCase{"<Topology>\n<Slave name=\"A\"/>\n<Slave name=\"A\"/>\n</Topology>",
                "line 3: duplicate slave name"},
        BadCase{"<Topology>\n<Slave name=\"A\"/>\n<Link from=\"A:1\" to=\"B:0\"/>\n</Topology>",
                "line 3: unknown slave 'B'"},
        BadCase{"<Topology>\n<Slave name=\"A\"/>\n<Slave name=\"B\"/>\n<Link from=\"A:7\" "
                "to=\"B:0\"/>\n</Topology>",
                "line 4: from: port must be 0..3"},
        BadCase{"<Topology>\n<Slave name=\"A\" esi=\"x.xml\"/>\n</Topology>",
                "line 2: Slave 'A' names an ESI file but no product code"},
        BadCase{"<Topology>\n<Slave name=\"A\">\n<Clock driftPpm=\"fast\"/>\n</Slave>\n</Topology>",
                "line 3: attribute driftPpm"},
        BadCase{"<Topology>\n<Slave name=\"A\"/>\n<Slave name=\"B\"/>\n<Link from=\"A:1\" "
                "to=\"B:0\" cable=\"150\"/>\n</Topology>",
                "line 4: attribute cable: '150' is not a number in [0, 100] m"},
        // Issue #21: numbers outside their range, NaN and infinities were accepted.
        BadCase{"<Topology>\n<Master cable=\"1e300\"/>\n<Slave name=\"A\"/>\n</Topology>",
                "line 2: attribute cable: '1e300' is not a number in [0, 100]"},
        BadCase{"<Topology>\n<Master cable=\"-5\"/>\n<Slave name=\"A\"/>\n</Topology>",
                "line 2: attribute cable: '-5' is not a number in [0, 100]"},
        BadCase{"<Topology>\n<Master cable=\"2m\"/>\n<Slave name=\"A\"/>\n</Topology>",
                "line 2: attribute cable: '2m' is not a number"},
        BadCase{"<Topology>\n<Slave name=\"A\"/>\n<Slave name=\"B\"/>\n<Link from=\"A:1\" "
                "to=\"B:0\" cable=\"nan\"/>\n</Topology>",
                "line 4: attribute cable: 'nan' is not a number in [0, 100]"},
        BadCase{"<Topology>\n<Slave name=\"A\" processingDelayNs=\"9223372036854775807\"/>\n"
                "</Topology>",
                "line 2: attribute processingDelayNs: '9223372036854775807' is not a number in "
                "[0, 1000000]"},
        BadCase{"<Topology>\n<Slave name=\"A\" forwardingDelayNs=\"-100\"/>\n</Topology>",
                "line 2: attribute forwardingDelayNs: '-100' is not a number in [0, 1000000]"},
        BadCase{"<Topology>\n<Slave name=\"A\">\n<Clock offsetNs=\"9223372036854775807\"/>\n"
                "</Slave>\n</Topology>",
                "line 3: attribute offsetNs: '9223372036854775807' is not a number in "
                "[-4000000000000000000, 4000000000000000000]"},
        BadCase{"<Topology>\n<Slave name=\"A\">\n<Clock driftPpm=\"nan\"/>\n</Slave>\n"
                "</Topology>",
                "line 3: attribute driftPpm: 'nan' is not a number in [-1000, 1000] ppm"},
        BadCase{"<Topology>\n<Slave name=\"A\">\n<Clock driftPpm=\"-inf\"/>\n</Slave>\n"
                "</Topology>",
                "line 3: attribute driftPpm: '-inf' is not a number in [-1000, 1000]"},
        // Modules of a modular device: type or ident, strict attributes, ESI devices only.
        BadCase{"<Topology>\n<Slave name=\"A\" esi=\"h.xml\" product=\"1\">\n<Module/>\n"
                "</Slave>\n</Topology>",
                "line 3: Module needs either type"},
        BadCase{"<Topology>\n<Slave name=\"A\" esi=\"h.xml\" product=\"1\">\n"
                "<Module type=\"X\" idents=\"1\"/>\n</Slave>\n</Topology>",
                "line 3: unknown attribute 'idents' on <Module>; did you mean 'ident'?"},
        BadCase{"<Topology>\n<Slave name=\"A\">\n<Module type=\"X\"/>\n</Slave>\n</Topology>",
                "line 2: Slave 'A': modules need a device from an ESI file"}));

std::string slaves(std::size_t n) {
  std::string xml = "<Topology>\n";
  for (std::size_t i = 0; i < n; ++i) xml += "<Slave name=\"S" + std::to_string(i) + "\"/>\n";
  return xml + "</Topology>\n";
}

// Issue #21 item 9: a segment addresses at most 65,535 slaves.
TEST(TopologyFile, MoreSlavesThanTheAddressSpaceAreRefused) {
  auto most = parseTopology(slaves(65'535), kFile);
  ASSERT_TRUE(most.ok()) << most.error().message();
  EXPECT_EQ(most->slaves.size(), 65'535u);
  EXPECT_EQ(most->findSlave("S65534"), 65'534u);
  auto over = parseTopology(slaves(65'536), kFile);
  ASSERT_FALSE(over.ok());
  EXPECT_NE(over.error().context.find("line 65537: more than 65535 slaves"), std::string::npos)
      << over.error().context;
}

TEST(TopologyFile, MissingFileIsAClearError) {
  auto t = loadTopologyFile("/nonexistent/ecsim/topology.xml");
  ASSERT_FALSE(t.ok());
  EXPECT_NE(t.error().context.find("/nonexistent/ecsim/topology.xml"), std::string::npos);
}

}  // namespace
}  // namespace ecsim
