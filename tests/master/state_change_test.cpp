// AL state changes of all slaves together: the way up to OP, a refused transition reported
// with its AL status code and text and acknowledged, an illegal jump.
#include "master/state_change.hpp"

#include <gtest/gtest.h>

#include "master/scan.hpp"
#include "tests/master/sim_network.hpp"
#include "tests/master/test_slaves.hpp"

namespace ecsim::testing {
namespace {

using master::StateChangeTask;

class StateChangeTest : public ::testing::Test {
 protected:
  void scan() {
    net_.start();
    master::ScanTask task(transport_, slaves_);
    task.start(net_.clock().now());
    ASSERT_TRUE(master::runTask(task, transport_, net_.bus(), kNsPerSecond).ok());
    ASSERT_TRUE(task.status().ok()) << task.status().error().message();
  }
  Status request(AlState target) {
    StateChangeTask task(transport_, slaves_);
    task.start(target, net_.clock().now());
    auto run = master::runTask(task, transport_, net_.bus(), 10 * kNsPerSecond);
    refusals_ = task.refusals();
    return run.ok() ? task.status() : run;
  }

  SimNetwork net_;
  master::Transport transport_{net_.masterLink()};
  std::vector<master::SlaveInfo> slaves_;
  std::vector<master::StateRefusal> refusals_;
};

TEST_F(StateChangeTest, AllSlavesGoUpToOpAndBackToInitTogether) {
  for (int i = 0; i < 3; ++i) {
    net_.segment().addSlave(slavesim::makeGenericSlave("G" + std::to_string(i), 0));
  }
  net_.segment().wireLine();
  scan();
  for (AlState s : {AlState::kPreOp, AlState::kSafeOp, AlState::kOp, AlState::kInit}) {
    auto status = request(s);
    ASSERT_TRUE(status.ok()) << toString(s) << ": " << status.error().message();
    for (std::size_t i = 0; i < 3; ++i) {
      EXPECT_EQ(net_.segment().slave(i).state(), s);
      EXPECT_EQ(slaves_[i].state(), s);
    }
  }
  EXPECT_TRUE(refusals_.empty());
}

TEST_F(StateChangeTest, RefusingSlaveIsReportedWithCodeAndTextAndAcknowledged) {
  net_.segment().addSlave(slavesim::makeGenericSlave("Good", 0));
  // This firmware wants a mailbox that the master (seeing no mailbox in the SII) never
  // configures: INIT->PREOP is refused with 0x0016.
  slavesim::SlaveProfile wantsMailbox;
  wantsMailbox.mailbox = slavesim::SlaveProfile::Mailbox{0x1000, 128, 0x1080, 128};
  net_.segment().addSlave(makeSiiSlave("Picky", ioSii("Picky", 0x99, 0, 0), wantsMailbox));
  net_.segment().wireLine();
  scan();
  auto status = request(AlState::kPreOp);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().code, ErrorCode::kAborted);
  ASSERT_EQ(refusals_.size(), 1u);
  EXPECT_EQ(refusals_[0].position, 1u);
  EXPECT_EQ(refusals_[0].alStatusCode, 0x0016);
  EXPECT_TRUE(refusals_[0].acknowledged);
  const std::string& text = status.error().context;
  EXPECT_NE(text.find("slave 1 (0x1002 'Picky') refused PREOP"), std::string::npos) << text;
  EXPECT_NE(text.find("0x0016 (" + std::string(alStatusCodeText(0x0016)) + ")"), std::string::npos)
      << text;
  EXPECT_NE(text.find("stays INIT"), std::string::npos) << text;
  // The other slave made it; the refusing one stays in INIT with its error acknowledged.
  EXPECT_EQ(net_.segment().slave(0).state(), AlState::kPreOp);
  EXPECT_EQ(net_.segment().slave(1).state(), AlState::kInit);
  EXPECT_EQ(net_.segment().slave(1).esc().alStatus() & kAlErrorFlag, 0);
}

TEST_F(StateChangeTest, IllegalJumpIsRefusedByEverySlave) {
  // Slaves with firmware (ESC configuration 0x0141 bit 0 clear): their state machine checks
  // the transition. With device emulation (the generic slave, like a real EK1100) the ESC
  // copies the request into AL status unchecked (ESC datasheet section II 0x0120).
  for (int i = 0; i < 2; ++i) {
    SiiContents c = ioSii("F" + std::to_string(i), 0x42, 0, 0);
    c.config.pdiControl = static_cast<std::uint16_t>(c.config.pdiControl & 0x00FF);
    net_.segment().addSlave(makeSiiSlave("F" + std::to_string(i), c));
  }
  net_.segment().wireLine();
  scan();
  auto status = request(AlState::kOp);  // INIT -> OP is not a transition (ETG.1000.6)
  ASSERT_FALSE(status.ok());
  ASSERT_EQ(refusals_.size(), 2u);
  for (const auto& r : refusals_) {
    EXPECT_EQ(r.alStatusCode, 0x0011);
    EXPECT_EQ(r.requested, AlState::kOp);
  }
  // Acknowledged: a legal request afterwards works.
  auto again = request(AlState::kPreOp);
  EXPECT_TRUE(again.ok()) << again.error().message();
}

TEST_F(StateChangeTest, LostAnswersAreRetriedTransparently) {
  for (int i = 0; i < 2; ++i) {
    net_.segment().addSlave(slavesim::makeGenericSlave("G" + std::to_string(i), 0));
  }
  net_.segment().wireLine();
  scan();
  const auto sent = net_.fault().sentCount();
  net_.fault().dropSend = {sent + 1, sent + 2};  // the first read and the first request
  auto status = request(AlState::kPreOp);
  EXPECT_TRUE(status.ok()) << status.error().message();
  EXPECT_EQ(transport_.counters().framesResent, 2u);
}

}  // namespace
}  // namespace ecsim::testing
