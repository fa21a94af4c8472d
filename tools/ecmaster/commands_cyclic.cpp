// ecmaster cyclic: bring the bus to OP, exchange process data at a fixed cycle with health and
// recovery (Master::cycle), print a live line every second (stderr with --json), then a
// summary: round trip and cycle jitter (min, mean, max, p99, p99.9), lost, late and WKC
// errors, slave events. --show NAME prints process variables; --rt runs the master on the
// real-time driver's threads (master/rt_driver.hpp); --cpu N pins them (or, without --rt, the
// thread that runs the cycles) to one CPU.
#include <fmt/core.h>
#include <sched.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <thread>

#include "link/signal_flag.hpp"
#include "master/rt_driver.hpp"
#include "tools/ecmaster/commands.hpp"

namespace ecsim::tools::ecmaster {
namespace {

struct CyclicOptions {
  unsigned cycleUs{1000};
  double seconds{1.0};
  bool stopAtEnd{true};
  bool recovery{true};
  bool rt{false};
  bool quiet{false};
  int cpu{-1};  // --cpu: pin to this CPU
  std::vector<std::string> show;
};

// Pins the calling thread (the one running Master::cycle() without --rt).
std::optional<std::string> pinThisThread(int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(static_cast<std::size_t>(cpu), &set);
  if (sched_setaffinity(0, sizeof(set), &set) == 0) return std::nullopt;
  return fmt::format("not pinned to CPU {} ({})", cpu, std::strerror(errno));
}

double us(SimTime ns) {
  return static_cast<double>(ns) / 1e3;
}

nlohmann::json histogramJson(const master::LatencyHistogram& h) {
  return {{"min", us(h.min())}, {"mean", us(h.mean())}, {"max", us(h.max())},
          {"p99", us(h.p99())}, {"p999", us(h.p999())}, {"samples", h.count()}};
}

std::string histogramText(const master::LatencyHistogram& h) {
  return fmt::format("min {:.1f} mean {:.1f} p99 {:.1f} p99.9 {:.1f} max {:.1f}", us(h.min()),
                     us(h.mean()), us(h.p99()), us(h.p999()), us(h.max()));
}

std::string variablesText(const std::vector<master::PdoVariable>& vars) {
  std::string s;
  for (const auto& v : vars) s += fmt::format("  {} = {}", v.name(), v.format());
  return s;
}

// Everything the summary needs, from the master (plain run) or the driver's snapshot.
struct RunResult {
  std::uint64_t cycles{0};
  std::uint64_t failedCycles{0};
  std::uint64_t overruns{0};
  std::string firstError;
  master::CyclicStatistics statistics;
  master::MasterHealth health;
  std::vector<master::MasterEvent> events;
  std::optional<master::LatencyHistogram> wakeLatency;  // --rt
};

// Lost: never returned by the network; late: returned after the deadline (MasterHealth), both
// counted from `base`, the health when the cyclic run began (start-up frames are not its own).
void printLive(const GlobalOptions& g, double second, const master::CyclicStatistics& st,
               const master::MasterHealth& h, const master::MasterHealth& base,
               const std::vector<master::PdoVariable>& vars) {
  std::FILE* out = g.json ? stderr : stdout;
  fmt::print(out,
             "[{:6.1f} s] cycles {} rtt us {} | jitter p99 {:.1f} us | lost {} late {} wkc {}{}\n",
             second, st.cycles, histogramText(st.roundTrip), us(st.jitter.p99()),
             h.framesLost - base.framesLost, h.framesLate - base.framesLate, h.wkcErrors,
             variablesText(vars));
  std::fflush(out);
}

int runCyclic(const GlobalOptions& g, const CyclicOptions& o) {
  auto c = connectAndScan(g, true, o.recovery);
  if (!c.ok()) return fail(c.error());
  master::Master& m = (*c)->master();
  master::Bus& bus = (*c)->bus();
  if (o.rt && (*c)->simulated())
    return fail("--rt needs --iface (the simulator runs on virtual time)");
  if (auto s = m.bringTo(AlState::kOp); !s.ok()) return fail(s.error());
  std::vector<master::PdoVariable> vars;
  for (const auto& name : o.show) {
    auto v = m.variable(name);
    if (!v.ok()) return fail(v.error());
    vars.push_back(std::move(v).value());
  }
  const SimTime cycle = static_cast<SimTime>(o.cycleUs) * kNsPerUs;
  const SimTime duration = static_cast<SimTime>(o.seconds * static_cast<double>(kNsPerSecond));
  m.setCycleTime(cycle);
  m.resetStatistics();
  m.clearEvents();
  const master::MasterHealth base = m.health();
  SignalFlag stop;
  RunResult r;
  std::size_t eventsPrinted = 0;
  // Each event leaves at once, also into a pipe or file (a log watcher, a scenario judging
  // when the line appeared).
  auto printEvents = [&](const std::vector<master::MasterEvent>& events) {
    std::FILE* out = g.json ? stderr : stdout;
    for (; eventsPrinted < events.size(); ++eventsPrinted) {
      fmt::print(out, "event: {}\n", events[eventsPrinted].text);
      std::fflush(out);
    }
  };
  std::vector<std::string> warnings;
  bool realtime = false;
  if (o.rt) {
    master::RtDriverOptions rto;
    rto.period = cycle;
    if (o.cpu >= 0) rto.cpu = o.cpu;
    master::RtDriver driver(m, rto);
    if (auto s = driver.start(); !s.ok()) return fail(s.error());
    warnings = driver.warnings();
    realtime = driver.realtime();
    for (const auto& w : warnings) fmt::print(stderr, "ecmaster: warning: {}\n", w);
    RealClock clock;
    const SimTime start = clock.now();
    SimTime nextPrint = start + kNsPerSecond;
    while (!stop.raised() && clock.now() - start < duration) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      const auto snap = driver.snapshot();  // events as they come (the snapshot's period late)
      printEvents(snap.events);
      if (clock.now() >= nextPrint && !o.quiet) {
        nextPrint += kNsPerSecond;
        printLive(g, static_cast<double>(clock.now() - start) / 1e9, snap.statistics, snap.health,
                  base, vars);
      }
    }
    driver.stop();
    const auto snap = driver.snapshot();
    r.cycles = snap.cycles;
    r.failedCycles = snap.failedCycles;
    r.overruns = snap.overruns;
    r.firstError = snap.firstError;
    r.statistics = snap.statistics;
    r.health = snap.health;
    r.events = snap.events;
    r.wakeLatency = snap.wakeLatency;
  } else {
    if (o.cpu >= 0) {
      if (auto w = pinThisThread(o.cpu)) {
        warnings.push_back(*w);
        fmt::print(stderr, "ecmaster: warning: {}\n", *w);
      }
    }
    const SimTime start = bus.now();
    SimTime next = start;
    SimTime nextPrint = start + kNsPerSecond;
    while (!stop.raised() && bus.now() - start < duration) {
      auto status = m.cycle();
      ++r.cycles;
      if (!status.ok()) {
        ++r.failedCycles;
        if (r.firstError.empty()) r.firstError = status.error().message();
      }
      printEvents(m.events());
      next += cycle;
      if (bus.now() > next) {
        ++r.overruns;  // the cycle took longer than its period: start the next one now
        next = bus.now();
      }
      if (bus.now() >= nextPrint && !o.quiet) {
        nextPrint += kNsPerSecond;
        printLive(g, static_cast<double>(bus.now() - start) / 1e9, m.statistics(), m.health(), base,
                  vars);
      }
      while (bus.now() < next && !stop.raised()) bus.wait(next);
    }
    r.statistics = m.statistics();
    r.health = m.health();
    r.events = m.events();
  }
  printEvents(r.events);
  const auto& st = r.statistics;
  const std::uint64_t lost = r.health.framesLost - base.framesLost;
  const std::uint64_t late = r.health.framesLate - base.framesLate;
  (void)m.readStates();
  Status stopped = o.stopAtEnd ? m.stop() : okStatus();
  if (g.json) {
    nlohmann::json j{{"cycles", r.cycles},
                     {"cycleTimeUs", o.cycleUs},
                     {"roundTripUs", histogramJson(st.roundTrip)},
                     {"jitterUs", histogramJson(st.jitter)},
                     {"framesPerCycle", m.layout().frameCount},
                     {"framesLost", lost},
                     {"framesLate", late},
                     {"wkcErrors", st.wkcErrors},
                     {"failedCycles", r.failedCycles},
                     {"overruns", r.overruns},
                     {"outputBytes", m.layout().outputBytes},
                     {"inputBytes", m.layout().inputBytes},
                     {"slaves", m.slaves().size()},
                     {"slavesLost", r.health.slavesLost},
                     {"slavesRecovered", r.health.slavesRecovered},
                     {"simulated", (*c)->simulated()}};
    if (r.health.ring != master::RingState::kNone) {
      j["ring"] = std::string(master::toString(r.health.ring));
      j["ringBreaks"] = r.health.ringBreaks;
    }
    if (o.rt) {
      j["realtime"] = realtime;
      j["warnings"] = warnings;
      if (r.wakeLatency) j["wakeLatencyUs"] = histogramJson(*r.wakeLatency);
    }
    if (o.cpu >= 0) j["cpu"] = o.cpu;
    nlohmann::json events = nlohmann::json::array();
    for (const auto& e : r.events) {
      events.push_back({{"cycle", e.cycle},
                        {"position", e.position},
                        {"kind", std::string(master::toString(e.kind))},
                        {"text", e.text}});
    }
    j["events"] = events;
    nlohmann::json shown = nlohmann::json::object();
    for (const auto& v : vars) shown[v.name()] = v.format();
    if (!vars.empty()) j["variables"] = shown;
    if (!r.firstError.empty()) j["firstError"] = r.firstError;
    printJson(j);
  } else {
    fmt::print("{} slaves in OP, {} output + {} input bytes in {} frame(s) per cycle\n",
               m.slaves().size(), m.layout().outputBytes, m.layout().inputBytes,
               m.layout().frameCount);
    fmt::print("cycles {} at {} us{}\n", r.cycles, o.cycleUs,
               (*c)->simulated() ? " (virtual time)"
               : o.rt            ? (realtime ? " (real-time threads)" : " (threads, not real-time)")
                                 : "");
    fmt::print("round trip us: {}\n", histogramText(st.roundTrip));
    fmt::print("cycle jitter us: {}\n", histogramText(st.jitter));
    if (r.wakeLatency) fmt::print("wake-up latency us: {}\n", histogramText(*r.wakeLatency));
    fmt::print("lost frames {}, late frames {}, WKC errors {}, failed cycles {}, overruns {}\n",
               lost, late, st.wkcErrors, r.failedCycles, r.overruns);
    fmt::print("slaves lost {}, recovered {}\n", r.health.slavesLost, r.health.slavesRecovered);
    if (r.health.ring != master::RingState::kNone) {
      fmt::print("ring {}, broken {} time(s)\n", master::toString(r.health.ring),
                 r.health.ringBreaks);
    }
    if (!vars.empty()) fmt::print("variables:{}\n", variablesText(vars));
    if (!r.firstError.empty()) fmt::print("first error: {}\n", r.firstError);
  }
  if (!stopped.ok()) return fail(stopped.error());
  return r.failedCycles == 0 ? 0 : 1;
}

}  // namespace

CommandRunner addCyclicCommand(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<CyclicOptions>();
  auto* cmd = app.add_subcommand("cyclic", "Bring the bus to OP and exchange process data");
  cmd->add_option("--cycle-us", o->cycleUs, "Cycle time in microseconds (default 1000)")
      ->check(CLI::Range(10u, 10'000'000u));
  cmd->add_option("--seconds", o->seconds, "How long to run (default 1)")
      ->check(CLI::Range(0.0, 86400.0));
  cmd->add_flag("!--no-stop", o->stopAtEnd, "Leave the slaves in OP at the end");
  cmd->add_flag("!--no-recovery", o->recovery,
                "Do not watch the slaves: no lost/returned events, nothing brought back to OP "
                "(every missing working counter is an error)");
  cmd->add_option("--show", o->show,
                  "Print a process variable live and at the end (e.g. Drive1.Statusword); "
                  "repeatable");
  cmd->add_flag("--rt", o->rt,
                "Run on real-time threads (SCHED_FIFO, mlockall; a warning when not permitted)");
  cmd->add_option("--cpu", o->cpu,
                  "Pin the cycle to this CPU: with --rt the send/receive, control and cyclic "
                  "threads, else the thread that runs the cycles")
      ->check(CLI::Range(0, CPU_SETSIZE - 1));
  cmd->add_flag("--quiet", o->quiet, "No live line every second");
  return [&global, o] { return runCyclic(global, *o); };
}

}  // namespace ecsim::tools::ecmaster
