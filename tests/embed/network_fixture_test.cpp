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
