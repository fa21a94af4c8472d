// Zero heap allocations in the cyclic path, proved by counting: global operator new and
// delete are replaced in this test binary only (its own executable, so no other test sees
// the replacement). After a warm-up, thousands of cycles on the demo network (coupler, DI1,
// DO1, AI1, Drive1 from examples/esi/ecsim_devices.xml) in-process on virtual time allocate
// nothing while nothing goes wrong:
//   - Master::cycle(), health and its routine status reads every 100 cycles included;
//   - the same cycle in the driver's steps: sendCycle, pollCycle, finishCycle, control;
//   - the real-time driver's send/receive and cyclic threads, counted by thread name.
// The simulator's share is not the master's: the Bus the master waits on is wrapped so that
// nothing allocated while it serves the network is counted (a thread-local pause). The master
// sends on the MemoryLink itself (SimNetwork's FaultLink records every frame's size, which
// allocates: it is a test's decorator, not the master).
#include <gtest/gtest.h>
#include <sys/prctl.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <new>
#include <thread>

#include "link/memory_link.hpp"
#include "master/master.hpp"
#include "master/rt_driver.hpp"
#include "tests/master/bring_up.hpp"
#include "topology/network_server.hpp"

namespace {
std::atomic<bool> gCounting{false};  // count every allocation (one thread runs)
std::atomic<std::uint64_t> gAllocations{0};
std::atomic<bool> gByThread{false};  // count the driver's threads' allocations by name
std::atomic<std::uint64_t> gSendReceive{0};
std::atomic<std::uint64_t> gCyclic{0};
std::atomic<std::uint64_t> gControl{0};
thread_local bool tPaused = false;  // this thread is serving the simulator

void count() {
  if (tPaused) return;
  if (gCounting.load(std::memory_order_relaxed)) gAllocations.fetch_add(1);
  if (!gByThread.load(std::memory_order_relaxed)) return;
  char name[16] = {};
  prctl(PR_GET_NAME, name, 0, 0, 0);
  if (std::strcmp(name, "ec-sendrecv") == 0) gSendReceive.fetch_add(1);
  if (std::strcmp(name, "ec-cyclic") == 0) gCyclic.fetch_add(1);
  if (std::strcmp(name, "ec-control") == 0) gControl.fetch_add(1);
}
}  // namespace

void* operator new(std::size_t size) {
  count();
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) {
  return ::operator new(size);
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  count();
  return std::malloc(size == 0 ? 1 : size);
}
void* operator new[](std::size_t size, const std::nothrow_t& tag) noexcept {
  return ::operator new(size, tag);
}
// Every non-aligned form of new and delete is replaced, so that allocation and release always
// pair malloc with free, also under AddressSanitizer. Aligned forms stay the library's.
// (g++ cannot see that the replaced operator new above mallocs, hence the pragma.)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}
#pragma GCC diagnostic pop

namespace ecsim::testing {
namespace {

class Counting {
 public:
  Counting() { gCounting = true; }
  ~Counting() { gCounting = false; }
};

// The demo network on virtual time: the master on one end of a MemoryLink, a NetworkServer
// on the other, served inside the master's bus waits, where nothing allocated is counted.
class VirtualNetwork {
 public:
  VirtualNetwork()
      : links_(MemoryLink::makePair(256)), bus_(clock_, [this](SimTime) {
          tPaused = true;
          auto roundTrip = serveOne();
          tPaused = false;
          return roundTrip;
        }) {}
  topology::Segment& segment() { return segment_; }
  void start() {
    topology::ServerOptions options;
    options.idleWait = std::chrono::nanoseconds(0);
    server_ = std::make_unique<topology::NetworkServer>(links_.second, segment_, clock_, options);
  }
  Link& masterLink() { return links_.first; }
  master::Bus& bus() { return bus_; }

 private:
  std::optional<SimTime> serveOne() {
    const bool waiting = links_.second.pending() > 0;
    const auto before = server_->counters().framesAnswered;
    (void)server_->step();
    if (waiting && server_->counters().framesAnswered != before) {
      return server_->counters().lastRoundTrip;
    }
    return std::nullopt;
  }

  VirtualClock clock_;
  topology::Segment segment_;
  std::pair<MemoryLink, MemoryLink> links_;
  std::unique_ptr<topology::NetworkServer> server_;
  master::VirtualBus bus_;
};

constexpr int kWarmUp = 1000;
constexpr int kCycles = 10000;

class CycleAllocTest : public ::testing::Test {
 protected:
  void SetUp() override {
    addDemoSlaves(net_, 1);
    net_.start();
    master_ = std::make_unique<master::Master>(net_.masterLink(), bus_);
    auto status = master_->start();
    ASSERT_TRUE(status.ok()) << status.error().message();
    for (int i = 0; i < kWarmUp; ++i) {
      ASSERT_TRUE(master_->cycle().ok());
      waitForNextPeriod();
    }
    ASSERT_TRUE(master_->events().empty());
    startCycles_ = master_->statistics().cycles;
    gAllocations = 0;
  }
  void waitForNextPeriod() {
    const SimTime next = start_ + kNsPerMs;
    while (bus_.now() < next) bus_.wait(next);
    start_ = bus_.now();
  }
  std::string eventLog() const { return testing::eventLog(master_->events()); }

  VirtualNetwork net_;
  master::Bus& bus_{net_.bus()};
  std::unique_ptr<master::Master> master_;
  SimTime start_{0};
  std::uint64_t startCycles_{0};
};

TEST_F(CycleAllocTest, MasterCycleAllocatesNothing) {
  std::uint64_t failed = 0;
  std::array<std::uint8_t, 1> out{};
  for (int i = 0; i < kCycles; ++i) {
    out[0] = static_cast<std::uint8_t>(i);
    {
      Counting on;
      (void)master_->writeData(0, out);
      if (!master_->cycle().ok()) ++failed;
    }
    waitForNextPeriod();
  }
  EXPECT_EQ(gAllocations.load(), 0u) << "heap allocations in " << kCycles << " cycles";
  EXPECT_EQ(failed, 0u);
  EXPECT_TRUE(master_->events().empty()) << eventLog();
  // The routine AL status reads ran meanwhile (every 100 cycles): they were counted too.
  EXPECT_GE(master_->transport().counters().datagramsSent,
            static_cast<std::uint64_t>((kWarmUp + kCycles) / 100 * 5));
  EXPECT_EQ(master_->statistics().wkcErrors, 0u);
}

TEST_F(CycleAllocTest, DriverStepsAllocateNothing) {
  std::uint64_t failed = 0;
  master::Transport& transport = master_->transport();
  for (int i = 0; i < kCycles; ++i) {
    SimTime now = bus_.now();
    bool pending = false;
    {
      Counting on;
      if (!master_->sendCycle(now).ok()) ++failed;
      pending = master_->pollCycle(now);
    }
    while (pending) {
      SimTime next = now + transport.options().timeout;
      if (auto t = transport.nextDeadline()) next = std::min(next, *t);
      bus_.wait(next);
      now = bus_.now();
      Counting on;
      pending = master_->pollCycle(now);
    }
    {
      Counting on;
      if (!master_->finishCycle().ok()) ++failed;
      master_->control(now);
    }
    waitForNextPeriod();
  }
  EXPECT_EQ(gAllocations.load(), 0u) << "heap allocations in " << kCycles << " cycles";
  EXPECT_EQ(failed, 0u);
  EXPECT_TRUE(master_->events().empty()) << eventLog();
  EXPECT_EQ(master_->statistics().cycles, startCycles_ + kCycles);
}

TEST_F(CycleAllocTest, DriverSendReceiveAndCyclicThreadsAllocateNothing) {
  master::RtDriverOptions options;
  options.period = kNsPerMs;
  options.lockMemory = false;
  options.snapshotPeriod = 10 * kNsPerMs;
  master::RtDriver driver(*master_, options);
  std::atomic<std::uint64_t> calls{0};
  ASSERT_TRUE(driver
                  .start([&](master::Master& m, std::uint64_t cycle) {
                    const std::array<std::uint8_t, 1> out{static_cast<std::uint8_t>(cycle)};
                    (void)m.writeData(0, out);
                    ++calls;
                  })
                  .ok());
  // Warm-up: the threads' first cycles (and the first status reads) before counting.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (driver.snapshot().cycles < 200 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  const std::uint64_t before = calls.load();
  gSendReceive = gCyclic = gControl = 0;
  gByThread = true;
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  gByThread = false;
  const std::uint64_t counted = calls.load() - before;
  driver.stop();
  const auto s = driver.snapshot();
  EXPECT_GE(counted, 50u) << "too few cycles while counting (a loaded machine?)";
  EXPECT_EQ(gSendReceive.load(), 0u) << "allocations in send/receive over " << counted << " cycles";
  EXPECT_EQ(gCyclic.load(), 0u) << "allocations in the cyclic task over " << counted << " cycles";
  // The control thread copies snapshots for the non-real-time world: that allocates.
  std::printf("control thread: %llu allocations over %llu cycles (snapshots)\n",
              static_cast<unsigned long long>(gControl.load()),
              static_cast<unsigned long long>(counted));
  EXPECT_EQ(s.failedCycles, 0u) << s.firstError;
  EXPECT_TRUE(s.events.empty());
  EXPECT_GT(s.controlSteps, 0u);
}

TEST(CycleAllocCounterTest, CatchesAnAllocation) {
  // The counting itself works, globally and by thread name (so the tests above can fail).
  gAllocations = 0;
  {
    Counting on;
    void* p = ::operator new(16);  // a direct call: a new-expression may be elided
    ::operator delete(p);
  }
  EXPECT_EQ(gAllocations.load(), 1u);
  gSendReceive = 0;
  gByThread = true;
  std::thread t([] {
    prctl(PR_SET_NAME, "ec-sendrecv", 0, 0, 0);
    void* p = ::operator new(16);
    ::operator delete(p);
  });
  t.join();
  gByThread = false;
  EXPECT_EQ(gSendReceive.load(), 1u);
  // ... and a paused thread (serving the simulator) is not counted.
  gAllocations = 0;
  {
    Counting on;
    tPaused = true;
    void* p = ::operator new(16);
    ::operator delete(p);
    tPaused = false;
  }
  EXPECT_EQ(gAllocations.load(), 0u);
}

}  // namespace
}  // namespace ecsim::testing
