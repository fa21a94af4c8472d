#include "tests/bench/floor_workload.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <memory>
#include <span>

#include "protocol/esc_blocks.hpp"
#include "protocol/frame.hpp"
#include "protocol/registers.hpp"
#include "slavesim/generic_slave.hpp"
#include "topology/segment.hpp"

namespace ecsim::bench {
namespace {

using Clock = std::chrono::steady_clock;

constexpr std::uint16_t kPingData = 32;  // 14 + 2 + 10 + 32 + 2 = 60 bytes, 64 with the FCS
// BM_CyclicFrame's process image and frame size (tests/bench/sim_bench.cpp).
constexpr std::uint16_t kBytesPerSlave = 8;
constexpr std::size_t kCycleFrameRoom = 1486 - 12 - 8;  // room left for the FRMW
constexpr std::uint16_t kOutputsAt = 0x1000;
constexpr std::uint16_t kInputsAt = 0x1100;
const MacAddress kMasterMac{0x10, 0, 0, 0, 0, 1};
// Larger than this machine's caches: writing it evicts what a frame would find cached, as
// the processes that run while a server sleeps between frames do.
constexpr std::size_t kEvictBytes = 32u << 20;

template <typename AddDatagrams>
FrameBytes frame(AddDatagrams&& add) {
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  FrameBuilder b(buf, EthernetHeader{kBroadcastMac, kMasterMac, std::nullopt, kEtherTypeEtherCat});
  add(b);
  auto len = b.finish();
  return {buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(len.ok() ? *len : 0)};
}

FrameBytes single(Command c, std::uint32_t address, std::vector<std::uint8_t> data) {
  return frame([&](FrameBuilder& b) { (void)b.add(c, 0, address, data); });
}

// Station addresses and the two FMMUs of each slave, as BM_CyclicFrame's configure().
std::vector<FrameBytes> cycleSetup(unsigned slaves) {
  std::vector<FrameBytes> out;
  for (unsigned i = 0; i < slaves; ++i) {
    const auto station = static_cast<std::uint16_t>(0x1001 + i);
    out.push_back(
        single(Command::kApwr,
               DatagramHeader::physical(static_cast<std::uint16_t>(-static_cast<int>(i)),
                                        reg::kConfiguredStationAddress.address),
               {static_cast<std::uint8_t>(station), static_cast<std::uint8_t>(station >> 8)}));
    for (unsigned dir = 0; dir < 2; ++dir) {  // FMMU0 outputs, FMMU1 inputs
      FmmuBlock f;
      f.logicalStart = i * kBytesPerSlave;
      f.length = kBytesPerSlave;
      f.physicalStart = dir == 0 ? kOutputsAt : kInputsAt;
      f.write = dir == 0;
      f.read = dir != 0;
      f.enable = true;
      const auto bytes = f.bytes();
      out.push_back(single(Command::kFpwr, DatagramHeader::physical(station, reg::fmmuChannel(dir)),
                           {bytes.begin(), bytes.end()}));
    }
  }
  return out;
}

std::vector<FrameBytes> cycleFrames(unsigned slaves) {
  std::vector<FrameBytes> out;
  const std::size_t image = std::size_t{slaves} * kBytesPerSlave;
  for (std::size_t off = 0; off < image; off += kCycleFrameRoom) {
    out.push_back(frame([&](FrameBuilder& b) {
      const auto len = static_cast<std::uint16_t>(std::min(kCycleFrameRoom, image - off));
      (void)b.add(Command::kLrw, 0, static_cast<std::uint32_t>(off), len);
      if (off == 0) {  // the DC distribution rides in the first frame of the cycle
        (void)b.add(Command::kFrmw, 0, DatagramHeader::physical(0x1001, reg::kSystemTime.address),
                    8);
      }
    }));
  }
  return out;
}

std::unique_ptr<topology::Segment> line(unsigned slaves) {
  auto seg = std::make_unique<topology::Segment>();
  for (unsigned i = 0; i < slaves; ++i) {
    seg->addSlave(slavesim::makeGenericSlave(fmt::format("Slave{}", i + 1), i + 1));
  }
  seg->wireLine();
  return seg;
}

}  // namespace

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

std::size_t indexOffset() {
  return kEthernetHeaderSize + 2 + 1;
}

std::optional<std::uint16_t> lastWkc(ConstBytes frame) {
  auto parsed = ConstEtherCatFrame::parse(frame);
  if (!parsed.ok() || parsed->datagramCount() == 0) return std::nullopt;
  return readLe16(frame, parsed->datagramsOffset() + parsed->datagramBytes() - 2);
}

Workload makeWorkload(const std::string& kind, unsigned slaves) {
  Workload w;
  if (kind == "brd") {
    w.cycle.push_back(single(Command::kBrd, 0, std::vector<std::uint8_t>(kPingData, 0)));
    w.servedWkc.push_back(static_cast<std::uint16_t>(slaves));  // every slave counts once
    return w;
  }
  if (kind != "cycle") return w;
  w.setup = cycleSetup(slaves);
  w.cycle = cycleFrames(slaves);
  auto seg = line(slaves);
  for (auto f : w.setup) (void)seg->processFrame(f, 0);
  for (auto f : w.cycle) {
    (void)seg->processFrame(f, 0);
    w.servedWkc.push_back(lastWkc(f).value_or(0));
  }
  return w;
}

InProcess measureInProcess(const std::string& kind, unsigned slaves) {
  const Workload w = makeWorkload(kind, slaves);
  auto segment = line(slaves);
  topology::Segment& seg = *segment;
  for (auto f : w.setup) (void)seg.processFrame(f, 0);
  std::vector<FrameBytes> frames = w.cycle;
  auto pass = [&](unsigned i) {
    const std::size_t k = i % frames.size();
    std::copy(w.cycle[k].begin(), w.cycle[k].end(), frames[k].begin());
    (void)seg.processFrame(frames[k], static_cast<SimTime>(i) * kNsPerUs);
  };
  auto timeLoop = [](auto&& body) {
    std::vector<double> perCall;
    for (int rep = 0; rep < 5; ++rep) {  // median of 5 runs of ~20 ms
      unsigned calls = 0;
      const auto start = Clock::now();
      auto now = start;
      while (now - start < std::chrono::milliseconds(20)) {
        for (int i = 0; i < 16; ++i) body(calls++);
        now = Clock::now();
      }
      perCall.push_back(std::chrono::duration<double, std::nano>(now - start).count() / calls);
    }
    return median(perCall);
  };
  InProcess r;
  r.frames = static_cast<double>(frames.size());
  r.frameNs = timeLoop(pass);
  std::vector<std::uint8_t> evict(kEvictBytes);
  std::vector<double> cold;
  for (unsigned i = 0; i < 200; ++i) {
    for (std::size_t at = 0; at < evict.size(); at += 64) evict[at] = static_cast<std::uint8_t>(i);
    const auto start = Clock::now();
    pass(i);
    cold.push_back(std::chrono::duration<double, std::nano>(Clock::now() - start).count());
  }
  r.coldFrameNs = median(cold);
  r.pollNs = timeLoop([&](unsigned i) { seg.pollSlaves(static_cast<SimTime>(i) * kNsPerUs); });
  return r;
}

}  // namespace ecsim::bench
