// PDO assignment and mapping found without a configuration file: from the dictionary of CoE
// slaves (ours, and ecsim's demo ESI devices) and from the SII of slaves without CoE.
#include "master/pdo_config.hpp"

#include <gtest/gtest.h>

#include "tests/master/bring_up.hpp"
#include "tests/master/test_slaves.hpp"

namespace ecsim::testing {
namespace {

using master::PdoDiscoveryTask;
using master::PdoSource;

class PdoConfigTest : public ::testing::Test {
 protected:
  void bringUp() {
    net_.segment().wireLine();
    net_.start();
    auto status = scanAndPreOp(net_, transport_, slaves_);
    ASSERT_TRUE(status.ok()) << status.error().message();
  }
  master::SlaveProcessData discover(std::size_t position) {
    PdoDiscoveryTask task(transport_, slaves_[position], nullptr);
    EXPECT_TRUE(task.start(net_.clock().now()).ok());
    EXPECT_TRUE(master::runTask(task, transport_, net_.bus(), 10 * kNsPerSecond).ok());
    EXPECT_TRUE(task.status().ok()) << task.status().error().message();
    return task.result();
  }

  SimNetwork net_;
  master::Transport transport_{net_.masterLink()};
  std::vector<master::SlaveInfo> slaves_;
};

TEST_F(PdoConfigTest, MappingFromTheDictionary) {
  net_.segment().addSlave(makeCoeIoSlave("Coe", 0x51, 2, 3));
  bringUp();
  auto data = discover(0);
  EXPECT_EQ(data.source, PdoSource::kCoe);
  ASSERT_EQ(data.sms.size(), 2u);
  EXPECT_EQ(data.sms[0].sm, 2u);
  EXPECT_TRUE(data.sms[0].outputs);
  ASSERT_EQ(data.sms[0].pdos.size(), 1u);
  EXPECT_EQ(data.sms[0].pdos[0].index, 0x1600);
  ASSERT_EQ(data.sms[0].pdos[0].entries.size(), 2u);
  EXPECT_EQ(data.sms[0].pdos[0].entries[1].index, 0x7000);
  EXPECT_EQ(data.sms[0].pdos[0].entries[1].subindex, 2);
  EXPECT_EQ(data.sms[0].pdos[0].entries[1].bitLength, 16);
  EXPECT_EQ(data.sms[1].sm, 3u);
  EXPECT_FALSE(data.sms[1].outputs);
  EXPECT_EQ(data.sms[1].bitLength(), 48u);
  EXPECT_EQ(data.outputBits(), 32u);
  EXPECT_EQ(data.inputBits(), 48u);
}

TEST_F(PdoConfigTest, DemoAnalogInputFromItsDictionaryWithSiiNames) {
  net_.segment().addSlave(makeDemoSlave(0x3102, "AI1"));
  bringUp();
  auto data = discover(0);
  EXPECT_EQ(data.source, PdoSource::kCoe);
  // examples/README.md: SM3 holds 0x1A00 and 0x1A01, status + value per channel, 8 bytes;
  // SM2 has no PDO assigned.
  EXPECT_EQ(data.outputBits(), 0u);
  EXPECT_EQ(data.inputBits(), 64u);
  const master::SmPdoAssignment* inputs = nullptr;
  for (const auto& sm : data.sms) {
    if (sm.sm == 3) inputs = &sm;
  }
  ASSERT_NE(inputs, nullptr);
  ASSERT_EQ(inputs->pdos.size(), 2u);
  EXPECT_EQ(inputs->pdos[0].index, 0x1A00);
  EXPECT_EQ(inputs->pdos[1].index, 0x1A01);
  EXPECT_EQ(inputs->pdos[0].entries[1].index, 0x6000);
  EXPECT_EQ(inputs->pdos[0].entries[1].subindex, 0x11);
  EXPECT_FALSE(inputs->pdos[0].name.empty());  // from the SII strings
  EXPECT_FALSE(inputs->pdos[0].entries[0].name.empty());
  EXPECT_NE(inputs->pdos[0].entries[0].dataType, 0);
}

TEST_F(PdoConfigTest, SiiOnlySlave) {
  net_.segment().addSlave(makeIoSlave("DO", 0x2004, 3, 0));
  bringUp();
  auto data = master::processDataFromSii(slaves_[0]);
  EXPECT_EQ(data.source, PdoSource::kSii);
  ASSERT_EQ(data.sms.size(), 2u);
  EXPECT_EQ(data.sms[0].sm, 0u);
  EXPECT_EQ(data.sms[0].bitLength(), 24u);
  EXPECT_EQ(data.sms[0].pdos[0].name, "Outputs");
  EXPECT_EQ(data.sms[0].pdos[0].entries[2].name, "Out");
  EXPECT_EQ(data.sms[1].bitLength(), 0u);
}

TEST_F(PdoConfigTest, DictionaryWithoutSmTypesGivesNothing) {
  auto od = std::make_shared<slavesim::coe::ObjectDictionary>();
  slavesim::coe::addIdentityObject(*od, {kTestVendor, 0x52, 1, 0});
  net_.segment().addSlave(makeCoeSlave("Bare", 0x52, od));
  bringUp();
  PdoDiscoveryTask task(transport_, slaves_[0], nullptr);
  ASSERT_TRUE(task.start(net_.clock().now()).ok());
  ASSERT_TRUE(master::runTask(task, transport_, net_.bus(), kNsPerSecond).ok());
  EXPECT_TRUE(task.status().ok());
  EXPECT_EQ(task.result().source, PdoSource::kNone);
  EXPECT_EQ(task.uploads(), 1u);  // 0x1C00:00 aborted, nothing more asked
}


TEST_F(PdoConfigTest, ZeroAssignmentEntriesAndDummyMappingEntriesAreNotObjects) {
  // A dynamic-PDO device leaves unused assignment subindexes 0 (0x1C12:02 = 0 with sub 0 = 2:
  // ETG.1020 / as TwinCAT and IgH skip it), and a mapping may pad with a CiA 301 §7.4.8.3 dummy
  // entry (0x0005:00, 8 bits = UNSIGNED8). Neither is an object the master may ask for or list.
  namespace coe = slavesim::coe;
  auto od = std::make_shared<coe::ObjectDictionary>();
  coe::addIdentityObject(*od, {kTestVendor, 0x53, 1, 0});
  const std::uint8_t types[] = {1, 2, 3, 4};
  coe::addSyncManagerTypes(*od, types);
  od->addArray(0x7000, "Outputs", 0x0006, 16, 1,
               coe::access::kReadWrite | coe::access::kRxMappable);
  coe::PdoMappingSpec rx{0x1600, "Out", {{0x0005, 0, 8}, {0x7000, 1, 16}}, {}, 2, false};
  coe::addPdoMapping(*od, rx);
  const std::uint16_t rxPdos[] = {0x1600, 0x0000};
  coe::addPdoAssignment(*od, 2, rxPdos, 2, true);
  net_.segment().addSlave(makeCoeSlave("Dyn", 0x53, od));
  bringUp();
  auto data = discover(0);
  ASSERT_GE(data.sms.size(), 1u);
  ASSERT_EQ(data.sms[0].sm, 2u);
  ASSERT_EQ(data.sms[0].pdos.size(), 1u) << "the zero entry is no PDO";
  EXPECT_EQ(data.sms[0].pdos[0].index, 0x1600);
  EXPECT_EQ(data.sms[0].bitLength(), 24u) << "the dummy entry pads by 8 bits";
  EXPECT_TRUE(isPaddingEntry(data.sms[0].pdos[0].entries[0].index));
  EXPECT_FALSE(isPaddingEntry(data.sms[0].pdos[0].entries[1].index));
}

}  // namespace
}  // namespace ecsim::testing
