#include "tools/ecsim/study_network.hpp"

#include <fmt/core.h>
#include <unistd.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "config/eni.hpp"
#include "config/topology_file.hpp"
#include "link/memory_link.hpp"
#include "link/netns.hpp"
#include "master/master.hpp"
#include "protocol/registers.hpp"
#include "topology/network_builder.hpp"
#include "topology/network_from_eni.hpp"
#include "topology/network_server.hpp"
#include "topology/slave_names.hpp"

namespace ecsim::tools::study {
namespace {

// The columns of latency.csv; the plot refers to them by position.
constexpr std::array<const char*, 21> kColumns{"cycle_us",
                                               "modelled_round_trip_us",
                                               "modelled_wire_us",
                                               "modelled_min_cycle_us",
                                               "outputs_complete_us",
                                               "sync0_shift_us",
                                               "model_fits",
                                               "frames_per_cycle",
                                               "frame_bytes",
                                               "measured_cycles",
                                               "rtt_p50_us",
                                               "rtt_p99_us",
                                               "rtt_max_us",
                                               "jitter_p50_us",
                                               "jitter_p99_us",
                                               "jitter_max_us",
                                               "lost",
                                               "late",
                                               "overruns",
                                               "wkc_errors",
                                               "measured_fits"};

std::size_t column(std::string_view name) {
  for (std::size_t i = 0; i < kColumns.size(); ++i) {
    if (name == kColumns[i]) return i + 1;  // gnuplot counts from 1
  }
  return 0;
}

double us(SimTime ns) {
  return static_cast<double>(ns) / 1e3;
}

Result<TopologyConfig> loadConfig(const NetworkStudyOptions& o) {
  ECSIM_ASSIGN_OR_RETURN(const std::string root, xmlRootName(o.topology));
  if (root == "EtherCATConfig") {
    ECSIM_ASSIGN_OR_RETURN(EniConfig eni, loadEniFile(o.topology));
    const std::filesystem::path esi = o.esiDir.empty()
                                          ? std::filesystem::path(o.topology).parent_path()
                                          : std::filesystem::path(o.esiDir);
    return topology::topologyFromEni(eni, {esi});
  }
  return loadTopologyFile(o.topology);
}

// The master's cyclic frames in OP, as master/cyclic.cpp assembles them: the layout's
// datagrams by frame, and the reference clock's FRMW of 0x0910 after the first frame's
// datagrams unless the layout (an ENI's) has its own.
std::vector<topology::ModelFrame> cyclicFrames(const master::Master& m) {
  std::vector<topology::ModelFrame> frames;
  bool ownSystemTime = false;
  for (const auto& d : m.layout().datagrams) {
    if (!d.activeIn(AlState::kOp)) continue;
    if (frames.size() <= d.frame) frames.resize(d.frame + 1);
    frames[d.frame].push_back({d.command, d.logicalStart, d.length});
    ownSystemTime |= (d.command == Command::kFrmw || d.command == Command::kArmw) &&
                     (d.logicalStart >> 16) == reg::kSystemTime.address;
  }
  std::erase_if(frames, [](const auto& f) { return f.empty(); });
  const auto& ref = m.dcSetup().reference;
  if (ref && !ownSystemTime && !frames.empty()) {
    frames.front().push_back(
        {Command::kFrmw,
         DatagramHeader::physical(m.slaves()[*ref].station, reg::kSystemTime.address), 8});
  }
  return frames;
}

Error inFile(const NetworkStudyOptions& o, std::string_view what, const Error& e) {
  return makeError(e.code, fmt::format("{}: {}: {}", o.topology, what, e.context));
}

}  // namespace

bool isEniFile(const std::string& path) {
  auto root = xmlRootName(path);
  return root.ok() && *root == "EtherCATConfig";
}

Result<NetworkModel> modelNetwork(const NetworkStudyOptions& o) {
  auto loaded = loadConfig(o);
  if (!loaded.ok()) return loaded.takeError();
  const TopologyConfig config = std::move(loaded).value();
  ECSIM_ASSIGN_OR_RETURN(topology::Network net, topology::buildNetwork(config));
  topology::Segment& seg = *net.segment;

  VirtualClock clock{kNsPerSecond};
  auto links = MemoryLink::makePair(256);
  topology::ServerOptions serverOptions;
  serverOptions.idleWait = std::chrono::nanoseconds(0);
  topology::NetworkServer server(links.second, seg, clock, serverOptions);
  MemoryLink& serverEnd = links.second;
  master::VirtualBus bus(clock, [&](SimTime) -> std::optional<SimTime> {
    const bool waiting = serverEnd.pending() > 0;
    const auto before = server.counters().framesAnswered;
    (void)server.step();
    if (waiting && server.counters().framesAnswered != before) {
      return server.counters().lastRoundTrip;
    }
    return std::nullopt;
  });
  bool useDc = false;
  if (o.dc) {
    master::Master probe(links.first, bus);
    if (auto s = probe.scan(); !s.ok()) return inFile(o, "scan", s.error());
    for (const auto& s : probe.slaves()) useDc |= s.hasDc();
  }
  master::MasterOptions options;
  options.dc.enable = useDc;
  master::Master m(links.first, bus, options);
  m.setSlaveNames(topology::slaveNamesInBusOrder(config));
  // An ENI configures the master too: its identities, init commands and cyclic frames.
  if (isEniFile(o.topology)) {
    if (auto s = m.loadConfig(o.topology); !s.ok())
      return inFile(o, "master configuration", s.error());
  }
  if (auto s = m.start(); !s.ok()) return inFile(o, "bringing the network to OP", s.error());

  NetworkModel model;
  model.name =
      config.name.empty() ? std::filesystem::path(o.topology).stem().string() : config.name;
  model.outputBytes = m.layout().outputBytes;
  model.inputBytes = m.layout().inputBytes;
  model.frames = cyclicFrames(m);
  model.dc = m.dcSetup().reference.has_value();
  if (model.frames.empty()) {
    return makeError(ErrorCode::kInvalidArgument,
                     o.topology + ": no device has process data: there is no cycle to study");
  }
  const auto order = topology::busOrder(seg);
  for (std::size_t p = 0; p < order.size() && p < m.layout().slaves.size(); ++p) {
    const std::size_t i = order[p];
    const auto& type = seg.slave(i).esc().type();
    DeviceRow row;
    row.position = p;
    row.name = config.slaves[i].name;
    row.outputBytes = m.layout().slaves[p].outputBytes;
    row.inputBytes = m.layout().slaves[p].inputBytes;
    row.processingNs = config.slaves[i].processingDelayNs.value_or(type.processingDelayNs);
    row.forwardingNs = config.slaves[i].forwardingDelayNs.value_or(type.forwardingDelayNs);
    row.dc = p < m.slaves().size() && m.slaves()[p].hasDc();
    model.devices.push_back(std::move(row));
  }
  auto cycle =
      topology::modelCycle(seg, model.frames, clock.now() + kNsPerMs, config.masterCableMetres);
  if (!cycle.ok()) return inFile(o, "modelling the cycle", cycle.error());
  model.cycle = *cycle;
  return model;
}

Progress::Progress() : tty_(::isatty(STDERR_FILENO) == 1) {}

void Progress::update(const std::string& line, bool important) {
  if (tty_) {
    fmt::print(stderr, "\r{}\x1b[K", line);
    open_ = true;
  } else if (important) {
    fmt::print(stderr, "{}\n", line);
  }
  std::fflush(stderr);
}

void Progress::finish() {
  if (tty_ && open_) fmt::print(stderr, "\n");
  open_ = false;
}

SimTime sync0Shift(const NetworkModel& model, const MeasuredCycle* measured) {
  return model.cycle.outputsCompleteNs + (measured ? measured->jitterP99 : 0);
}

MeasuredCycle parseMasterJson(const std::string& output, SimTime cycleNs) {
  MeasuredCycle r;
  r.cycleNs = cycleNs;
  r.rttP50 = r.rttP99 = r.rttMax = r.jitterP50 = r.jitterP99 = r.jitterMax = -1;
  // The document is the whole output, or begins at the last line that starts with '{'.
  auto doc = nlohmann::json::parse(output, nullptr, false);
  for (std::size_t at = output.rfind("\n{"); doc.is_discarded() && at != std::string::npos;
       at = at == 0 ? std::string::npos : output.rfind("\n{", at - 1)) {
    doc = nlohmann::json::parse(output.substr(at + 1), nullptr, false);
  }
  if (doc.is_discarded() || !doc.is_object()) return r;
  const auto micros = [&](const char* group, const char* key, SimTime& into) {
    if (doc.contains(group) && doc[group].is_object() && doc[group].contains(key) &&
        doc[group][key].is_number()) {
      into = static_cast<SimTime>(doc[group][key].get<double>() * 1e3 + 0.5);
    }
  };
  const auto count = [&](const char* key, std::uint64_t& into) {
    if (doc.contains(key) && doc[key].is_number_unsigned()) into = doc[key].get<std::uint64_t>();
  };
  micros("roundTripUs", "p50", r.rttP50);
  micros("roundTripUs", "p99", r.rttP99);
  micros("roundTripUs", "max", r.rttMax);
  micros("jitterUs", "p50", r.jitterP50);
  micros("jitterUs", "p99", r.jitterP99);
  micros("jitterUs", "max", r.jitterMax);
  count("cycles", r.cycles);
  count("framesLost", r.lost);
  count("framesLate", r.late);
  count("overruns", r.overruns);
  count("wkcErrors", r.wkcErrors);
  return r;
}

std::string externalCsvHeader() {
  return "cycle_us,exit_code,cycles,rtt_p50_us,rtt_p99_us,rtt_max_us,jitter_p50_us,"
         "jitter_p99_us,jitter_max_us,lost,late,overruns,wkc_errors";
}

std::string externalCsvRow(double cycleUs, const MeasuredCycle& m) {
  const auto time = [](SimTime ns) {
    return ns < 0 ? std::string() : fmt::format("{:.3f}", us(ns));
  };
  return fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{}", cycleUs, m.exitCode, m.cycles,
                     time(m.rttP50), time(m.rttP99), time(m.rttMax), time(m.jitterP50),
                     time(m.jitterP99), time(m.jitterMax), m.lost, m.late, m.overruns, m.wkcErrors);
}

std::string csvHeader() {
  std::string h;
  for (const char* c : kColumns) h += (h.empty() ? "" : ",") + std::string(c);
  return h;
}

std::string csvRow(double cycleUs, const NetworkModel& model, const MeasuredCycle* m) {
  const auto& c = model.cycle;
  const double shift = us(sync0Shift(model, m));
  const bool modelFits = us(c.minCycleNs()) < cycleUs && us(c.outputsCompleteNs) < cycleUs;
  std::string row =
      fmt::format("{},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{},{},{}", cycleUs, us(c.roundTripNs),
                  us(c.wireNs), us(c.minCycleNs()), us(c.outputsCompleteNs), shift,
                  modelFits ? "yes" : "no", c.frames, c.frameBytes);
  if (m == nullptr) return row + ",,,,,,,,,,,,";
  const bool fits = m->cycles > 0 && m->lost == 0 && m->late == 0 && m->wkcErrors == 0 &&
                    m->overruns == 0 && us(m->rttMax) < cycleUs && shift < cycleUs;
  return row + fmt::format(",{},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{},{},{},{},{}",
                           m->cycles, us(m->rttP50), us(m->rttP99), us(m->rttMax), us(m->jitterP50),
                           us(m->jitterP99), us(m->jitterMax), m->lost, m->late, m->overruns,
                           m->wkcErrors, fits ? "yes" : "no");
}

std::string gnuplotScript(const NetworkModel& model, const std::vector<double>& cyclesUs,
                          bool measured, bool external) {
  const auto [lo, hi] = std::minmax_element(cyclesUs.begin(), cyclesUs.end());
  const double xmin = *lo / 1.3;
  const double xmax = *hi * 1.3;
  std::string s = fmt::format(
      "# gnuplot script written by `ecsim study latency --topology`; edit and rerun: gnuplot "
      "latency.gp\n"
      "set datafile separator comma\n"
      "set datafile columnheaders\n"
      "set terminal pngcairo size 1100,700 font ',11'\n"
      "set output 'latency.png'\n"
      "set title \"{}: {} devices, {} B out + {} B in, {} frame(s) of {} B per cycle{}\"\n"
      "set xlabel 'cycle time [us]'\n"
      "set ylabel 'time after the cycle starts [us]'\n"
      "set logscale xy\n"
      "set xrange [{:g}:{:g}]\n"
      "set grid\n"
      "set key left top box opaque\n",
      model.name, model.devices.size(), model.outputBytes, model.inputBytes, model.cycle.frames,
      model.cycle.frameBytes, model.dc ? ", DC" : "", xmin, xmax);
  std::string tics;
  for (double c : cyclesUs) tics += fmt::format("{}\"{:g}\" {:g}", tics.empty() ? "" : ", ", c, c);
  s += "set xtics (" + tics + ")\n";
  // Reference lines at the usual cycle times.
  int n = 0;
  for (const auto& [at, label] : std::array<std::pair<double, const char*>, 4>{
           {{1000, "1 ms"}, {500, "500 us"}, {250, "250 us"}, {125, "125 us"}}}) {
    if (at <= xmin || at >= xmax) continue;
    ++n;
    s += fmt::format(
        "set arrow {} from {:g}, graph 0 to {:g}, graph 1 nohead dt 2 lw 1.5 lc rgb '#999999'\n"
        "set label {} '{}' at {:g}, graph 0.03 offset 0.4,0 left textcolor rgb '#666666'\n",
        n, at, at, n, label, at);
  }
  s += fmt::format(
      "plot x title 'cycle time (a round trip must stay below)' with lines dt 3 lw 1.5 lc rgb "
      "'black', \\\n"
      "     'latency.csv' using {}:{} title 'modelled round trip' with linespoints lw 2 "
      "pt 7 lc rgb '#1f77b4', \\\n"
      "     '' using {}:{} title 'SYNC0 shift needed' with linespoints lw 2 pt 5 lc rgb "
      "'#2ca02c'",
      column("cycle_us"), column("modelled_round_trip_us"), column("cycle_us"),
      column("sync0_shift_us"));
  if (measured) {
    s += fmt::format(
        ", \\\n     '' using {0}:{1} title 'measured round trip p50' with linespoints "
        "lw 2 pt 9 lc rgb '#ff7f0e'"
        ", \\\n     '' using {0}:{2} title 'measured round trip p99' with linespoints "
        "lw 2 pt 11 lc rgb '#d62728'"
        ", \\\n     '' using {0}:{3} title 'measured round trip max' with linespoints "
        "lw 1 dt 2 pt 13 lc rgb '#d62728'"
        ", \\\n     '' using {0}:{4} title 'measured cycle jitter p99' with linespoints "
        "lw 1.5 pt 3 lc rgb '#9467bd'",
        column("cycle_us"), column("rtt_p50_us"), column("rtt_p99_us"), column("rtt_max_us"),
        column("jitter_p99_us"));
  }
  if (external) {  // external.csv: rtt_p99_us and rtt_max_us are its columns 5 and 6
    s += ", \\\n     'external.csv' using 1:5 title 'external master round trip p99' with "
         "linespoints lw 2 pt 6 lc rgb '#8c564b'"
         ", \\\n     '' using 1:6 title 'external master round trip max' with linespoints "
         "lw 1 dt 2 pt 6 lc rgb '#8c564b'";
  }
  return s + "\n";
}

int runNetworkStudy(const NetworkStudyOptions& o) {
  if (o.cyclesUs.empty()) {
    fmt::print(stderr, "ecsim study: --cycles-us needs at least one cycle time\n");
    return 2;
  }
  Progress progress;
  progress.update(fmt::format("modelling {}", o.topology), true);
  auto model = modelNetwork(o);
  if (!model.ok()) {
    progress.finish();
    fmt::print(stderr, "ecsim study: {}\n", model.error().context);
    return 1;
  }
  progress.finish();
  const auto& c = model->cycle;
  fmt::print("{}: {} devices, {} output + {} input bytes in {} frame(s) of {} bytes{}\n",
             model->name, model->devices.size(), model->outputBytes, model->inputBytes, c.frames,
             c.frameBytes, model->dc ? ", DC (FRMW of 0x0910 in the first frame)" : ", no DC");
  fmt::print(
      "modelled: round trip {:.2f} us, wire {:.2f} us, outputs complete at every slave "
      "{:.2f} us after the cycle starts\n",
      us(c.roundTripNs), us(c.wireNs), us(c.outputsCompleteNs));
  std::vector<MeasuredCycle> measured;
  std::vector<MeasuredCycle> external;
  if (o.measure) {
    auto m = measureNetwork(o, *model, progress);
    progress.finish();
    if (!m.ok()) {
      fmt::print(stderr, "ecsim study: measurement: {} (--no-measure: the model alone)\n",
                 m.error().message());
      return 1;
    }
    measured = std::move(m->ours);
    external = std::move(m->external);
  }
  const auto dir = std::filesystem::path(o.out);
  std::filesystem::create_directories(dir);
  {
    std::ofstream devices(dir / "devices.csv");
    devices
        << "position,name,output_bytes,input_bytes,processing_delay_ns,forwarding_delay_ns,dc\n";
    for (const auto& d : model->devices) {
      devices << fmt::format("{},\"{}\",{},{},{},{},{}\n", d.position, d.name, d.outputBytes,
                             d.inputBytes, d.processingNs, d.forwardingNs, d.dc ? "yes" : "no");
    }
    std::ofstream csv(dir / "latency.csv");
    csv << csvHeader() << "\n";
    for (std::size_t i = 0; i < o.cyclesUs.size(); ++i) {
      const MeasuredCycle* m = i < measured.size() ? &measured[i] : nullptr;
      csv << csvRow(o.cyclesUs[i], *model, m) << "\n";
      fmt::print("{:8g} us: SYNC0 shift {:7.2f} us", o.cyclesUs[i], us(sync0Shift(*model, m)));
      if (m != nullptr) {
        fmt::print(
            ", measured round trip p50 {:.1f} p99 {:.1f} max {:.1f} us, jitter p50 {:.1f} "
            "p99 {:.1f} max {:.1f} us, lost {}, late {}, overruns {}",
            us(m->rttP50), us(m->rttP99), us(m->rttMax), us(m->jitterP50), us(m->jitterP99),
            us(m->jitterMax), m->lost, m->late, m->overruns);
      }
      fmt::print("\n");
    }
    if (!external.empty()) {
      std::ofstream ext(dir / "external.csv");
      ext << externalCsvHeader() << "\n";
      for (std::size_t i = 0; i < external.size(); ++i) {
        ext << externalCsvRow(o.cyclesUs[i], external[i]) << "\n";
        const auto& e = external[i];
        fmt::print("{:8g} us: external master exit {}, {} cycles, round trip p99 {} max {} us\n",
                   o.cyclesUs[i], e.exitCode, e.cycles,
                   e.rttP99 < 0 ? "-" : fmt::format("{:.1f}", us(e.rttP99)),
                   e.rttMax < 0 ? "-" : fmt::format("{:.1f}", us(e.rttMax)));
      }
    }
    std::ofstream gp(dir / "latency.gp");
    gp << gnuplotScript(*model, o.cyclesUs, !measured.empty(), !external.empty());
  }
  auto plot = runCommand({"sh", "-c", "cd '" + dir.string() + "' && gnuplot latency.gp"});
  if (!plot.ok() || plot->exitCode != 0) {
    fmt::print(stderr, "ecsim study: gnuplot failed ({}); CSV and script are in {}\n",
               plot.ok() ? plot->output : plot.error().message(), o.out);
    return 1;
  }
  fmt::print("wrote {}/latency.csv, devices.csv, latency.gp, latency.png\n", o.out);
  return 0;
}

}  // namespace ecsim::tools::study
