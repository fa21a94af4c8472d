// Cable redundancy in our master (issue #20 item 4; master/transport.hpp): the demo line with
// its last slave's port 1 wired back to the master's second port, cycling at 1 ms on virtual
// time. The simulator's side of the ring is tests/topology/segment_redundancy_test.cpp; SOEM's
// (ec_init_redundant) is tests/interop/soem_redundancy_test.cpp. What the master relies on is
// the ESC's forwarding (ESC datasheet section I §3.2, Table 10: a frame entering at port 1
// leaves by port 0 unprocessed): on a whole ring its frame comes back at the second port; with
// the ring cut it comes back at the primary port, and sent on from the second port it collects
// the slaves behind the cut.
#include <gtest/gtest.h>

#include "master/health.hpp"
#include "master/master.hpp"
#include "protocol/registers.hpp"
#include "tests/master/bring_up.hpp"

namespace ecsim::testing {
namespace {

using master::MasterEventKind;
using master::RingState;

enum : std::size_t { kCoupler, kDi, kDo, kAi, kDrive, kCount };

class RedundancyTest : public ::testing::Test {
 protected:
  // `redundant`: the line's end wired to the master's second port, which the master uses;
  // otherwise a plain line.
  void build(bool redundant = true) {
    addDemoSlaves(net_, 1);
    if (redundant) {
      ASSERT_TRUE(net_.segment().setRedundantPort(kDrive, 1).ok());
    }
    net_.start(redundant);
    master_ = std::make_unique<master::Master>(net_.masterLink(), net_.bus());
    if (redundant) master_->setRedundantLink(&net_.secondPort());
    auto status = master_->start();
    ASSERT_TRUE(status.ok()) << status.error().message();
    master_->resetStatistics();
  }
  std::uint64_t run(std::uint64_t n) { return runCycles(*master_, net_, n); }
  void setCable(std::size_t a, std::size_t b, bool up) {
    net_.segment().setLinkUp(a, 1, up);
    net_.segment().setLinkUp(b, 0, up);
  }
  std::size_t count(MasterEventKind kind) const {
    std::size_t n = 0;
    for (const auto& e : master_->events()) n += e.kind == kind ? 1 : 0;
    return n;
  }
  const master::MasterEvent* find(MasterEventKind kind) const {
    for (const auto& e : master_->events()) {
      if (e.kind == kind) return &e;
    }
    return nullptr;
  }

  SimNetwork net_;
  std::unique_ptr<master::Master> master_;
};

TEST_F(RedundancyTest, OnAWholeRingEveryFrameComesRoundToTheSecondPort) {
  build();
  EXPECT_EQ(run(500), 0u) << eventLog(master_->events());
  EXPECT_EQ(master_->transport().ring(), RingState::kWhole);
  EXPECT_EQ(master_->health().ring, RingState::kWhole);
  const auto& c = master_->transport().counters();
  EXPECT_EQ(c.framesPassedOn, 0u);
  EXPECT_EQ(c.framesLost, 0u);
  EXPECT_EQ(master_->events().size(), 0u) << eventLog(master_->events());
}

TEST_F(RedundancyTest, ACablePulledMidRingLosesNoCycleIsReportedWhereAndHeals) {
  build();
  ASSERT_EQ(run(200), 0u);
  setCable(kDo, kAi, false);  // AI1 and Drive1 are now reached from the second port only
  EXPECT_EQ(run(1000), 0u) << eventLog(master_->events());
  const auto* broken = find(MasterEventKind::kRingBroken);
  ASSERT_NE(broken, nullptr) << eventLog(master_->events());
  EXPECT_EQ(broken->position, kDo) << broken->text;
  EXPECT_NE(broken->text.find("2 slave(s) answer at the second port"), std::string::npos)
      << broken->text;
  EXPECT_EQ(broken->cycle, 201u) << "reported in the cycle the cable was pulled";
  EXPECT_EQ(count(MasterEventKind::kSlaveLost), 0u) << eventLog(master_->events());
  EXPECT_EQ(master_->health().ring, RingState::kBroken);
  EXPECT_EQ(master_->health().ringBreaks, 1u);
  EXPECT_EQ(master_->health().wkcErrors, 0u);
  EXPECT_EQ(master_->health().framesLost, 0u);
  EXPECT_GE(master_->transport().counters().framesPassedOn, 1000u);

  setCable(kDo, kAi, true);
  EXPECT_EQ(run(200), 0u) << eventLog(master_->events());
  const auto* whole = find(MasterEventKind::kRingWhole);
  ASSERT_NE(whole, nullptr) << eventLog(master_->events());
  EXPECT_EQ(whole->cycle, 1201u);
  EXPECT_EQ(master_->transport().ring(), RingState::kWhole);
  EXPECT_EQ(count(MasterEventKind::kRingBroken), 1u);
}

// The control: the same line and the same cut without the ring. AI1 and Drive1 are lost
// (working counter errors, then lost events): what the redundancy saves.
TEST_F(RedundancyTest, WithoutTheSecondPortTheSameCutLosesTheSlavesBehindIt) {
  build(false);
  ASSERT_EQ(run(200), 0u);
  setCable(kDo, kAi, false);
  EXPECT_GT(run(100), 0u);
  EXPECT_EQ(count(MasterEventKind::kSlaveLost), 2u) << eventLog(master_->events());
  EXPECT_EQ(master_->health().ring, RingState::kNone);
}

// The cut after the last slave (its port 1 to the second port): every slave is still reached
// from the primary port, whose frame comes back complete. The frames sent on in the cycle of
// the cut wait for their deadline (nothing behind the second port answers); after that frames
// are taken as they come back.
TEST_F(RedundancyTest, TheLastCablePulledCostsOneFrameTimeoutAndNoCycle) {
  build();
  ASSERT_EQ(run(200), 0u);
  net_.segment().setLinkUp(kDrive, 1, false);
  EXPECT_EQ(run(5), 0u) << eventLog(master_->events());
  const auto& c = master_->transport().counters();
  const auto unanswered = c.passOnsUnanswered;
  EXPECT_GE(unanswered, 1u);
  EXPECT_EQ(run(495), 0u) << eventLog(master_->events());
  EXPECT_EQ(c.passOnsUnanswered, unanswered) << "no more waiting after the first";
  EXPECT_EQ(c.framesLost, 0u);
  const auto* broken = find(MasterEventKind::kRingBroken);
  ASSERT_NE(broken, nullptr) << eventLog(master_->events());
  EXPECT_EQ(broken->position, kDrive) << broken->text;
  EXPECT_EQ(count(MasterEventKind::kSlaveLost), 0u) << eventLog(master_->events());
}

// The master's own cable (primary port to the coupler's port 0) pulled: the primary port
// reaches no slave, and every frame it sends is lost on the dead link. The BRD beside it comes
// back at the second port having passed every slave: the coupler's port 0, without link, loops
// the frame back (ESC datasheet section I §3.2), so it is processed on its way back out. The
// master sends the frame itself from the second port, as SOEM's ecx_waitinframe_red does when
// the primary port got nothing and the second port its BRD; knowing the ring's slave count it
// does so as soon as that BRD shows all of them behind the break, without waiting for the
// frame's timeout, and no cycle is lost.
TEST_F(RedundancyTest, TheMastersOwnCablePulledLosesNoCycleAndIsReportedAtThePrimaryPort) {
  build();
  ASSERT_EQ(run(200), 0u);
  net_.segment().setLinkUp(kCoupler, 0, false);
  EXPECT_EQ(run(1000), 0u) << eventLog(master_->events());
  const auto& c = master_->transport().counters();
  EXPECT_GE(c.framesSentFromSecond, 1000u);
  EXPECT_EQ(c.framesLost, 0u);
  EXPECT_EQ(master_->health().wkcErrors, 0u);
  EXPECT_EQ(count(MasterEventKind::kSlaveLost), 0u) << eventLog(master_->events());
  const auto* broken = find(MasterEventKind::kRingBroken);
  ASSERT_NE(broken, nullptr) << eventLog(master_->events());
  EXPECT_EQ(broken->position, kCoupler) << broken->text;
  EXPECT_NE(broken->text.find("the primary port reaches no slave"), std::string::npos)
      << broken->text;
  EXPECT_NE(broken->text.find("5 slave(s) answer at the second port"), std::string::npos)
      << broken->text;

  net_.segment().setLinkUp(kCoupler, 0, true);
  EXPECT_EQ(run(200), 0u) << eventLog(master_->events());
  EXPECT_EQ(master_->transport().ring(), RingState::kWhole);
  EXPECT_EQ(count(MasterEventKind::kRingWhole), 1u) << eventLog(master_->events());
}

// Without the ring's slave count (a transport used on its own, or slaves missing so that the
// BRD counts fewer), the master waits for the frame's timeout first, then sends it from the
// second port: each frame answered, one timeout late, as SOEM's ecx_waitinframe_red.
TEST_F(RedundancyTest, WithoutTheSlaveCountTheFrameGoesOutOfTheSecondPortAfterItsTimeout) {
  build();
  ASSERT_EQ(run(200), 0u);
  master_->transport().setRingSlaveCount(0);
  net_.segment().setLinkUp(kCoupler, 0, false);
  master::Datagram read;
  read.read(Command::kBrd, 0, reg::kAlStatus, kCount);
  master_->transport().queue(read);
  const SimTime sent = net_.bus().now();
  while (read.pending()) {
    master_->transport().poll(net_.bus().now());
    net_.bus().wait(net_.bus().now() + 10 * kNsPerUs);
  }
  EXPECT_EQ(read.state(), master::DatagramState::kReceived);
  EXPECT_EQ(read.wkc(), kCount);
  EXPECT_GE(net_.bus().now() - sent, master_->transport().options().timeout);
  EXPECT_EQ(master_->transport().counters().framesSentFromSecond, 1u);
}

}  // namespace
}  // namespace ecsim::testing
