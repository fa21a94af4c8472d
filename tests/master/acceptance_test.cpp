// Acceptance of the master core (issue #7, "in-process system tests on virtual time"): the
// demo network (examples/topologies/demo.xml's devices) and a 100-slave network reach OP
// through start() without any configuration file, run 100,000 cycles of 1 ms with
// Master::cycle() and zero WKC errors, lost or late frames, and return to INIT with stop().
#include <gtest/gtest.h>

#include <chrono>

#include "master/master.hpp"
#include "slavesim/generic_slave.hpp"
#include "tests/master/bring_up.hpp"
#include "tests/master/test_slaves.hpp"

namespace ecsim::testing {
namespace {

// 100,000 cycles, the figure; 10,000 under AddressSanitizer (the asan preset's g++
// defines __SANITIZE_ADDRESS__), where a cycle costs some 10 times more, as in
// eni_master_test.cpp: every cycle runs the same allocation-free cyclic code, so what the
// sanitizers can find they find in the first of them; the long run's count stays in the
// other builds.
#if defined(__SANITIZE_ADDRESS__)
constexpr std::uint64_t kCycles = 10'000;
#else
constexpr std::uint64_t kCycles = 100'000;
#endif

class AcceptanceTest : public ::testing::Test {
 protected:
  // Starts, runs kCycles cycles (outputs change every cycle), stops; checks every step.
  void startRunStop() {
    net_.segment().wireLine();
    net_.start();
    master::Master master(net_.masterLink(), net_.bus());
    auto status = master.start();
    ASSERT_TRUE(status.ok()) << status.error().message();
    for (std::size_t i = 0; i < net_.segment().size(); ++i) {
      ASSERT_EQ(net_.segment().slave(i).state(), AlState::kOp) << i;
    }
    master.resetStatistics();
    const auto wall = std::chrono::steady_clock::now();
    std::uint64_t failed = 0;
    std::string firstError;
    std::vector<std::uint8_t> outputs(master.layout().outputBytes);
    for (std::uint64_t cycle = 0; cycle < kCycles; ++cycle) {
      const SimTime next = net_.clock().now() + kNsPerMs;
      for (std::size_t k = 0; k < outputs.size(); ++k) {
        outputs[k] = static_cast<std::uint8_t>(cycle + k);
      }
      ASSERT_TRUE(master.writeData(0, outputs).ok());
      auto s = master.cycle();
      if (!s.ok() && failed++ == 0) firstError = s.error().message();
      while (net_.clock().now() < next) net_.bus().wait(next);
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall).count();
    std::printf("%zu slaves: %llu cycles in %.2f s wall (%.1f us per cycle)\n",
                master.slaves().size(), static_cast<unsigned long long>(kCycles), seconds,
                seconds * 1e6 / static_cast<double>(kCycles));
    EXPECT_EQ(failed, 0u) << firstError;
    const auto& st = master.statistics();
    EXPECT_EQ(st.cycles, kCycles);
    EXPECT_EQ(st.wkcErrors, 0u);
    EXPECT_EQ(st.framesLost, 0u);
    EXPECT_EQ(st.framesLate, 0u);
    EXPECT_EQ(st.roundTrip.count(), kCycles * master.layout().frameCount);
    EXPECT_TRUE(master.events().empty()) << master.events().front().text;
    EXPECT_TRUE(master.health().allOperational());
    ASSERT_TRUE(master.stop().ok());
    for (std::size_t i = 0; i < net_.segment().size(); ++i) {
      EXPECT_EQ(net_.segment().slave(i).state(), AlState::kInit) << i;
    }
  }

  SimNetwork net_;
};

TEST_F(AcceptanceTest, DemoNetworkRunsHundredThousandCyclesWithoutErrors) {
  net_.segment().addSlave(makeDemoSlave(0x1100, "Coupler"));
  net_.segment().addSlave(makeDemoSlave(0x1008, "DI1"));
  net_.segment().addSlave(makeDemoSlave(0x2008, "DO1"));
  net_.segment().addSlave(makeDemoSlave(0x3102, "AI1"));
  net_.segment().addSlave(makeDemoSlave(0x7201, "Drive1"));
  net_.segment().addSlave(makeDemoSlave(0x7201, "Drive2"));
  startRunStop();
}

TEST_F(AcceptanceTest, HundredSlavesRunHundredThousandCyclesWithoutErrors) {
  // SII-only I/O terminals (4 output bytes, 2 input words each): 600 bytes of process data.
  for (std::uint32_t i = 0; i < 100; ++i) {
    net_.segment().addSlave(makeIoSlave("IO" + std::to_string(i + 1), 0x3000 + i, 4, 2));
  }
  startRunStop();
}

}  // namespace
}  // namespace ecsim::testing
