// The measured curve of `ecsim study latency --topology FILE`: our master (the Master library,
// as ecmaster runs it) over a veth pair in a private network namespace against
// `ecsim serve --paced` of the same file, which answers each frame at its modelled return time.
// The network is brought to OP once; each cycle-time candidate then runs for
// --measure-seconds with fresh statistics: round trip of every frame, start-to-start cycle
// jitter (master/histogram.hpp), lost and late frames, overruns (a cycle that ended after the
// next should have begun). The namespace, the pair and the server are removed on every path.
#include <fmt/core.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <thread>

#include "link/netns.hpp"
#include "link/raw_socket_link.hpp"
#include "link/realtime.hpp"
#include "link/signal_flag.hpp"
#include "master/master.hpp"
#include "tools/ecsim/study_network.hpp"
#include "topology/slave_names.hpp"

namespace ecsim::tools::study {
namespace {

constexpr auto kServerStartTimeout = std::chrono::seconds(20);
constexpr int kMasterPriority = 50;  // SCHED_FIFO, below ecsim serve --rt's server
constexpr SimTime kProgressEvery = 250 * kNsPerMs;
// The per-try frame timeout of the bring-up, which is not what is measured. A frame can wait
// several ms on a busy or virtual host (on a 2-core VM the wake-up of an idle CPU by the
// server's answer was traced at 8.6 ms), and one frame of the ~16,000 of a DC bring-up lost
// after its three 2 ms tries aborted the whole study. The measured cycles keep the master's
// own timeout; what they lose is counted in the `lost` column.
constexpr SimTime kBringUpFrameTimeout = 50 * kNsPerMs;
// An external master may take this long beyond its cycles (scan, bring-up, stop).
constexpr std::chrono::seconds kExternalGrace{60};

std::string readWhole(const std::filesystem::path& p) {
  std::ifstream in(p);
  return {std::istreambuf_iterator<char>(in), {}};
}

// Waits until the server says it serves (its socket is open), or fails with its output.
Status waitForServer(const std::filesystem::path& log, ChildProcess& server,
                     const SignalFlag& stop) {
  const auto until = std::chrono::steady_clock::now() + kServerStartTimeout;
  while (std::chrono::steady_clock::now() < until && !stop.raised()) {
    if (readWhole(log).find("ecsim: serving") != std::string::npos) return okStatus();
    if (!server.running()) {
      return makeError(ErrorCode::kState, "ecsim serve stopped: " + readWhole(log));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return makeError(ErrorCode::kTimeout, "ecsim serve did not start: " + readWhole(log));
}

Result<MeasuredCycle> runCandidate(master::Master& m, master::Bus& bus, double cycleUs,
                                   double seconds, const SignalFlag& stop, Progress& progress) {
  const auto cycle = static_cast<SimTime>(cycleUs * static_cast<double>(kNsPerUs));
  const auto duration = static_cast<SimTime>(seconds * static_cast<double>(kNsPerSecond));
  m.setCycleTime(cycle);
  m.resetStatistics();
  const master::MasterHealth base = m.health();
  MeasuredCycle r;
  r.cycleNs = cycle;
  const SimTime start = bus.now();
  SimTime next = start;
  SimTime nextProgress = start + kProgressEvery;
  while (!stop.raised() && bus.now() - start < duration) {
    (void)m.cycle();  // lost frames and WKC errors are counted in the statistics
    ++r.cycles;
    next += cycle;
    if (bus.now() > next) {
      ++r.overruns;
      next = bus.now();
    }
    if (bus.now() >= nextProgress) {
      nextProgress += kProgressEvery;
      const auto& st = m.statistics();
      progress.update(
          fmt::format("measuring {:g} us: {:.1f}/{:.1f} s, {} cycles, round trip p99 "
                      "{:.1f} us, jitter p99 {:.1f} us",
                      cycleUs, static_cast<double>(bus.now() - start) / 1e9, seconds, r.cycles,
                      static_cast<double>(st.roundTrip.p99()) / 1e3,
                      static_cast<double>(st.jitter.p99()) / 1e3));
    }
    while (bus.now() < next && !stop.raised()) bus.wait(next);
  }
  if (stop.raised()) return makeError(ErrorCode::kAborted, "interrupted");
  const auto& st = m.statistics();
  r.rttP50 = st.roundTrip.percentile(0.5);
  r.rttP99 = st.roundTrip.p99();
  r.rttMax = st.roundTrip.max();
  r.jitterP50 = st.jitter.percentile(0.5);
  r.jitterP99 = st.jitter.p99();
  r.jitterMax = st.jitter.max();
  r.wkcErrors = st.wkcErrors;
  const auto h = m.health();
  r.lost = h.framesLost - base.framesLost;
  r.late = h.framesLate - base.framesLate;
  return r;
}

std::string substitute(std::string text, std::string_view key, const std::string& value) {
  for (std::size_t at = text.find(key); at != std::string::npos;
       at = text.find(key, at + value.size())) {
    text.replace(at, key.size(), value);
  }
  return text;
}

// Our master: brought to OP once, every candidate, back to INIT. Its socket is closed on return.
Result<std::vector<MeasuredCycle>> measureOurs(const NetworkStudyOptions& o,
                                               const NetworkModel& model, const VethNamespace& ns,
                                               const std::filesystem::path& log,
                                               const SignalFlag& stop, Progress& progress) {
  ECSIM_ASSIGN_OR_RETURN(
      RawSocketLink link,
      RawSocketLink::open(ns.masterInterface(), RawSocketOptions{ns.name(), true}));
  RealClock clock;
  master::RealTimeBus bus(link, clock);
  master::MasterOptions options;
  options.dc.enable = model.dc;
  master::Master m(link, bus, options);
  if (auto names = topology::loadSlaveNames(o.topology); names.ok()) m.setSlaveNames(*names);
  if (isEniFile(o.topology)) ECSIM_TRY(m.loadConfig(o.topology));
  RealTimeThread rt(kMasterPriority);
  progress.update(
      fmt::format("measuring: bringing the served network to OP (master thread {})", rt.note()),
      true);
  const SimTime cycleTimeout = m.transport().options().timeout;
  m.transport().setTimeout(kBringUpFrameTimeout);
  if (auto s = m.start(); !s.ok()) {
    const auto& c = m.transport().counters();
    return makeError(
        s.error().code,
        fmt::format("bringing the served network to OP: {}\nmaster: frames sent {}, resent {}, "
                    "received {}, answered {}, lost {}, late {}, unexpected {}, send errors {}, "
                    "receive errors {}\nserver: {}",
                    s.error().context, c.framesSent, c.framesResent, c.framesReceived,
                    c.framesAnswered, c.framesLost, c.framesLate, c.framesUnexpected, c.sendErrors,
                    c.receiveErrors, readWhole(log)));
  }
  // What the scan measured a frame needs on a long network, else the master's default.
  const auto& advice = m.timeoutAdvice();
  m.transport().setTimeout(std::max(cycleTimeout, advice ? advice->needed : SimTime{0}));
  if (model.dc != m.dcSetup().reference.has_value()) {
    return makeError(ErrorCode::kState, "the served network's DC set-up differs from the model's");
  }
  std::vector<MeasuredCycle> measured;
  for (double c : o.cyclesUs) {
    progress.update(fmt::format("measuring {:g} us for {:g} s", c, o.measureSeconds), true);
    ECSIM_ASSIGN_OR_RETURN(MeasuredCycle r,
                           runCandidate(m, bus, c, o.measureSeconds, stop, progress));
    progress.update(
        fmt::format("measured {:g} us: {} cycles, round trip p50 {:.1f} p99 {:.1f} max {:.1f} us, "
                    "jitter p99 {:.1f} us, lost {}, overruns {}",
                    c, r.cycles, static_cast<double>(r.rttP50) / 1e3,
                    static_cast<double>(r.rttP99) / 1e3, static_cast<double>(r.rttMax) / 1e3,
                    static_cast<double>(r.jitterP99) / 1e3, r.lost, r.overruns),
        true);
    measured.push_back(r);
  }
  (void)m.stop();
  return measured;
}

// The external master, once per candidate; its output in DIR/external-CYCLE.out and .err.
Result<std::vector<MeasuredCycle>> measureExternal(const NetworkStudyOptions& o,
                                                   const VethNamespace& ns, const SignalFlag& stop,
                                                   Progress& progress) {
  std::vector<MeasuredCycle> measured;
  for (double c : o.cyclesUs) {
    std::string command = substitute(o.masterCommand, "{iface}", ns.masterInterface());
    command = substitute(command, "{netns}", ns.name());
    command = substitute(command, "{cycle_us}", fmt::format("{:g}", c));
    command = substitute(command, "{seconds}", fmt::format("{:g}", o.measureSeconds));
    const auto base = std::filesystem::path(o.out) / fmt::format("external-{:g}", c);
    progress.update(fmt::format("external master at {:g} us: {}", c, command), true);
    ECSIM_ASSIGN_OR_RETURN(ChildProcess child,
                           ns.spawn({"sh", "-c", command},
                                    SpawnOptions{base.string() + ".out", base.string() + ".err"}));
    const auto limit = std::chrono::duration<double>(o.measureSeconds) + kExternalGrace;
    const auto until = std::chrono::steady_clock::now() + limit;
    Result<int> status = makeError(ErrorCode::kTimeout, "still running");
    while (!stop.raised() && std::chrono::steady_clock::now() < until) {
      status = child.wait(std::chrono::milliseconds(100));
      if (status.ok()) break;
    }
    if (!status.ok()) {
      (void)child.stop();
      if (stop.raised()) return makeError(ErrorCode::kAborted, "interrupted");
      return makeError(ErrorCode::kTimeout,
                       fmt::format("the external master at {:g} us ran longer than {:.0f} s: {}", c,
                                   limit.count(), command));
    }
    MeasuredCycle r = parseMasterJson(readWhole(base.string() + ".out"),
                                      static_cast<SimTime>(c * static_cast<double>(kNsPerUs)));
    r.exitCode = *status;
    progress.update(
        fmt::format("external master at {:g} us: exit {}, {} cycles", c, r.exitCode, r.cycles),
        true);
    measured.push_back(r);
  }
  return measured;
}

}  // namespace

Result<Measurement> measureNetwork(const NetworkStudyOptions& o, const NetworkModel& model,
                                   Progress& progress) {
  ECSIM_TRY(checkNetworkCapabilities());
  SignalFlag stop;
  std::filesystem::create_directories(o.out);
  const auto log = std::filesystem::path(o.out) / "serve.log";
  progress.update("measuring: creating a veth pair in a private network namespace", true);
  ECSIM_ASSIGN_OR_RETURN(VethNamespace ns, VethNamespace::create());
  const std::string ecsim = o.ecsimBinary.empty()
                                ? std::filesystem::read_symlink("/proc/self/exe").string()
                                : o.ecsimBinary;
  std::vector<std::string> argv{ecsim,  "serve",   "--paced",
                                "--rt", "--iface", ns.simulatorInterface()};
  if (!o.esiDir.empty()) {
    argv.push_back("--esi-dir");
    argv.push_back(o.esiDir);
  }
  argv.push_back(std::filesystem::absolute(o.topology).string());
  ECSIM_ASSIGN_OR_RETURN(ChildProcess server,
                         ns.spawn(argv, SpawnOptions{log.string(), log.string()}));
  ECSIM_TRY(waitForServer(log, server, stop));
  Measurement result;
  ECSIM_ASSIGN_OR_RETURN(result.ours, measureOurs(o, model, ns, log, stop, progress));
  if (!o.masterCommand.empty()) {
    ECSIM_ASSIGN_OR_RETURN(result.external, measureExternal(o, ns, stop, progress));
  }
  (void)server.stop();
  ECSIM_TRY(ns.destroy());
  return result;
}

}  // namespace ecsim::tools::study
