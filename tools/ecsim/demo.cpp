// `ecsim demo`: the one-command tour. The demo network (examples/topologies/demo.xml) runs
// in-process on virtual time; our master brings every slave INIT -> PREOP -> SAFEOP -> OP
// through frames only (the same code that runs on a real interface), runs 100 cycles of 1 ms
// with a running light on the digital outputs, and every frame at the master's cable is
// captured to demo.pcap, stamped with model time. Everything is deterministic: the same run
// gives the same bytes.
#include <fmt/core.h>

#include <filesystem>
#include <optional>
#include <string>

#include "config/topology_file.hpp"
#include "link/memory_link.hpp"
#include "link/pcap.hpp"
#include "master/bus.hpp"
#include "master/master.hpp"
#include "master/process_image.hpp"
#include "protocol/al_status.hpp"
#include "tools/ecsim/commands.hpp"
#include "topology/network_builder.hpp"
#include "topology/network_server.hpp"
#include "topology/pcap_cable_tap.hpp"

namespace ecsim::tools {
namespace {

struct DemoOptions {
  std::string out{"ecsim-demo"};
  std::string topology;
  unsigned cycles{100};
};

std::string defaultDemoTopology() {
  if (const char* dir = std::getenv("ECSIM_DATA_DIR")) {
    return (std::filesystem::path(dir) / "topologies" / "demo.xml").string();
  }
  const std::filesystem::path installed = ECSIM_INSTALLED_DATA_DIR "/topologies/demo.xml";
  if (std::filesystem::exists(installed)) return installed.string();
  return ECSIM_SOURCE_DATA_DIR "/topologies/demo.xml";
}

int runDemo(const DemoOptions& o) {
  std::filesystem::create_directories(o.out);
  const std::string pcapPath = (std::filesystem::path(o.out) / "demo.pcap").string();
  const std::string topologyPath = o.topology.empty() ? defaultDemoTopology() : o.topology;
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
  const SimTime start = clock.now();
  for (unsigned c = 0; c < o.cycles; ++c) {
    if (lightByte) {
      std::uint8_t pattern = static_cast<std::uint8_t>(1u << (c % 8));
      (void)m.writeData(*lightByte, ConstBytes(&pattern, 1));
    }
    if (auto s = m.exchange(); !s.ok()) {
      fmt::print(stderr, "ecsim demo: cycle {}: {}\n", c, s.error().message());
    }
    clock.set(start + static_cast<SimTime>(c + 1) * kNsPerMs);
  }
  const auto& st = m.statistics();
  fmt::print(
      "\n{} cycles of 1 ms: {} WKC errors, {} lost frames; round trip min {:.1f} us, "
      "mean {:.1f} us, max {:.1f} us\n",
      st.cycles, st.wkcErrors, st.framesLost, static_cast<double>(st.roundTripMin) / 1e3,
      static_cast<double>(st.roundTripMean()) / 1e3, static_cast<double>(st.roundTripMax) / 1e3);
  if (auto s = m.stop(); !s.ok()) {
    fmt::print(stderr, "ecsim demo: stop: {}\n", s.error().message());
  }
  segment.setCableObserver(0, 0, nullptr);
  (void)writer->close();
  fmt::print("all slaves back in INIT; {} frames captured in {} (tshark -r {})\n",
             server.counters().framesAnswered * 2, pcapPath, pcapPath);
  return st.wkcErrors == 0 && st.framesLost == 0 ? 0 : 1;
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
