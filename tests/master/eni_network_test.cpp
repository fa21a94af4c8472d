// A network built from an ENI (topology/network_from_eni.hpp, devices from examples/esi) and
// served in-process reaches OP with our master configured from the same ENI: the simulator and
// the master agree on examples/eni/demo-eni.xml.
#include <gtest/gtest.h>

#include "config/eni.hpp"
#include "link/memory_link.hpp"
#include "master/master.hpp"
#include "topology/network_from_eni.hpp"
#include "topology/network_server.hpp"

namespace ecsim::testing {
namespace {

TEST(EniNetworkTest, DemoEniServedInProcessReachesOpWithTheSameEni) {
  const std::filesystem::path eniFile =
      std::filesystem::path(ECSIM_SOURCE_DIR) / "examples/eni/demo-eni.xml";
  auto network = topology::buildNetworkFromEni(
      eniFile, {std::filesystem::path(ECSIM_SOURCE_DIR) / "examples/esi"});
  ASSERT_TRUE(network.ok()) << network.error().message();
  topology::Segment& segment = *network->segment;
  ASSERT_EQ(segment.size(), 6u);
  // The ENI's PreviousPort entries made a line: every slave after the first on port 0 of the
  // one before's port 1 (B).
  for (std::size_t i = 1; i < segment.size(); ++i) {
    EXPECT_EQ(segment.ports(i)[0].slave, static_cast<int>(i - 1));
    EXPECT_EQ(segment.ports(i)[0].port, 1);
  }

  VirtualClock clock;
  auto links = MemoryLink::makePair(256);
  topology::ServerOptions serverOptions;
  serverOptions.idleWait = std::chrono::nanoseconds(0);
  topology::NetworkServer server(links.second, segment, clock, serverOptions);
  master::VirtualBus bus(clock, [&](SimTime) -> std::optional<SimTime> {
    const bool waiting = links.second.pending() > 0;
    const auto before = server.counters().framesAnswered;
    EXPECT_TRUE(server.step().ok());
    if (waiting && server.counters().framesAnswered != before) {
      return server.counters().lastRoundTrip;
    }
    return std::nullopt;
  });
  master::Master m(links.first, bus);
  ASSERT_TRUE(m.loadConfig(eniFile).ok());
  auto status = m.start();
  ASSERT_TRUE(status.ok()) << status.error().message();
  for (std::size_t i = 0; i < segment.size(); ++i) {
    EXPECT_EQ(segment.slave(i).state(), AlState::kOp) << i;
    EXPECT_EQ(m.slaves()[i].station, 1001 + i);
  }
  EXPECT_EQ(m.layout().outputBytes, 27u);
  EXPECT_EQ(m.layout().inputBytes, 39u);
  for (int cycle = 0; cycle < 100; ++cycle) {
    auto s = m.exchange();
    ASSERT_TRUE(s.ok()) << s.error().message();
  }
  ASSERT_TRUE(m.stop().ok());
  for (std::size_t i = 0; i < segment.size(); ++i) {
    EXPECT_EQ(segment.slave(i).state(), AlState::kInit);
  }
}

}  // namespace
}  // namespace ecsim::testing
