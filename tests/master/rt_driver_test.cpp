// The real-time driver's threads around a master on the in-process simulator: the cyclic task
// wakes on real time (clock_nanosleep), the send/receive thread runs the cycle's I/O steps on
// the virtual-time bus (whose waits serve the simulator), the control thread steps health and
// publishes snapshots. Whether SCHED_FIFO was granted
// depends on the environment: either realtime() or a warning that says why not.
#include "master/rt_driver.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "tests/master/bring_up.hpp"
#include "tests/master/test_slaves.hpp"

namespace ecsim::testing {
namespace {

TEST(RtDriverTest, RunsCyclesWithTheApplicationAndPublishesSnapshots) {
  SimNetwork net;
  net.segment().addSlave(makeIoSlave("A", 0x10, 2, 1));
  net.segment().addSlave(makeIoSlave("B", 0x11, 1, 2));
  net.segment().wireLine();
  net.start();
  master::Master m(net.masterLink(), net.bus());
  ASSERT_TRUE(m.start().ok());

  master::RtDriverOptions options;
  options.period = 2 * kNsPerMs;
  options.snapshotPeriod = 10 * kNsPerMs;
  options.lockMemory = false;  // keep the test process's memory as it is
  master::RtDriver driver(m, options);
  std::uint64_t calls = 0;
  std::uint64_t lastCycle = 0;
  ASSERT_TRUE(driver
                  .start([&](master::Master& master, std::uint64_t cycle) {
                    ++calls;
                    lastCycle = cycle;
                    const std::array<std::uint8_t, 1> out{static_cast<std::uint8_t>(cycle)};
                    (void)master.writeData(0, out);
                  })
                  .ok());
  EXPECT_TRUE(driver.running());
  EXPECT_FALSE(driver.start().ok());  // already running
  if (!driver.realtime()) {
    ASSERT_FALSE(driver.warnings().empty());
    EXPECT_NE(driver.warnings()[0].find("real-time scheduling not available"), std::string::npos)
        << driver.warnings()[0];
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const auto live = driver.snapshot();
  driver.stop();
  EXPECT_FALSE(driver.running());
  const auto s = driver.snapshot();
  EXPECT_GT(live.cycles, 0u);
  EXPECT_GE(s.cycles, live.cycles);
  // About 100 periods of 2 ms in 200 ms; a loaded machine may lose some to overruns.
  EXPECT_GE(s.cycles, 20u);
  EXPECT_LE(s.cycles, 110u);
  EXPECT_EQ(calls, s.cycles);
  EXPECT_EQ(lastCycle, s.cycles);
  EXPECT_EQ(s.failedCycles, 0u) << s.firstError;
  EXPECT_EQ(s.statistics.wkcErrors, 0u);
  EXPECT_EQ(s.wakeLatency.count(), s.cycles);
  EXPECT_GE(s.wakeLatency.min(), 0);
  // The last outputs reached slave A.
  ConstBytes outputs = net.segment().slave(0).esc().pdiOutputs(0);
  ASSERT_EQ(outputs.size(), 2u);
  EXPECT_EQ(outputs[0], static_cast<std::uint8_t>(lastCycle));
  EXPECT_TRUE(s.health.allOperational());
}

}  // namespace
}  // namespace ecsim::testing
