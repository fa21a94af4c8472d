// `ecsim demo`: the one-command tour. The demo network (examples/topologies/demo.xml) runs
// in-process on virtual time; our master brings every slave INIT -> PREOP -> SAFEOP -> OP
// through frames only (the same code that runs on a real interface), then runs cycles of 1 ms
// (3000 by default): it enables the first CiA 402 drive by the CiA 402 sequence (shutdown,
// switch on, enable operation) and moves it in cyclic synchronous position mode through a
// smooth move out and back (quintic polynomials, 5 turns each way, with a rest after each),
// while a running light plays on the digital outputs. Every frame at the master's cable is
// captured to demo.pcap, stamped with model time; demo.csv has per cycle the commanded and the
// actual position, the following error and the statusword; demo.gp plots it into demo.png
// with gnuplot. Everything is deterministic: the same run gives the same bytes.
//
// The following error in the CSV is the position commanded one cycle earlier minus the actual
// one: the inputs a frame brings were latched before the outputs of the same frame arrived, so
// they show the drive after it acted on the previous cycle's target.
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include "config/topology_file.hpp"
#include "link/memory_link.hpp"
#include "link/netns.hpp"
#include "link/pcap.hpp"
#include "master/bus.hpp"
#include "master/master.hpp"
#include "master/process_image.hpp"
#include "protocol/al_status.hpp"
#include "tools/ecsim/commands.hpp"
#include "topology/network_builder.hpp"
#include "topology/network_server.hpp"
#include "topology/pcap_cable_tap.hpp"
#include "tools/common/install_paths.hpp"

namespace ecsim::tools {
namespace {

struct DemoOptions {
  std::string out{"ecsim-demo"};
  std::string topology;
  unsigned cycles{3000};
};

constexpr std::uint32_t kEcsimVendor = 0x00000E5C;  // examples/esi/ecsim_devices.xml
constexpr std::uint32_t kDriveProduct = 0x00007201;
constexpr std::uint32_t kRobotDriveProduct = 0x00007211;
constexpr double kMoveCounts = 5.0 * 131072.0;  // 5 turns of the 17-bit encoder
constexpr std::int8_t kCyclicSyncPosition = 8;
constexpr unsigned kEnableCycles = 10;  // the enable sequence needs 3; the rest is a rest

// Smooth step 0 -> 1 with zero speed and acceleration at both ends (quintic polynomial).
double quintic(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return t * t * t * (10.0 + t * (-15.0 + 6.0 * t));
}

// The move: after the enable cycles, 40 % of the rest out, 10 % rest, 40 % back, 10 % rest.
double trajectory(unsigned cycle, unsigned cycles) {
  if (cycle < kEnableCycles || cycles <= kEnableCycles) return 0.0;
  const double span = static_cast<double>(cycles - kEnableCycles);
  const double t = static_cast<double>(cycle - kEnableCycles) / span;
  if (t < 0.4) return kMoveCounts * quintic(t / 0.4);
  if (t < 0.5) return kMoveCounts;
  if (t < 0.9) return kMoveCounts * (1.0 - quintic((t - 0.5) / 0.4));
  return 0.0;
}

// The first CiA 402 drive of ecsim's (ECS7201/ECS7211) and its process data by entry.
struct DemoAxis {
  std::size_t position{0};
  std::string name;
  std::optional<master::PdoVariable> controlword, target, mode, statusword, actual;

  static std::optional<DemoAxis> find(master::Master& m) {
    for (const auto& s : m.slaves()) {
      const auto& id = s.identity();
      if (id.vendorId != kEcsimVendor ||
          (id.productCode != kDriveProduct && id.productCode != kRobotDriveProduct)) {
        continue;
      }
      DemoAxis a;
      a.position = s.position;
      a.name = s.name;
      auto var = [&](const char* entry) -> std::optional<master::PdoVariable> {
        auto v = m.variable(std::to_string(s.position) + "." + entry);
        if (!v.ok()) return std::nullopt;
        return std::move(v).value();
      };
      a.controlword = var("0x6040:00");
      a.target = var("0x607A:00");
      a.mode = var("0x6060:00");
      a.statusword = var("0x6041:00");
      a.actual = var("0x6064:00");
      if (a.controlword && a.target && a.mode && a.statusword && a.actual) return a;
    }
    return std::nullopt;
  }

  // The controlword on the way to Operation enabled (0x..27 in the statusword's state bits):
  // fault reset, shutdown, switch on, enable operation.
  std::uint16_t nextControlword(std::uint16_t previous) const {
    const auto sw = statusword->get<std::uint16_t>();
    if ((sw & 0x004F) == 0x0008) return previous == 0x0080 ? 0x0000 : 0x0080;  // fault
    if ((sw & 0x006F) == 0x0021) return 0x0007;                                // ready
    if ((sw & 0x006F) == 0x0023 || (sw & 0x006F) == 0x0027) return 0x000F;     // on, enabled
    return 0x0006;
  }
};

const char* kPlot =
    R"(# gnuplot script written by `ecsim demo`; edit and rerun: gnuplot demo.gp
set datafile separator comma
set terminal pngcairo size 1000,750 font ',11'
set output 'demo.png'
set multiplot layout 2,1 title 'ecsim demo: CiA 402 drive in CSP, 1 ms cycle, through simulated EtherCAT frames'
set grid
set key left top
set ylabel 'position [turns]'
set format x ''
plot 'demo.csv' using 1:($2/131072) with lines lw 2 title 'commanded', \
     '' using 1:($3/131072) with lines lw 1 dt 2 title 'actual'
set format x '%g'
set xlabel 'time [s]'
set ylabel 'following error [counts]'
plot 'demo.csv' using 1:4 with lines title 'following error'
unset multiplot
)";

int runDemo(const DemoOptions& o) {
  std::filesystem::create_directories(o.out);
  const std::string pcapPath = (std::filesystem::path(o.out) / "demo.pcap").string();
  std::string topologyPath = o.topology;
  if (topologyPath.empty()) {
    auto demo = dataFile("topologies/demo.xml");
    if (!demo.ok()) {
      fmt::print(stderr, "ecsim demo: {}\n", demo.error().message());
      return 1;
    }
    topologyPath = demo->string();
  }
  auto config = loadTopologyFile(topologyPath);
  if (!config.ok()) {
    fmt::print(stderr, "ecsim demo: {}\n", config.error().message());
    return 1;
  }
  auto network = topology::buildNetwork(*config);
  if (!network.ok()) {
    fmt::print(stderr, "ecsim demo: {}\n", network.error().message());
    return 1;
  }
  topology::Segment& segment = *network->segment;
  auto writer = PcapWriter::open(pcapPath);
  if (!writer.ok()) {
    fmt::print(stderr, "ecsim demo: {}\n", writer.error().message());
    return 1;
  }
  // Model time 0 is 2000-01-01 (the DC epoch) in the capture: deterministic timestamps.
  topology::PcapCableTap tap(*writer, kDcEpochUnixNs);
  segment.setCableObserver(0, 0, &tap);

  auto [masterEnd, networkEnd] = MemoryLink::makePair(256);
  VirtualClock clock(kNsPerSecond);
  topology::ServerOptions serverOptions;
  serverOptions.idleWait = std::chrono::nanoseconds(0);
  topology::NetworkServer server(networkEnd, segment, clock, serverOptions);
  // The virtual bus steps the simulator whenever the master waits; a frame is back after
  // its modelled round trip.
  master::VirtualBus bus(clock, [&](SimTime) -> std::optional<SimTime> {
    const bool waiting = networkEnd.pending() > 0;
    const auto before = server.counters().framesAnswered;
    (void)server.step();
    if (waiting && server.counters().framesAnswered != before)
      return server.counters().lastRoundTrip;
    return std::nullopt;
  });
  master::Master m(masterEnd, bus);

  fmt::print("ecsim demo: network '{}' from {}\n", config->name, topologyPath);
  fmt::print("our master brings every slave to OP through frames only...\n\n");
  if (auto s = m.start(); !s.ok()) {
    fmt::print(stderr, "ecsim demo: start failed: {}\n", s.error().message());
    return 1;
  }
  fmt::print("{:>3}  {:>7}  {:>10}  {:>10}  {:>6}  {}\n", "pos", "station", "vendor", "product",
             "state", "name");
  for (const auto& s : m.slaves()) {
    fmt::print("{:>3}  {:#07x}  {:#010x}  {:#010x}  {:>6}  {}\n", s.position, s.station,
               s.identity().vendorId, s.identity().productCode,
               s.state() ? std::string(toString(*s.state())) : std::string("?"), s.name);
  }
  // A running light on the first 8-bit output variable block (the DO terminal).
  std::optional<std::size_t> lightByte;
  for (const auto& v : master::processVariables(m.layout())) {
    if (v.output && v.bitLength == 1 && v.bitOffset % 8 == 0 && v.index == 0x7000) {
      lightByte = v.bitOffset / 8;
      break;
    }
  }
  std::optional<DemoAxis> axis = DemoAxis::find(m);
  const auto dir = std::filesystem::path(o.out);
  std::ofstream csv(dir / "demo.csv");
  csv << "time_s,commanded,actual,following_error,statusword,outputs\n";
  std::int32_t origin = 0;
  std::int32_t previousTarget = 0;
  std::uint16_t controlword = 0;
  std::optional<unsigned> enabledAt;
  double maxFollowingError = 0.0;
  if (axis) {
    fmt::print("\n{} (position {}): CiA 402 enable, then a CSP move of 5 turns out and back\n",
               axis->name, axis->position);
    axis->mode->set(kCyclicSyncPosition);
    origin = axis->actual->get<std::int32_t>();
    previousTarget = origin;
  }
  const SimTime start = clock.now();
  for (unsigned c = 0; c < o.cycles; ++c) {
    std::uint8_t pattern = 0;
    if (lightByte) {
      pattern = static_cast<std::uint8_t>(1u << ((c / 50) % 8));  // a step every 50 ms
      (void)m.writeData(*lightByte, ConstBytes(&pattern, 1));
    }
    std::int32_t target = previousTarget;
    if (axis) {
      const bool enabled = (axis->statusword->get<std::uint16_t>() & 0x006F) == 0x0027;
      if (enabled && !enabledAt) enabledAt = c;
      controlword = axis->nextControlword(controlword);
      axis->controlword->set(controlword);
      target = enabledAt ? origin + static_cast<std::int32_t>(std::llround(
                                        trajectory(c - *enabledAt + kEnableCycles, o.cycles)))
                         : axis->actual->get<std::int32_t>();
      axis->target->set(target);
    }
    if (auto s = m.exchange(); !s.ok()) {
      fmt::print(stderr, "ecsim demo: cycle {}: {}\n", c, s.error().message());
    }
    if (axis) {
      const std::int32_t actual = axis->actual->get<std::int32_t>();
      const double error = static_cast<double>(previousTarget) - static_cast<double>(actual);
      if (enabledAt) maxFollowingError = std::max(maxFollowingError, std::abs(error));
      csv << fmt::format("{:.3f},{},{},{},{:#06x},{}\n", static_cast<double>(c + 1) * 1e-3,
                         target - origin, actual - origin, previousTarget - actual,
                         axis->statusword->get<std::uint16_t>(), pattern);
    }
    previousTarget = target;
    clock.set(start + static_cast<SimTime>(c + 1) * kNsPerMs);
  }
  csv.close();
  const auto& st = m.statistics();
  fmt::print(
      "\n{} cycles of 1 ms: {} WKC errors, {} lost frames; round trip min {:.1f} us, "
      "mean {:.1f} us, max {:.1f} us\n",
      st.cycles, st.wkcErrors, st.framesLost, static_cast<double>(st.roundTripMin) / 1e3,
      static_cast<double>(st.roundTripMean()) / 1e3, static_cast<double>(st.roundTripMax) / 1e3);
  bool plotted = false;
  if (axis) {
    const auto sw = axis->statusword->get<std::uint16_t>();
    if (enabledAt) {
      fmt::print(
          "{}: operation enabled after {} cycles; statusword {:#06x}; max following "
          "error {:.0f} counts ({:.2f} degrees)\n",
          axis->name, *enabledAt, sw, maxFollowingError, maxFollowingError / 131072.0 * 360.0);
    } else {
      fmt::print("{}: NOT enabled; statusword {:#06x}\n", axis->name, sw);
    }
    std::ofstream(dir / "demo.gp") << kPlot;
    auto plot = runCommand({"sh", "-c", "cd '" + dir.string() + "' && gnuplot demo.gp"});
    plotted = plot.ok() && plot->exitCode == 0;
    if (!plotted) {
      fmt::print(stderr, "ecsim demo: gnuplot failed ({}); demo.csv and demo.gp are in {}\n",
                 plot.ok() ? plot->output : plot.error().message(), o.out);
    }
  }
  if (auto s = m.stop(); !s.ok()) {
    fmt::print(stderr, "ecsim demo: stop: {}\n", s.error().message());
  }
  segment.setCableObserver(0, 0, nullptr);
  (void)writer->close();
  fmt::print("all slaves back in INIT; {} frames captured in {} (tshark -r {})\n",
             server.counters().framesAnswered * 2, pcapPath, pcapPath);
  if (axis) {
    fmt::print("wrote {}/demo.csv, demo.gp{}\n", o.out, plotted ? ", demo.png" : "");
  }
  const bool moved = !axis || enabledAt.has_value();
  return st.wkcErrors == 0 && st.framesLost == 0 && moved ? 0 : 1;
}

}  // namespace

CommandRunner addDemoCommand(CLI::App& app) {
  auto opts = std::make_shared<DemoOptions>();
  auto* cmd = app.add_subcommand("demo", "Run the one-command tour and print a summary");
  cmd->add_option("--out", opts->out, "Directory for the demo's files (pcap, CSV, plots)");
  cmd->add_option("--topology", opts->topology, "Network to tour (default: the demo network)");
  cmd->add_option("--cycles", opts->cycles, "Cyclic exchanges to run")
      ->check(CLI::Range(1u, 1000000u));
  return [opts] { return runDemo(*opts); };
}

}  // namespace ecsim::tools
