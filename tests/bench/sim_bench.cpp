// Simulator CPU time per cyclic frame: an LRW carrying 8 bytes of outputs and 8 bytes of
// inputs per slave (inputs and outputs overlapping in the logical image, as TwinCAT maps
// them) plus the DC FRMW distribution, through lines of 10, 100 and 1000 slaves.
// Reports ns per cycle and ns per slave; compare with the modelled wire round trip. Also the
// time to parse and build a topology of 1,000 to 20,000 slaves (linear: the same per slave).
// BM_DriveNetwork: the robot6 example (six drives, two joints falling under gravity) stepped
// once per 1 ms cycle, without state files (0) and with one per drive (1), saved every 100 ms
// of simulated time while a joint moves: the cost of the periodic saves.
#include <benchmark/benchmark.h>

#include <unistd.h>

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "config/topology_file.hpp"
#include "protocol/frame.hpp"
#include "protocol/esc_blocks.hpp"
#include "protocol/registers.hpp"
#include "slavesim/generic_slave.hpp"
#include "topology/network_builder.hpp"
#include "topology/segment.hpp"

namespace ecsim {
namespace {

constexpr std::uint16_t kBytesPerSlave = 8;

void send(topology::Segment& seg, Command c, std::uint32_t address,
          std::vector<std::uint8_t> data) {
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  FrameBuilder b(buf, EthernetHeader{});
  (void)b.add(c, 0, address, data);
  auto len = b.finish();
  seg.processFrame(std::span(buf.data(), *len), 0);
}

void configure(topology::Segment& seg, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    const auto station = static_cast<std::uint16_t>(0x1001 + i);
    send(seg, Command::kApwr,
         DatagramHeader::physical(static_cast<std::uint16_t>(-static_cast<int>(i)),
                                  reg::kConfiguredStationAddress.address),
         {static_cast<std::uint8_t>(station), static_cast<std::uint8_t>(station >> 8)});
    for (int dir = 0; dir < 2; ++dir) {  // FMMU0 outputs -> 0x1000, FMMU1 inputs <- 0x1100
      FmmuBlock f;
      f.logicalStart = static_cast<std::uint32_t>(i * kBytesPerSlave);
      f.length = kBytesPerSlave;
      f.physicalStart = dir == 0 ? 0x1000 : 0x1100;
      f.write = dir == 0;
      f.read = dir != 0;
      f.enable = true;
      const auto bytes = f.bytes();
      send(seg, Command::kFpwr,
           DatagramHeader::physical(station, reg::fmmuChannel(static_cast<unsigned>(dir))),
           {bytes.begin(), bytes.end()});
    }
  }
}

void BM_CyclicFrame(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  topology::Segment seg;
  for (std::size_t i = 0; i < n; ++i)
    seg.addSlave(slavesim::makeGenericSlave("s", static_cast<std::uint32_t>(i)));
  seg.wireLine();
  configure(seg, n);
  // The image of 1000 slaves (8000 bytes) needs several frames: count all of them.
  const std::size_t perFrame = 1486 - 12 - 8;  // room left for the FRMW
  std::vector<std::array<std::uint8_t, kMaxFrameSize>> frames;
  std::vector<std::size_t> lengths;
  const std::size_t image = n * kBytesPerSlave;
  for (std::size_t off = 0; off < image; off += perFrame) {
    frames.emplace_back();
    FrameBuilder b(frames.back(), EthernetHeader{});
    auto len = static_cast<std::uint16_t>(std::min(perFrame, image - off));
    (void)b.add(Command::kLrw, 1, static_cast<std::uint32_t>(off), len);
    if (off == 0) {  // the DC distribution rides in the first frame of the cycle
      (void)b.add(Command::kFrmw, 1, DatagramHeader::physical(0x1001, reg::kSystemTime.address), 8);
    }
    lengths.push_back(*b.finish());
  }
  SimTime now = 0;
  SimTime roundTrip = 0;  // of the last frame of the cycle (frames are sent back to back)
  for (auto _ : state) {
    for (std::size_t k = 0; k < frames.size(); ++k) {
      auto out = seg.processFrame(std::span(frames[k].data(), lengths[k]), now);
      roundTrip = out.returnTime - now;
      benchmark::DoNotOptimize(out);
    }
    now += 1'000'000;
  }
  state.counters["slaves"] = static_cast<double>(n);
  state.counters["frames"] = static_cast<double>(frames.size());
  // CPU per slave per frame: every frame passes every slave, as on the wire.
  state.counters["per_slave_frame"] = benchmark::Counter(
      static_cast<double>(n * frames.size()),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["modelled_rtt_ns"] = static_cast<double>(roundTrip);
}
BENCHMARK(BM_CyclicFrame)->Arg(10)->Arg(100)->Arg(1000)->Unit(benchmark::kMicrosecond);

// Building a network is linear in its size (issue #21 item 9): a topology file of N generic
// slaves in a line, parsed and built. Compare the time per slave across N.
void BM_BuildTopology(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  std::string xml = "<Topology name=\"bench\">\n";
  for (std::size_t i = 0; i < n; ++i) xml += "<Slave name=\"S" + std::to_string(i) + "\"/>\n";
  xml += "</Topology>\n";
  for (auto _ : state) {
    auto config = parseTopology(xml, "bench.xml");
    auto net = topology::buildNetwork(*config);
    benchmark::DoNotOptimize(net.ok());
  }
  state.counters["ns_per_slave"] =
      benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate |
                                                     benchmark::Counter::kInvert);
}
BENCHMARK(BM_BuildTopology)->Arg(1000)->Arg(5000)->Arg(20000)->Unit(benchmark::kMillisecond);

// What building cost before: every link refreshed the DL status of every slave (quadratic;
// 20,000 slaves took 77 s). Kept to show the difference; nothing builds this way now.
void BM_WireLineRefreshingEverySlavePerLink(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  for (auto _ : state) {
    topology::Segment seg;
    for (std::size_t i = 0; i < n; ++i) {
      seg.addSlave(slavesim::makeGenericSlave("s", static_cast<std::uint32_t>(i)));
      seg.refreshLinkStatus();
    }
    for (std::size_t i = 1; i < n; ++i) {
      (void)seg.connect(i - 1, 1, i, 0);
      seg.refreshLinkStatus();
    }
  }
  state.counters["ns_per_slave"] =
      benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate |
                                                     benchmark::Counter::kInvert);
}
BENCHMARK(BM_WireLineRefreshingEverySlavePerLink)
    ->Arg(1000)
    ->Arg(5000)
    ->Unit(benchmark::kMillisecond);


void BM_DriveNetwork(benchmark::State& state) {
  auto config = loadTopologyFile(std::filesystem::path(ECSIM_SOURCE_DIR) /
                                 "examples/topologies/robot6.xml");
  if (!config.ok()) {
    state.SkipWithError(config.error().message().c_str());
    return;
  }
  const auto dir = std::filesystem::temp_directory_path() /
                   ("ecsim-bench-state-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::size_t files = 0;
  if (state.range(0) != 0) {
    for (auto& slave : config->slaves) {
      if (slave.name.size() == 2 && slave.name[0] == 'J') {
        slave.stateFile = dir / (slave.name + ".state");
        ++files;
      }
    }
  }
  {
    auto network = topology::buildNetwork(*config);
    if (!network.ok()) {
      state.SkipWithError(network.error().message().c_str());
      return;
    }
    std::array<std::uint8_t, kMaxFrameSize> frame{};
    FrameBuilder b(frame, EthernetHeader{});
    (void)b.add(Command::kBrd, 0, DatagramHeader::physical(0, reg::kAlStatus.address), 2);
    const std::size_t length = *b.finish();
    SimTime now = 0;
    for (auto _ : state) {
      auto out = network->segment->processFrame(std::span(frame.data(), length), now);
      benchmark::DoNotOptimize(out);
      network->segment->pollSlaves(now);  // the firmware step, as the server does after a frame
      now += 1'000'000;
    }
    state.counters["state_files"] = static_cast<double>(files);
  }
  std::filesystem::remove_all(dir);
}
BENCHMARK(BM_DriveNetwork)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace ecsim

BENCHMARK_MAIN();
