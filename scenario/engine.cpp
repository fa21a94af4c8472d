#include "scenario/engine.hpp"

#include <fmt/core.h>
#include <pthread.h>
#include <sched.h>

#include <algorithm>

#include "config/topology_file.hpp"
#include "link/fd.hpp"
#include "link/pcap.hpp"
#include "link/signal_flag.hpp"
#include "scenario/expectations.hpp"
#include "scenario/master_under_test.hpp"
#include "topology/faults.hpp"
#include "topology/network_builder.hpp"
#include "topology/pcap_cable_tap.hpp"

namespace ecsim::scenario {
namespace {

std::string number(double v) {
  if (v == static_cast<double>(static_cast<std::int64_t>(v))) {
    return std::to_string(static_cast<std::int64_t>(v));
  }
  return fmt::format("{:.6g}", v);
}

// The one place a timeline action meets the run: a fault goes to the injector, pause-master
// to the engine's pause. Returns the log's text for it.
Result<std::string> applyAction(const TimedAction& a, const MasterUnderTest& master,
                                topology::FaultInjector& faults, SimTime now,
                                SimTime& pausedUntil) {
  if (const auto* pause = std::get_if<topology::PauseMaster>(&a.fault)) {
    if (!master.pausable()) {
      return makeError(ErrorCode::kInvalidArgument,
                       fmt::format("line {}: pause-master needs our master", a.line));
    }
    pausedUntil = saturatingAdd(now, pause->duration);
    return fmt::format("the master sends nothing for {} ms",
                       number(static_cast<double>(pause->duration) / kNsPerMs));
  }
  return faults.apply(a.fault, now, a.action.where);
}

Result<topology::Network> buildScenarioNetwork(const Scenario& scenario) {
  ECSIM_ASSIGN_OR_RETURN(auto config, loadTopologyFile(scenario.topology));
  return topology::buildNetwork(config);
}

class Engine {
 public:
  Engine(const Scenario& s, const RunOptions& o) : s_(s), o_(o) {}
  ScenarioResult run();

 private:
  const Scenario& s_;
  const RunOptions& o_;
  ScenarioResult r_;
};

ScenarioResult Engine::run() {
  r_.name = s_.name;
  r_.file = s_.file.filename().string();
  r_.seed = o_.seed.value_or(s_.seed);
  r_.cycleTime = s_.cycleTime;
  auto kind = masterKindFor(s_, o_);
  if (!kind.ok()) {
    r_.error = kind.error().message();
    return r_;
  }
  r_.master = *kind;
  auto built = buildScenarioNetwork(s_);
  if (!built.ok()) {
    r_.error = built.error().message();
    return r_;
  }
  topology::Network network = std::move(*built);
  topology::Segment& segment = *network.segment;
  topology::FaultInjector faults(network, r_.seed);
  RunLog log;
  Judge judge(s_, segment, log);
  // Real-time runs: SIGINT/SIGTERM end the run in order (the master or command stopped, the
  // namespace removed, the report saying so).
  std::optional<SignalFlag> signals;
  if (*kind != "in-process") signals.emplace();
  RunContext context{s_, o_, network, faults, judge, log, signals ? &*signals : nullptr};
  std::unique_ptr<MasterUnderTest> master = *kind == "in-process" ? makeInProcessMaster(context)
                                            : *kind == "veth"     ? makeVethMaster(context)
                                                                  : makeExternalMaster(context);
  std::optional<PcapWriter> writer;
  std::optional<topology::PcapCableTap> tap;
  if (!o_.pcapDir.empty()) {
    auto w = PcapWriter::open((o_.pcapDir / (s_.name + ".pcap")).string());
    if (!w.ok()) {
      r_.error = w.error().message();
      return r_;
    }
    writer.emplace(std::move(*w));
    tap.emplace(*writer, master->virtualTime() ? kDcEpochUnixNs
                                               : WallClock().now() - master->clock().now());
    segment.setCableObserver(0, 0, &*tap);
  }
  struct Detach {  // the capture ends before the writer, the master before the network
    topology::Segment& segment;
    std::unique_ptr<MasterUnderTest>& master;
    ~Detach() {
      master.reset();
      segment.setCableObserver(0, 0, nullptr);
    }
  } detach{segment, master};

  if (auto st = master->start(); !st.ok()) {
    r_.error = st.error().message();
    r_.log = log.lines(master->zero().value_or(0));
    return r_;
  }
  std::vector<bool> applied(s_.actions.size(), false);
  SimTime pausedUntil = 0;
  std::string actionError;
  while (auto tick = master->next()) {
    const SimTime zero = *master->zero();
    for (std::uint64_t k = tick->cycle - tick->skipped; k < tick->cycle; ++k) {
      judge.sample(k, static_cast<SimTime>(k) * s_.cycleTime, false, false);
    }
    if (tick->end) break;
    const SimTime since = tick->now - zero;
    for (std::size_t i = 0; i < s_.actions.size() && actionError.empty(); ++i) {
      const auto& a = s_.actions[i];
      if (applied[i] || !((a.cycle && tick->cycle >= *a.cycle) || (a.time && since >= *a.time))) {
        continue;
      }
      applied[i] = true;
      auto done = applyAction(a, *master, faults, tick->now, pausedUntil);
      log.add(tick->now, fmt::format("cycle {:>6}  {}: {}", tick->cycle, a.action.text(),
                                     done.ok() ? *done : "ERROR " + done.error().context));
      if (!done.ok()) actionError = done.error().context;
    }
    if (!actionError.empty()) break;
    // "At cycle N": after cycle N's actions, before its exchange.
    judge.checkDue(tick->cycle, since);
    const Exchange exchanged = master->exchange(*tick, tick->now < pausedUntil);
    judge.sample(tick->cycle, since, exchanged.good, exchanged.clean);
  }
  RunEnd end = master->stop();
  if (!actionError.empty()) end.ranToEnd = false;
  if (!end.zero) {
    log.add(end.at, "the network never had all slaves in OP: no time zero, no timeline");
  } else {
    for (std::size_t i = 0; i < s_.actions.size(); ++i) {
      if (applied[i]) continue;
      log.add(end.at, fmt::format("not applied, the run had ended: {} (line {})",
                                  s_.actions[i].action.text(), s_.actions[i].line));
    }
  }
  r_.cycles = master->cycles();
  r_.results = judge.finish(end, master->command());
  // Times are counted from time zero, else from the command's start.
  const SimTime origin =
      master->zero().value_or(master->command() != nullptr ? master->command()->start : end.at);
  r_.log = log.lines(origin);
  for (auto& line : master->trailer()) r_.log.push_back(std::move(line));
  if (!actionError.empty()) {
    r_.error = actionError;
  } else if (auto error = master->error(); !error.empty()) {
    r_.error = error;
  }
  if (writer) {
    segment.setCableObserver(0, 0, nullptr);
    (void)writer->close();
  }
  return r_;
}

}  // namespace

bool ScenarioResult::passed() const {
  return error.empty() && failures() == 0;
}

std::size_t ScenarioResult::failures() const {
  return static_cast<std::size_t>(
      std::count_if(results.begin(), results.end(), [](const auto& r) { return !r.passed; }));
}

Result<std::string> masterKindFor(const Scenario& s, const RunOptions& o) {
  if (o.master.empty() || o.master == s.masterKind) return s.masterKind;
  auto error = [&](const std::string& what) {
    return makeError(ErrorCode::kInvalidArgument,
                     fmt::format("{}, line {}: {}", s.file.string(),
                                 s.masterLine != 0 ? s.masterLine : s.line, what));
  };
  if (o.master != "in-process" && o.master != "veth" && o.master != "external") {
    return error("--master " + o.master + ": in-process, veth or external");
  }
  if (s.masterKind == "external") {
    return error("--master " + o.master +
                 ": this scenario is written for an external master's command; it runs with "
                 "Master kind=\"external\" only");
  }
  if (o.master == "external") {
    return error("--master external: this scenario is written for our master (no command to "
                 "run); in-process or veth");
  }
  return o.master;  // in-process <-> veth: both are our master
}

ScenarioResult runScenario(const Scenario& scenario, const RunOptions& options) {
  Engine engine(scenario, options);
  return engine.run();
}

RealtimeScheduling::~RealtimeScheduling() {
  if (!enabled_) return;
  sched_param param{};
  param.sched_priority = priority_;
  (void)pthread_setschedparam(pthread_self(), policy_, &param);
}

std::string RealtimeScheduling::enable() {
  sched_param old{};
  if (pthread_getschedparam(pthread_self(), &policy_, &old) != 0) return "no scheduling policy";
  priority_ = old.sched_priority;
  sched_param param{};
  param.sched_priority = 80;
  if (const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param); rc != 0) {
    return fmt::format("SCHED_FIFO not permitted ({}): normal priority", errnoText(rc));
  }
  enabled_ = true;
  return {};
}

}  // namespace ecsim::scenario
