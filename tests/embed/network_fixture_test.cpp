// The GoogleTest fixture (embed/testing/network_fixture.hpp) on the demo topology: in process
// on virtual time, and on a veth pair in a private namespace (privileged; skipped without the
// capabilities, failed under CI=true).
#include "embed/testing/network_fixture.hpp"

#include <gtest/gtest.h>

#include "master/process_image.hpp"

namespace ecsim::testing {
namespace {

const std::filesystem::path kDemo = ECSIM_SOURCE_DIR "/examples/topologies/demo.xml";

class DemoNetwork : public NetworkFixture {};

TEST_F(DemoNetwork, InProcessOurMasterReachesOpAndStopsToInit) {
  ASSERT_TRUE(startInProcess(kDemo).ok());
  ASSERT_TRUE(hasMaster());
  ASSERT_TRUE(master().start().ok());
  ASSERT_EQ(master().slaves().size(), 6u);
  for (std::size_t i = 0; i < network().slaveCount(); ++i) {
    EXPECT_EQ(network().slave(i)->state(), AlState::kOp);
  }
  ASSERT_TRUE(master().exchange().ok());
  ASSERT_TRUE(master().stop().ok());
  EXPECT_EQ(network().slave("Drive1")->state(), AlState::kInit);
}

// Issue #16 item 3: the fixture's master names the slaves as the topology does, so the demo
// network's variables are "Drive1.Statusword" (not the SII's "ECS7201_4.Statusword"), and its
// events name the slave "Drive1" too.
TEST_F(DemoNetwork, InProcessVariablesAndEventsUseTheTopologysNames) {
  ASSERT_TRUE(startInProcess(kDemo).ok());
  ASSERT_TRUE(master().start().ok());
  auto statusword = master().variable("Drive1.Statusword");
  ASSERT_TRUE(statusword.ok()) << statusword.error().message();
  EXPECT_EQ(statusword->info().index, 0x6041);
  EXPECT_EQ(statusword->info().position, 4u);  // the fifth slave on the bus
  EXPECT_TRUE(master().variable("DI1.Input 3").ok());
  ASSERT_TRUE(master().exchange().ok());
  // The drive's statusword as the drive itself holds it (PDI side) is what the master read.
  auto onSlave = network().slave("Drive1")->read<std::uint16_t>(0x6041, 0);
  ASSERT_TRUE(onSlave.ok()) << onSlave.error().message();
  EXPECT_EQ(statusword->get<std::uint16_t>(), *onSlave);
  EXPECT_EQ(master().slaves()[4].label(), "slave 4 (0x1005 'Drive1')");

  // A pulled cable in front of Drive2: the master's event names it by its topology name.
  network().segment().setLinkUp(4, 1, false);
  for (int i = 0; i < 50; ++i) (void)master().cycle();
  bool named = false;
  std::string log;
  for (const auto& e : master().events()) {
    log += e.text + "\n";
    if (e.kind == master::MasterEventKind::kSlaveLost &&
        e.text.find("slave 5 (0x1006 'Drive2') lost") != std::string::npos) {
      named = true;
    }
  }
  EXPECT_TRUE(named) << log;
  EXPECT_EQ(master().health().slaves[5].name, "Drive2");
}

TEST_F(DemoNetwork, InProcessWithoutMasterTheNetworkStillRuns) {
  FixtureOptions options;
  options.withMaster = false;
  ASSERT_TRUE(startInProcess(kDemo, options).ok());
  EXPECT_FALSE(hasMaster());
  ASSERT_TRUE(advance(2 * kNsPerMs).ok());
  EXPECT_EQ(network().now(), 2 * kNsPerMs);
}

TEST_F(DemoNetwork, AMissingTopologyIsReported) {
  auto s = startInProcess("/nonexistent/demo.xml");
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().context.find("/nonexistent/demo.xml"), std::string::npos);
}

TEST_F(DemoNetwork, OnVethOurMasterReachesOpThroughARawSocket) {
  ECSIM_FIXTURE_SKIP_WITHOUT_NETWORK(startOnVeth(kDemo));
  ASSERT_TRUE(master().start().ok());
  EXPECT_EQ(master().slaves().size(), 6u);
  // Named as the topology names the slaves, over the raw socket too (issue #16 item 3).
  auto statusword = master().variable("Drive1.Statusword");
  ASSERT_TRUE(statusword.ok()) << statusword.error().message();
  EXPECT_EQ(statusword->info().index, 0x6041);
  {
    auto lock = network().lock();
    EXPECT_EQ(network().slave("Drive2")->state(), AlState::kOp);
    EXPECT_GT(network().serverCounters().framesAnswered, 0u);
  }
  ASSERT_TRUE(master().stop().ok());
  stopNetwork();
  EXPECT_TRUE(serverStatus().ok());
}

}  // namespace
}  // namespace ecsim::testing
