// Networks from ENI files (topology/network_from_eni.hpp): devices found by vendor, product
// and revision in the ESI files of a folder, wiring from PreviousPort (a tree) or a line, and
// the error naming the ENI line of a slave no ESI file has.
#include "topology/network_from_eni.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

namespace ecsim::testing {
namespace {

const std::filesystem::path kEsiDir = std::filesystem::path(ECSIM_SOURCE_DIR) / "examples/esi";

// An ENI of ecsim demo devices: (name, PhysAddr, product, previous PhysAddr, previous port).
struct Entry {
  const char* name;
  int physAddr;
  unsigned product;
  int previous;  // 0: none
  char port;
};
std::string eniText(const std::vector<Entry>& entries) {
  std::string xml = "<?xml version=\"1.0\"?>\n<EtherCATConfig>\n<Config>\n";
  for (const auto& e : entries) {
    xml += "<Slave>\n<Info><Name>" + std::string(e.name) + "</Name><PhysAddr>" +
           std::to_string(e.physAddr) + "</PhysAddr><VendorId>#x00000E5C</VendorId><ProductCode>" +
           std::to_string(e.product) + "</ProductCode><RevisionNo>#x00010000</RevisionNo></Info>\n";
    if (e.previous != 0) {
      xml += "<PreviousPort><Port>" + std::string(1, e.port) + "</Port><PhysAddr>" +
             std::to_string(e.previous) + "</PhysAddr></PreviousPort>\n";
    }
    xml += "</Slave>\n";
  }
  return xml + "</Config>\n</EtherCATConfig>\n";
}

TEST(NetworkFromEni, TreeFromPreviousPorts) {
  // A 4-port junction (ECS1122) with DI1 behind port D (3) and DO1 behind port B (1).
  auto eni = parseEni(eniText({{"J", 1001, 0x1122, 0, 'A'},
                               {"DI1", 1002, 0x1008, 1001, 'D'},
                               {"DO1", 1003, 0x2008, 1001, 'B'}}),
                      "tree.xml");
  ASSERT_TRUE(eni.ok()) << eni.error().message();
  auto config = topology::topologyFromEni(*eni, {kEsiDir});
  ASSERT_TRUE(config.ok()) << config.error().message();
  ASSERT_EQ(config->slaves.size(), 3u);
  EXPECT_EQ(config->slaves[0].productCode, 0x1122u);
  EXPECT_EQ(config->slaves[1].esiFile.filename(), "ecsim_devices.xml");
  EXPECT_EQ(config->slaves[2].revision, 0x00010000u);
  ASSERT_EQ(config->links.size(), 2u);
  EXPECT_EQ(config->links[0].fromSlave, 0u);
  EXPECT_EQ(config->links[0].fromPort, 3u);
  EXPECT_EQ(config->links[0].toSlave, 1u);
  EXPECT_EQ(config->links[1].fromPort, 1u);
  EXPECT_EQ(config->links[1].toSlave, 2u);
  auto network = topology::buildNetwork(*config);
  ASSERT_TRUE(network.ok()) << network.error().message();
  EXPECT_EQ(network->segment->ports(0)[3].slave, 1);
  EXPECT_EQ(network->segment->ports(0)[1].slave, 2);
}

TEST(NetworkFromEni, LineWithoutPreviousPorts) {
  auto eni = parseEni(
      eniText({{"A", 1, 0x1100, 0, 'A'}, {"B", 2, 0x1008, 0, 'A'}, {"C", 3, 0x2008, 0, 'A'}}),
      "line.xml");
  ASSERT_TRUE(eni.ok());
  auto config = topology::topologyFromEni(*eni, {kEsiDir});
  ASSERT_TRUE(config.ok()) << config.error().message();
  ASSERT_EQ(config->links.size(), 2u);
  EXPECT_EQ(config->links[1].fromSlave, 1u);
  EXPECT_EQ(config->links[1].fromPort, 1u);
  EXPECT_EQ(config->links[1].toSlave, 2u);
  EXPECT_EQ(config->links[1].name, "B:1-C:0");
}

// Issue #21: an ENI value the reader ignored reaches the network's warnings (ecsim serve
// prints them) instead of vanishing.
TEST(NetworkFromEni, IgnoredValuesAreWarningsOfTheNetwork) {
  std::string text = eniText({{"A", 1, 0x1100, 0, 'A'}});
  const std::string end = "</Config>";
  text.insert(text.find(end), "<Cyclic><CycleTime>5000000</CycleTime></Cyclic>\n");
  const auto file = std::filesystem::path(::testing::TempDir()) /
                    ("ecsim_eni_warning_" + std::to_string(::getpid()) + ".xml");
  {
    std::ofstream out(file);
    out << text;
  }
  auto network = topology::buildNetworkFromEni(file, {kEsiDir});
  std::filesystem::remove(file);
  ASSERT_TRUE(network.ok()) << network.error().message();
  ASSERT_EQ(network->warnings.size(), 1u);
  EXPECT_NE(network->warnings[0].find("line 7: CycleTime 5000000 us is outside [1, 1000000]"),
            std::string::npos)
      << network->warnings[0];
}

TEST(NetworkFromEni, UnknownDeviceNamesTheEniLine) {
  auto eni =
      parseEni(eniText({{"A", 1, 0x1100, 0, 'A'}, {"Mystery", 2, 0x9999, 1, 'B'}}), "unknown.xml");
  ASSERT_TRUE(eni.ok());
  auto config = topology::topologyFromEni(*eni, {kEsiDir});
  ASSERT_FALSE(config.ok());
  EXPECT_EQ(config.error().code, ErrorCode::kNotFound);
  const std::string& text = config.error().context;
  EXPECT_NE(text.find("unknown.xml, line 7: slave 'Mystery'"), std::string::npos) << text;
  EXPECT_NE(text.find("product 0x00009999"), std::string::npos) << text;
  EXPECT_NE(text.find("examples/esi"), std::string::npos) << text;
}

}  // namespace
}  // namespace ecsim::testing
