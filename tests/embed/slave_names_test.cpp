// Slave names by bus position (topology/slave_names.hpp, issue #16 item 3): the order a topology
// file's wiring gives (ports 0 -> 3 -> 1 -> 2, ESC datasheet section I §3.2 Table 10) checked
// against what a master actually scans, and the names an ENI and a topology file give.
#include "topology/slave_names.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "embed/testing/network_fixture.hpp"
#include "support/readiness.hpp"

namespace ecsim::testing {
namespace {

// Written Junction, B1, A1, A2, but a frame leaves the junction through port 3 (A1, then A2
// behind it) before port 1 (B1): the bus order is Junction, A1, A2, B1. A2 is wired in by its
// port 1, so the frame passes its processing unit only on the way back (port 1 -> 2 -> 0).
constexpr const char* kTree = R"(<?xml version="1.0"?>
<Topology name="tree">
  <Slave name="Junction" device="generic"/>
  <Slave name="B1" device="generic"/>
  <Slave name="A1" device="generic"/>
  <Slave name="A2" device="generic"/>
  <Link from="Junction:1" to="B1:0"/>
  <Link from="Junction:3" to="A1:0"/>
  <Link from="A1:1" to="A2:1"/>
</Topology>
)";

class SlaveNames : public NetworkFixture {
 protected:
  void TearDown() override {
    NetworkFixture::TearDown();
    if (!file_.empty()) std::filesystem::remove(file_);
  }
  std::filesystem::path write(const std::string& name, const std::string& text) {
    file_ = uniqueTempPath(name);
    std::ofstream(file_) << text;
    return file_;
  }
  std::filesystem::path file_;
};

TEST_F(SlaveNames, TreeOrderIsTheOrderTheMasterScans) {
  const auto file = write("slave_names_tree.xml", kTree);
  auto names = topology::loadSlaveNames(file);
  ASSERT_TRUE(names.ok()) << names.error().message();
  EXPECT_EQ(*names, (std::vector<std::string>{"Junction", "A1", "A2", "B1"}));

  // The master's scan, independently: generic slaves carry their topology name in the SII.
  ASSERT_TRUE(startInProcess(file).ok());
  EXPECT_EQ(topology::slaveNamesInBusOrder(network().segment()), *names);
  ASSERT_TRUE(master().scan().ok());
  std::vector<std::string> scanned;
  for (const auto& s : master().slaves()) scanned.push_back(s.name);
  EXPECT_EQ(scanned, *names);
  // The fixture named them: configured and SII names agree slave by slave.
  for (const auto& s : master().slaves()) EXPECT_EQ(s.configuredName, s.name) << s.label();
}

TEST_F(SlaveNames, AnEniGivesItsSlavesNamesInTheOrderWritten) {
  auto names = topology::loadSlaveNames(ECSIM_SOURCE_DIR "/examples/eni/demo-eni.xml");
  ASSERT_TRUE(names.ok()) << names.error().message();
  EXPECT_EQ(*names, (std::vector<std::string>{"Coupler", "DI1", "DO1", "AI1", "Drive1", "Drive2"}));
  auto demo = topology::loadSlaveNames(ECSIM_SOURCE_DIR "/examples/topologies/demo.xml");
  ASSERT_TRUE(demo.ok()) << demo.error().message();
  EXPECT_EQ(*demo, *names);
}

TEST_F(SlaveNames, AFileThatNamesNoSlavesIsRefusedNamingIt) {
  const auto file = write("slave_names_scenario.xml", "<Scenario name=\"x\"/>\n");
  auto names = topology::loadSlaveNames(file);
  ASSERT_FALSE(names.ok());
  EXPECT_NE(names.error().context.find(file.string()), std::string::npos) << names.error().context;
  EXPECT_NE(names.error().context.find("<Scenario>"), std::string::npos) << names.error().context;
  EXPECT_FALSE(topology::loadSlaveNames("/nonexistent/names.xml").ok());
}

}  // namespace
}  // namespace ecsim::testing
