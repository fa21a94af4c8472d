// `ecsim replay CAPTURE [--topology FILE]`: feed the master's frames of a capture to a
// simulated network and report, frame by frame, where the answers differ from the recorded.
#include <fmt/core.h>

#include <optional>

#include "config/topology_file.hpp"
#include "link/pcap.hpp"
#include "tools/common/install_paths.hpp"
#include "tools/ecsim/commands.hpp"
#include "topology/network_builder.hpp"
#include "topology/replay.hpp"

namespace ecsim::tools {
namespace {

struct ReplayOptions {
  std::string capture;
  std::string topology;
  std::size_t show{40};
  std::optional<SimTime> timeOrigin;
  bool ignoreDcTime{false};
};

int runReplay(const ReplayOptions& o) {
  auto records = PcapReader::readAll(o.capture);
  if (!records.ok()) {
    fmt::print(stderr, "ecsim replay: {}\n", records.error().message());
    return 1;
  }
  std::string topologyPath = o.topology;
  if (topologyPath.empty()) {
    auto demo = dataFile("topologies/demo.xml");
    if (!demo.ok()) {
      fmt::print(stderr, "ecsim replay: {}\n", demo.error().message());
      return 1;
    }
    topologyPath = demo->string();
  }
  auto config = loadTopologyFile(topologyPath);
  if (!config.ok()) {
    fmt::print(stderr, "ecsim replay: {}\n", config.error().message());
    return 1;
  }
  auto network = topology::buildNetwork(*config);
  if (!network.ok()) {
    fmt::print(stderr, "ecsim replay: {}\n", network.error().message());
    return 1;
  }
  auto report = topology::replayCapture(*records, *network->segment, o.timeOrigin);
  if (!report.ok()) {
    fmt::print(stderr, "ecsim replay: {}\n", report.error().message());
    return 1;
  }
  const auto& r = *report;
  std::size_t shown = 0;
  std::size_t left = 0;
  for (const auto& d : r.differences) {
    if (o.ignoreDcTime && d.timeRegisters) continue;
    if (shown == o.show) {
      ++left;
      continue;
    }
    ++shown;
    fmt::print("{}\n", d.describe());
  }
  if (left > 0) fmt::print("... {} more differences\n", left);
  fmt::print(
      "\n{}: {} frames ({} not EtherCAT), {} from the master, {} unanswered in the capture\n"
      "datagrams compared {}: WKC differs {}, data differs {} (+{} only in DC time registers)\n",
      o.capture, r.framesInCapture, r.otherFrames, r.masterFrames, r.unanswered, r.datagrams,
      r.wkcMismatches, r.dataMismatches, r.timeDataMismatches);
  // A capture's DC times come from another clock (real silicon, or a network served in real
  // time): --ignore-dc-time judges the answers by working counter and the other data alone.
  const bool same = o.ignoreDcTime ? r.wkcMismatches == 0 && r.dataMismatches == 0 : r.identical();
  if (same && !r.identical()) {
    fmt::print("identical apart from the DC time registers (--ignore-dc-time)\n");
  } else {
    fmt::print("{}\n", same ? "identical" : "differences found");
  }
  return same ? 0 : 3;
}

}  // namespace

CommandRunner addReplayCommand(CLI::App& app) {
  auto opts = std::make_shared<ReplayOptions>();
  auto* cmd = app.add_subcommand("replay", "Replay a capture's master frames and compare answers");
  cmd->add_option("capture", opts->capture, "pcap or pcapng file")->required();
  cmd->add_option("--topology", opts->topology, "Topology to replay against (default: demo)");
  cmd->add_option("--show", opts->show, "Differences to print");
  cmd->add_option("--time-origin", opts->timeOrigin,
                  "Capture timestamp (ns) of simulation time 0; default: the first frame's. "
                  "Captures by ecsim serve/demo are stamped from 2000-01-01: 946684800000000000");
  cmd->add_flag("--ignore-dc-time", opts->ignoreDcTime,
                "Differences only in the DC time registers (0x0900-0x09FF) do not count: the "
                "capture's clocks were other clocks");
  return [opts] { return runReplay(*opts); };
}

}  // namespace ecsim::tools
