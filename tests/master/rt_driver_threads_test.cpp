// The real-time driver's three threads against the demo network served by its own thread on
// real time (tests/master/rt_driver_network.hpp): their names, policies and priorities as the
// kernel reports them, pinning to one CPU, recovery stepped by the control thread (and not by
// send/receive), an SDO posted while running, and a clean stop.
#include <gtest/gtest.h>
#include <sched.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <set>
#include <thread>

#include "master/coe_client.hpp"
#include "master/rt_driver.hpp"
#include "tests/master/bring_up.hpp"
#include "tests/master/rt_driver_network.hpp"

namespace ecsim::testing {
namespace {

using master::MasterEventKind;
using master::SlaveCondition;

enum : std::size_t { kCoupler, kDi, kDo, kAi, kDrive };

// The names of this process's threads, from /proc (what `ps -L` and `top -H` show).
std::set<std::string> threadNames() {
  std::set<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/task")) {
    std::ifstream comm(entry.path() / "comm");
    std::string name;
    if (std::getline(comm, name)) names.insert(name);
  }
  return names;
}

class RtDriverThreadsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    addDemoSlaves(net_, 1);
    net_.start();
    master_ = std::make_unique<master::Master>(net_.masterLink(), net_.bus());
    auto status = master_->start();
    ASSERT_TRUE(status.ok()) << status.error().message();
  }
  master::RtDriverOptions options() const {
    master::RtDriverOptions o;
    o.period = 2 * kNsPerMs;  // a 2-core machine shared with others' builds
    o.lockMemory = false;     // keep the test process's memory as it is
    o.snapshotPeriod = 10 * kNsPerMs;
    return o;
  }
  // Polls the driver's snapshot until `done` holds or `seconds` pass; true when it held.
  template <typename F>
  bool waitFor(master::RtDriver& driver, F done, int seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(seconds);
    while (std::chrono::steady_clock::now() < end) {
      if (done(driver.snapshot())) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return done(driver.snapshot());
  }
  static bool hasEvent(const master::RtSnapshot& s, MasterEventKind kind, std::size_t position) {
    return testing::findEvent(s.events, kind, position) != nullptr;
  }
  static std::string eventLog(const master::RtSnapshot& s) { return testing::eventLog(s.events); }
  AlState simState(std::size_t i) {
    AlState state = AlState::kInit;
    net_.onServer([&](topology::Segment& segment) { state = segment.slave(i).state(); });
    return state;
  }

  ServedNetwork net_;
  std::unique_ptr<master::Master> master_;
};

TEST_F(RtDriverThreadsTest, ThreeNamedThreadsAtTheirPoliciesPinnedToOneCpu) {
  auto o = options();
  o.cpu = 0;
  master::RtDriver driver(*master_, o);
  ASSERT_TRUE(driver.start().ok());
  const auto threads = driver.threads();
  ASSERT_EQ(threads.size(), 3u);
  EXPECT_EQ(threads[0].name, "ec-sendrecv");
  EXPECT_EQ(threads[1].name, "ec-control");
  EXPECT_EQ(threads[2].name, "ec-cyclic");
  const auto live = threadNames();
  for (const char* name : {"ec-sendrecv", "ec-control", "ec-cyclic", "sim-server"}) {
    EXPECT_EQ(live.count(name), 1u) << name;
  }
  if (driver.realtime()) {
    for (const auto& t : threads) EXPECT_EQ(t.policy, SCHED_FIFO) << t.name;
    EXPECT_EQ(threads[0].priority, o.sendReceivePriority);
    EXPECT_EQ(threads[1].priority, o.controlPriority);
    EXPECT_EQ(threads[2].priority, o.cyclicPriority);
    EXPECT_GT(threads[0].priority, threads[1].priority);
    EXPECT_GT(threads[1].priority, threads[2].priority);
  } else {
    for (const auto& t : threads) EXPECT_EQ(t.policy, SCHED_OTHER) << t.name;
    ASSERT_FALSE(driver.warnings().empty());
    EXPECT_NE(driver.warnings()[0].find("real-time scheduling not available"), std::string::npos)
        << driver.warnings()[0];
  }
  for (const auto& t : threads) EXPECT_EQ(t.cpus, std::vector<int>{0}) << t.name;
  EXPECT_TRUE(waitFor(
      driver, [](const master::RtSnapshot& s) { return s.cycles >= 50; }, 20));
  driver.stop();
  // Joined: the threads are gone, the simulator's server thread still runs.
  const auto after = threadNames();
  for (const char* name : {"ec-sendrecv", "ec-control", "ec-cyclic"}) {
    EXPECT_EQ(after.count(name), 0u) << name;
  }
  EXPECT_EQ(after.count("sim-server"), 1u);
  EXPECT_TRUE(driver.threads().empty());
  const auto s = driver.snapshot();
  EXPECT_EQ(s.failedCycles, 0u) << s.firstError;
  // Control after every cycle (controlPeriod 0): at most one step per cycle; a control
  // thread that wakes late steps once for the cycles it missed.
  EXPECT_LE(s.controlSteps, s.cycles);
  EXPECT_GE(s.controlSteps, driver.realtime() ? s.cycles * 9 / 10 : s.cycles / 2);
  EXPECT_TRUE(s.health.allOperational());
}

TEST_F(RtDriverThreadsTest, AnInvalidCpuIsAWarningNotAFailure) {
  auto o = options();
  o.cpu = CPU_SETSIZE;  // no such CPU
  master::RtDriver driver(*master_, o);
  ASSERT_TRUE(driver.start().ok());
  std::size_t pinWarnings = 0;
  for (const auto& w : driver.warnings()) {
    if (w.find("not pinned to CPU") != std::string::npos) ++pinWarnings;
  }
  EXPECT_EQ(pinWarnings, 3u);
  EXPECT_TRUE(waitFor(
      driver, [](const master::RtSnapshot& s) { return s.cycles >= 10; }, 20));
  driver.stop();
  EXPECT_EQ(driver.snapshot().failedCycles, 0u) << driver.snapshot().firstError;
}

TEST_F(RtDriverThreadsTest, ControlThreadBringsAPulledSlaveBackToOpWhileTheCycleRuns) {
  master::RtDriver driver(*master_, options());
  ASSERT_TRUE(driver.start().ok());
  ASSERT_TRUE(waitFor(
      driver, [](const master::RtSnapshot& s) { return s.cycles >= 100; }, 20));
  ASSERT_TRUE(driver.snapshot().events.empty()) << eventLog(driver.snapshot());
  // Pull the cable behind DO1: AI1 and Drive1 disappear.
  net_.onServer([](topology::Segment& segment) { segment.setLinkUp(kDo, 1, false); });
  EXPECT_TRUE(waitFor(
      driver,
      [](const master::RtSnapshot& s) {
        return hasEvent(s, MasterEventKind::kSlaveLost, kAi) &&
               hasEvent(s, MasterEventKind::kSlaveLost, kDrive);
      },
      20))
      << eventLog(driver.snapshot());
  const auto lost = driver.snapshot();
  EXPECT_EQ(lost.health.slaves[kDo].condition, SlaveCondition::kOperational);
  // The others keep cycling: once the loss is known the expectation adapts.
  const std::uint64_t failedWhenLost = lost.failedCycles;
  const std::uint64_t cyclesWhenLost = lost.cycles;
  ASSERT_TRUE(waitFor(
      driver, [&](const master::RtSnapshot& s) { return s.cycles >= cyclesWhenLost + 50; }, 20));
  EXPECT_LE(driver.snapshot().failedCycles, failedWhenLost + 1);
  net_.onServer([](topology::Segment& segment) { segment.setLinkUp(kDo, 1, true); });
  EXPECT_TRUE(waitFor(
      driver,
      [](const master::RtSnapshot& s) {
        return hasEvent(s, MasterEventKind::kSlaveRecovered, kAi) &&
               hasEvent(s, MasterEventKind::kSlaveRecovered, kDrive) && s.health.allOperational();
      },
      30))
      << eventLog(driver.snapshot());
  driver.stop();
  const auto s = driver.snapshot();
  EXPECT_EQ(simState(kAi), AlState::kOp);
  EXPECT_EQ(simState(kDrive), AlState::kOp);
  EXPECT_EQ(s.health.slavesLost, 2u);
  EXPECT_EQ(s.health.slavesRecovered, 2u);
  EXPECT_LE(s.controlSteps, s.cycles);
  EXPECT_GT(s.controlSteps, 0u);
}

TEST_F(RtDriverThreadsTest, SendReceiveAloneDoesNoHealthWork) {
  // The control thread steps once (after the first cycle), then not for an hour: the cable
  // pull shows as failed cycles, but nobody reads a status or reports the slaves lost,
  // because send/receive does only I/O.
  auto o = options();
  o.controlPeriod = 3600 * kNsPerSecond;
  master::RtDriver driver(*master_, o);
  ASSERT_TRUE(driver.start().ok());
  ASSERT_TRUE(waitFor(
      driver, [](const master::RtSnapshot& s) { return s.cycles >= 20; }, 20));
  net_.onServer([](topology::Segment& segment) { segment.setLinkUp(kDo, 1, false); });
  EXPECT_TRUE(waitFor(
      driver, [](const master::RtSnapshot& s) { return s.failedCycles >= 50; }, 30));
  driver.stop();
  const auto s = driver.snapshot();
  EXPECT_EQ(s.controlSteps, 1u);
  EXPECT_TRUE(s.events.empty()) << eventLog(s);
  EXPECT_EQ(s.health.slaves[kAi].condition, SlaveCondition::kOperational);  // nobody looked
  EXPECT_GE(s.statistics.wkcErrors, 50u);
  EXPECT_NE(s.firstError.find("working counter"), std::string::npos) << s.firstError;
  // The same master with control every cycle finds the loss at once.
  master::RtDriver again(*master_, options());
  ASSERT_TRUE(again.start().ok());
  EXPECT_TRUE(waitFor(
      again,
      [](const master::RtSnapshot& snap) {
        return hasEvent(snap, MasterEventKind::kSlaveLost, kAi);
      },
      20))
      << eventLog(again.snapshot());
  again.stop();
}

TEST_F(RtDriverThreadsTest, AnSdoPostedWhileRunningIsSteppedByTheControlThread) {
  master::RtDriver driver(*master_, options());
  master::SlaveInfo drive = master_->slaves()[kDrive];  // the task's own record
  ASSERT_TRUE(drive.hasCoe());
  EXPECT_FALSE(driver.post([](master::Master&, SimTime) { return false; }).ok());  // not running
  ASSERT_TRUE(driver.start().ok());
  ASSERT_TRUE(waitFor(
      driver, [](const master::RtSnapshot& s) { return s.cycles >= 20; }, 20));
  struct Outcome {
    Status status;
    std::vector<std::uint8_t> data;
    std::string thread;
    std::uint64_t steps{0};
  };
  std::promise<Outcome> promise;
  auto result = promise.get_future();
  auto sdo = std::make_shared<master::SdoTask>(master_->transport(), drive, nullptr);
  ASSERT_TRUE(driver
                  .post([sdo, &promise, started = false, steps = std::uint64_t{0}](
                            master::Master&, SimTime now) mutable {
                    ++steps;
                    if (!std::exchange(started, true)) {
                      (void)sdo->startUpload(0x1018, 1, false, now);  // identity: vendor id
                    }
                    if (sdo->step(now)) return true;
                    char name[16] = {};
                    pthread_getname_np(pthread_self(), name, sizeof(name));
                    promise.set_value({sdo->status(), sdo->data(), name, steps});
                    return false;
                  })
                  .ok());
  ASSERT_EQ(result.wait_for(std::chrono::seconds(20)), std::future_status::ready);
  const Outcome out = result.get();
  driver.stop();
  ASSERT_TRUE(out.status.ok()) << out.status.error().message();
  ASSERT_EQ(out.data.size(), 4u);
  EXPECT_EQ(readLe32(out.data, 0), drive.identity().vendorId);
  EXPECT_EQ(out.thread, "ec-control");
  EXPECT_GE(out.steps, 2u);  // a mailbox write and a read: at least two cycles
  const auto s = driver.snapshot();
  EXPECT_EQ(s.failedCycles, 0u) << s.firstError;  // the cycle went on meanwhile
}

}  // namespace
}  // namespace ecsim::testing
