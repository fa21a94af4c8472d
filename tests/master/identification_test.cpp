// Which device came back: a slave that returns after a power cycle or a hot-connect (a tool
// changer's tool) is checked beyond vendor and product, by its configured station alias
// (0x0012, from SII word 4) and, when it showed one at the scan, its Explicit Device ID
// (ETG.1020 §22.2.2: AL control bit 5 requests it, AL status bit 5 and 0x0134 show it). Two
// tools of one type differ only there; the master must not bring the wrong one to OP.
#include <gtest/gtest.h>

#include "master/master.hpp"
#include "tests/master/bring_up.hpp"

namespace ecsim::testing {
namespace {

using master::MasterEventKind;

enum : std::size_t { kCoupler, kDi, kDo, kAi, kDrive, kCount };
constexpr std::uint16_t kToolId = 5;

class IdentificationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    addDemoSlaves(net_, 1);
    sim(kDrive).profile().explicitDeviceId = kToolId;  // the tool's ID switch
    net_.start();
    master_ = std::make_unique<master::Master>(net_.masterLink(), net_.bus());
    auto status = master_->start();
    ASSERT_TRUE(status.ok()) << status.error().message();
    EXPECT_EQ(runCycles(*master_, net_, 100), 0u);
  }
  // The tool taken off and another put on: power off, `change` the device, power on.
  template <typename F>
  void swap(std::size_t i, F change) {
    sim(i).powerOff();
    change(sim(i));
    sim(i).powerOn(net_.clock().now());
  }
  const master::MasterEvent* event(MasterEventKind kind, std::size_t position) const {
    return findEvent(master_->events(), kind, position);
  }
  std::string log() const { return eventLog(master_->events()); }
  slavesim::Slave& sim(std::size_t i) { return net_.segment().slave(i); }

  SimNetwork net_;
  std::unique_ptr<master::Master> master_;
};

TEST_F(IdentificationTest, TheScanRecordsTheExplicitDeviceIdOfSlavesThatHaveOne) {
  const auto& slaves = master_->slaves();
  ASSERT_EQ(slaves.size(), kCount);
  EXPECT_EQ(slaves[kDrive].deviceId, std::optional<std::uint16_t>(kToolId));
  for (std::size_t i : {kCoupler, kDi, kDo, kAi}) EXPECT_FALSE(slaves[i].deviceId) << i;
  // The request went with the reset and was withdrawn by INIT->PREOP: in OP, no ID shown.
  EXPECT_EQ(sim(kDrive).esc().reg16(reg::kAlStatus.address), 0x0008);
  EXPECT_EQ(sim(kDrive).esc().reg16(reg::kAlStatusCode.address), 0);
}

TEST_F(IdentificationTest, AToolWithAnotherIdIsNotBroughtToOp) {
  swap(kDrive, [](slavesim::Slave& s) { s.profile().explicitDeviceId = 9; });
  runCycles(*master_, net_, 300);
  const auto* failed = event(MasterEventKind::kRecoveryFailed, kDrive);
  ASSERT_NE(failed, nullptr) << log();
  EXPECT_NE(failed->text.find("explicit device ID (0x0134) 9, expected 5"), std::string::npos)
      << failed->text;
  EXPECT_EQ(event(MasterEventKind::kSlaveRecovered, kDrive), nullptr) << log();
  EXPECT_EQ(sim(kDrive).state(), AlState::kInit);
  EXPECT_EQ(runCycles(*master_, net_, 100), 0u);  // the others run on clean
  // The right tool back on: the next attempt (every 1000 cycles) brings it to OP.
  swap(kDrive, [](slavesim::Slave& s) { s.profile().explicitDeviceId = kToolId; });
  runCycles(*master_, net_, 1500);
  EXPECT_NE(event(MasterEventKind::kSlaveRecovered, kDrive), nullptr) << log();
  EXPECT_EQ(sim(kDrive).state(), AlState::kOp);
}

TEST_F(IdentificationTest, ADeviceWithAnotherAliasIsNotBroughtToOp) {
  swap(kAi, [](slavesim::Slave& s) { s.esc().setSiiStationAlias(7); });
  runCycles(*master_, net_, 300);
  const auto* failed = event(MasterEventKind::kRecoveryFailed, kAi);
  ASSERT_NE(failed, nullptr) << log();
  EXPECT_NE(failed->text.find("station alias (0x0012) 7, expected 0"), std::string::npos)
      << failed->text;
  EXPECT_NE(sim(kAi).state(), AlState::kOp);
}

TEST_F(IdentificationTest, TheSameDeviceComesBack) {
  swap(kDrive, [](slavesim::Slave&) {});
  runCycles(*master_, net_, 500);
  EXPECT_NE(event(MasterEventKind::kSlaveRecovered, kDrive), nullptr) << log();
  EXPECT_EQ(event(MasterEventKind::kRecoveryFailed, kDrive), nullptr) << log();
  EXPECT_EQ(sim(kDrive).state(), AlState::kOp);
}

}  // namespace
}  // namespace ecsim::testing
