// The master's own CPU time per cycle for 2, 10 and 100 slaves: Master::cycle() (cached LRW
// frames out, answers matched, inputs copied, WKC checked, health bookkeeping) against the
// in-process simulator over a MemoryLink on virtual time. The simulator runs inside the
// VirtualBus's waits; its share is timed separately (thread CPU time, so that other work on
// a shared machine does not count) and subtracted, so the counters say
//   total_ns   one cycle, master and simulator
//   sim_ns     the simulator serving the frames (Segment + NetworkServer)
//   master_ns  total_ns - sim_ns: what a real master would spend on its CPU
// The slaves are SII-only I/O terminals (4 output bytes, 2 input words each), as in
// tests/master/acceptance_test.cpp. Run: build/<preset>/tests/bench/master_bench
#include <benchmark/benchmark.h>

#include <time.h>

#include <chrono>
#include <memory>

#include "link/memory_link.hpp"
#include "master/master.hpp"
#include "protocol/sii.hpp"
#include "slavesim/esc_type.hpp"
#include "slavesim/slave.hpp"
#include "topology/network_server.hpp"
#include "topology/segment.hpp"

namespace ecsim {
namespace {

// CPU time of this thread: the machine may be shared, wall time would count the others.
std::int64_t threadCpuNs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// An I/O terminal described only by its SII (what an EL2004/EL1004 class device shows).
std::unique_ptr<slavesim::Slave> makeIo(std::uint32_t product) {
  SiiContents c;
  c.config.pdiControl = 0x0004;
  c.identity = {0x00000E5C, product, 1, 0};
  c.sizeField = siiSizeFieldForBytes(2048);
  c.strings = {"IO", "Outputs", "Inputs"};
  SiiGeneral g;
  g.nameIndex = 1;
  g.physicalPorts = 0x0011;
  c.general = g;
  c.fmmus = {SiiFmmuUsage::kOutputs, SiiFmmuUsage::kInputs};
  c.syncManagers = {
      {0x1000, 4, 0x64, 0, SiiSyncManagerEnable::kEnable, SiiSyncManagerType::kOutputs},
      {0x1100, 4, 0x20, 0, SiiSyncManagerEnable::kEnable, SiiSyncManagerType::kInputs}};
  SiiPdo rx;
  rx.index = 0x1600;
  rx.syncManager = 0;
  rx.nameIndex = 2;
  for (std::uint8_t i = 1; i <= 4; ++i) rx.entries.push_back({0x7000, i, 0, 0x05, 8, 0});
  SiiPdo tx;
  tx.index = 0x1A00;
  tx.syncManager = 1;
  tx.nameIndex = 3;
  for (std::uint8_t i = 1; i <= 2; ++i) tx.entries.push_back({0x6000, i, 0, 0x06, 16, 0});
  c.rxPdos = {rx};
  c.txPdos = {tx};
  slavesim::SlaveProfile profile;
  profile.processData.push_back({0, true, 4});
  profile.processData.push_back({1, false, 4});
  auto image = encodeSii(c);
  return std::make_unique<slavesim::Slave>("IO", slavesim::kEt1100,
                                           image.ok() ? *image : std::vector<std::uint8_t>{},
                                           std::move(profile));
}

class Bench {
 public:
  explicit Bench(std::size_t slaves) : links_(MemoryLink::makePair(256)) {
    for (std::size_t i = 0; i < slaves; ++i) {
      segment_.addSlave(makeIo(0x3000 + static_cast<std::uint32_t>(i)));
    }
    segment_.wireLine();
    topology::ServerOptions options;
    options.idleWait = std::chrono::nanoseconds(0);
    server_ = std::make_unique<topology::NetworkServer>(links_.second, segment_, clock_, options);
    bus_ = std::make_unique<master::VirtualBus>(clock_, [this](SimTime) { return serve(); });
    master_ = std::make_unique<master::Master>(links_.first, *bus_);
  }
  master::Master& master() { return *master_; }
  VirtualClock& clock() { return clock_; }
  master::Bus& bus() { return *bus_; }
  std::int64_t simTime{0};  // thread CPU ns spent in the simulator

 private:
  std::optional<SimTime> serve() {
    const auto t0 = threadCpuNs();
    const bool waiting = links_.second.pending() > 0;
    const auto before = server_->counters().framesAnswered;
    (void)server_->step();
    std::optional<SimTime> rtt;
    if (waiting && server_->counters().framesAnswered != before) {
      rtt = server_->counters().lastRoundTrip;
    }
    simTime += threadCpuNs() - t0;
    return rtt;
  }

  VirtualClock clock_;
  topology::Segment segment_;
  std::pair<MemoryLink, MemoryLink> links_;
  std::unique_ptr<topology::NetworkServer> server_;
  std::unique_ptr<master::VirtualBus> bus_;
  std::unique_ptr<master::Master> master_;
};

void BM_MasterCycle(benchmark::State& state) {
  Bench bench(static_cast<std::size_t>(state.range(0)));
  if (auto s = bench.master().start(); !s.ok()) {
    state.SkipWithError(s.error().message().c_str());
    return;
  }
  std::vector<std::uint8_t> outputs(bench.master().layout().outputBytes);
  std::uint64_t cycles = 0;
  std::uint64_t failed = 0;
  bench.simTime = 0;
  const auto t0 = threadCpuNs();
  for (auto _ : state) {
    outputs[0] = static_cast<std::uint8_t>(cycles);
    (void)bench.master().writeData(0, outputs);
    if (!bench.master().cycle().ok()) ++failed;
    ++cycles;
    // Virtual time moves to the next period: the simulator's firmware runs there too.
    const SimTime next = bench.clock().now() + kNsPerMs;
    while (bench.clock().now() < next) bench.bus().wait(next);
  }
  const double total = static_cast<double>(threadCpuNs() - t0) / static_cast<double>(cycles);
  const double sim = static_cast<double>(bench.simTime) / static_cast<double>(cycles);
  state.counters["total_ns"] = total;
  state.counters["sim_ns"] = sim;
  state.counters["master_ns"] = total - sim;
  state.counters["master_ns_per_slave"] = (total - sim) / static_cast<double>(state.range(0));
  state.counters["frames"] = static_cast<double>(bench.master().layout().frameCount);
  state.counters["failed"] = static_cast<double>(failed);
}
BENCHMARK(BM_MasterCycle)->Arg(2)->Arg(10)->Arg(100)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace ecsim

BENCHMARK_MAIN();
