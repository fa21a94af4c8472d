// `ecsim study latency --out DIR`: round trip and minimum cycle per slave count, process-data
// size and shape (line, tree), with the simulator's own CPU cost; writes latency.csv, the
// gnuplot script latency.gp and latency.png. With --topology FILE the study of that network
// instead (tools/ecsim/study_network.hpp): modelled and measured, per cycle-time candidate.
#include <fmt/core.h>
#include <fmt/ranges.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "link/netns.hpp"
#include "tools/ecsim/commands.hpp"
#include "tools/ecsim/study_network.hpp"
#include "topology/latency_study.hpp"

namespace ecsim::tools {
namespace {

struct StudyOptions {
  std::string out{"latency-study"};
  std::size_t maxSlaves{1024};
  std::vector<unsigned> bytes{1, 8, 32};
  std::vector<std::string> shapes{"line", "tree"};
  SimTime processingNs{1000};
  SimTime forwardingNs{1000};
  double cableMetres{1.0};
  std::string preset;  // "published": the published EtherCAT figures instead of the sweep
  study::NetworkStudyOptions network;  // --topology FILE: that network instead of the sweep
  bool noMeasure{false};
};

// `--preset published`: each published figure with the network that reproduces it
// (topology::publishedFigures, docs/timing.md), into published.csv; fails when one is off by
// more than 10 %.
int runPublished(const StudyOptions& o) {
  std::filesystem::create_directories(o.out);
  std::ofstream csv(std::filesystem::path(o.out) / "published.csv");
  csv << "figure,network,slaves,bytes_per_slave,frame_bytes,modelled_round_trip_ns,published_ns,"
         "deviation_percent,closed_form_ns,source\n";
  RealClock cpu;
  bool allWithin = true;
  for (const auto& f : topology::publishedFigures()) {
    auto point = topology::runLatencyPoint(f.parameters, cpu);
    if (!point.ok()) {
      fmt::print(stderr, "ecsim study: {}: {}\n", f.name, point.error().message());
      return 1;
    }
    const double deviation =
        100.0 * (static_cast<double>(point->roundTripNs) - static_cast<double>(f.publishedNs)) /
        static_cast<double>(f.publishedNs);
    allWithin = allWithin && deviation > -10.0 && deviation < 10.0;
    csv << fmt::format(
        "\"{}\",\"{}\",{},{},{},{},{},{:.1f},{},\"{}\"\n", f.name, f.network, f.parameters.slaves,
        f.parameters.bytesPerSlave, point->frameBytes, point->roundTripNs, f.publishedNs, deviation,
        topology::closedFormLineRoundTrip(f.parameters, point->frameBytes), f.source);
    fmt::print("{:36} {:8.1f} us (published {:5.0f} us, {:+5.1f} %)  {}\n", f.name,
               static_cast<double>(point->roundTripNs) / 1000.0,
               static_cast<double>(f.publishedNs) / 1000.0, deviation, f.network);
  }
  fmt::print("wrote {}/published.csv\n", o.out);
  return allWithin ? 0 : 1;
}

const char* kPlot =
    R"(# gnuplot script written by `ecsim study latency`; edit and rerun: gnuplot latency.gp
set datafile separator comma
set key autotitle columnhead
set terminal pngcairo size 1000,650 font ',11'
set output 'latency.png'
set title 'Modelled EtherCAT round trip vs slave count (100 Mbit/s)'
set xlabel 'slaves'
set ylabel 'round trip [us]'
set logscale xy
set grid
set key left top
set style data linespoints
)";

int runStudy(const StudyOptions& o) {
  if (!o.network.topology.empty()) {
    if (!o.preset.empty()) {
      fmt::print(stderr, "ecsim study: give either --topology FILE or --preset, not both\n");
      return 2;
    }
    study::NetworkStudyOptions n = o.network;
    n.out = o.out;
    n.measure = !o.noMeasure;
    return study::runNetworkStudy(n);
  }
  if (o.preset == "published") return runPublished(o);
  if (!o.preset.empty()) {
    fmt::print(stderr, "ecsim study: unknown preset '{}' (published)\n", o.preset);
    return 2;
  }
  std::filesystem::create_directories(o.out);
  const auto dir = std::filesystem::path(o.out);
  std::ofstream csv(dir / "latency.csv");
  csv << "topology,slaves,bytes_per_slave,frame_bytes,frames_per_cycle,modelled_round_trip_ns,"
         "min_cycle_ns,sim_cpu_ns_per_cycle,closed_form_ns\n";
  RealClock cpu;
  const auto counts = topology::logSpacedCounts(o.maxSlaves);
  const std::size_t total = counts.size() * o.bytes.size() * o.shapes.size();
  std::size_t done = 0;
  std::vector<std::string> series;
  for (const auto& topo : o.shapes) {
    if (topo != "line" && topo != "tree") {
      fmt::print(stderr, "ecsim study: unknown shape '{}' (line, tree)\n", topo);
      return 2;
    }
    for (unsigned b : o.bytes) {
      series.push_back(fmt::format("{} {} B/slave", topo, b));
      for (std::size_t n : counts) {
        topology::StudyParameters p;
        p.topology =
            topo == "line" ? topology::StudyTopology::kLine : topology::StudyTopology::kTree;
        p.slaves = n;
        p.bytesPerSlave = static_cast<std::uint16_t>(b);
        p.processingDelayNs = o.processingNs;
        p.forwardingDelayNs = o.forwardingNs;
        p.cableMetres = o.cableMetres;
        p.repetitions = n >= 512 ? 5 : 20;
        auto point = topology::runLatencyPoint(p, cpu);
        if (!point.ok()) {
          fmt::print(stderr, "ecsim study: {}\n", point.error().message());
          return 1;
        }
        const bool closedForm =
            p.topology == topology::StudyTopology::kLine && point->framesPerCycle == 1;
        csv << fmt::format(
            "{},{},{},{},{},{},{},{:.0f},{}\n", topo, n, b, point->frameBytes,
            point->framesPerCycle, point->roundTripNs, point->minCycleNs, point->simCpuNsPerCycle,
            closedForm ? std::to_string(topology::closedFormLineRoundTrip(p, point->frameBytes))
                       : "");
        ++done;
        fmt::print("\r[{:3}/{}] {:4} {:5} slaves {:3} B: round trip {:9.1f} us, cpu {:8.1f} us{}",
                   done, total, topo, n, b, static_cast<double>(point->roundTripNs) / 1000.0,
                   point->simCpuNsPerCycle / 1000.0, point->wkcErrors ? "  WKC ERRORS" : "");
        std::fflush(stdout);
      }
    }
  }
  csv.close();
  fmt::print("\n");
  std::ofstream gp(dir / "latency.gp");
  gp << kPlot << "plot ";
  for (std::size_t i = 0; i < series.size(); ++i) {
    const auto& topo = o.shapes[i / o.bytes.size()];
    const unsigned b = o.bytes[i % o.bytes.size()];
    gp << (i ? ", \\\n     " : "")
       << fmt::format(
              "'latency.csv' using (strcol(1) eq '{}' && $3 == {} ? $2 : 1/0):($6/1000) title '{}'",
              topo, b, series[i]);
  }
  gp << "\n";
  gp.close();
  auto plot = runCommand({"sh", "-c", "cd '" + dir.string() + "' && gnuplot latency.gp"});
  if (!plot.ok() || plot->exitCode != 0) {
    fmt::print(stderr, "ecsim study: gnuplot failed ({}); CSV and script are in {}\n",
               plot.ok() ? plot->output : plot.error().message(), o.out);
    return 1;
  }
  fmt::print("wrote {}/latency.csv, latency.gp, latency.png\n", o.out);
  return 0;
}

}  // namespace

CommandRunner addStudyCommand(CLI::App& app) {
  auto opts = std::make_shared<StudyOptions>();
  auto* study = app.add_subcommand("study", "Timing studies of simulated networks");
  study->require_subcommand(1);
  auto* latency = study->add_subcommand("latency", "Round trip per slave count and data size");
  latency->add_option("--out", opts->out, "Output directory");
  latency->add_option("--max-slaves", opts->maxSlaves, "Largest slave count (log-spaced up to it)")
      ->check(CLI::Range(1, 4096));
  latency->add_option("--bytes", opts->bytes, "Process-data bytes per slave (in and out)")
      ->delimiter(',');
  latency->add_option("--shape", opts->shapes, "Sweep: line and/or tree")->delimiter(',');
  latency
      ->add_option("--topology", opts->network.topology,
                   "Study this network (topology or ENI file) instead of the sweep: modelled "
                   "and measured round trip, SYNC0 shift and jitter per cycle time")
      ->check(CLI::Validator(
          [](std::string& v) -> std::string {
            if (v == "line" || v == "tree") {
              return "'" + v + "' is a shape of the sweep: --shape " + v +
                     " (--topology takes a topology or ENI file)";
            }
            return std::filesystem::is_regular_file(v) ? "" : "no such file: " + v;
          },
          "FILE"));
  latency->add_option("--esi-dir", opts->network.esiDir, "ESI folder of an ENI's devices");
  latency
      ->add_option("--cycles-us", opts->network.cyclesUs,
                   "Cycle-time candidates in us (with --topology)")
      ->delimiter(',')
      ->check(CLI::PositiveNumber);
  latency
      ->add_option("--measure-seconds", opts->network.measureSeconds,
                   "Measurement per candidate (with --topology)")
      ->check(CLI::Range(0.05, 3600.0));
  latency->add_flag("--no-measure", opts->noMeasure,
                    "Model only: no veth measurement (needs no privileges)");
  latency->add_flag("!--no-dc", opts->network.dc, "Do not use distributed clocks");
  latency->add_option("--master-command", opts->network.masterCommand,
                      "Also measure this master, per candidate, in the namespace ({iface}, "
                      "{netns}, {cycle_us}, {seconds} replaced; `ecmaster --json cyclic` output "
                      "read)");
  latency->add_option("--processing-ns", opts->processingNs, "ESC processing delay");
  latency->add_option("--forwarding-ns", opts->forwardingNs, "ESC forwarding delay");
  latency->add_option("--cable", opts->cableMetres, "Cable length between slaves in metres");
  latency->add_option("--preset", opts->preset,
                      "'published': reproduce the published EtherCAT figures (published.csv)");
  return [opts] { return runStudy(*opts); };
}

}  // namespace ecsim::tools
