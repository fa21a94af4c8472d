#include "scenario/runner.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <map>
#include <set>

#include "config/topology_file.hpp"
#include "link/memory_link.hpp"
#include "link/pcap.hpp"
#include "master/batch.hpp"
#include "master/bus.hpp"
#include "master/master.hpp"
#include "master/process_image.hpp"
#include "protocol/al_status.hpp"
#include "topology/faults.hpp"
#include "topology/network_builder.hpp"
#include "topology/network_server.hpp"
#include "topology/pcap_cable_tap.hpp"
#include "topology/slave_names.hpp"

namespace ecsim::scenario {
namespace {

std::string ms(SimTime t) {
  return fmt::format("{:.3f} ms", static_cast<double>(t) / static_cast<double>(kNsPerMs));
}

std::string stateText(std::uint16_t status, std::uint16_t code) {
  auto state = alStateFromRaw(static_cast<std::uint16_t>(status & kAlStateMask));
  std::string s = state ? std::string(toString(*state)) : fmt::format("{:#x}", status & 0xF);
  if ((status & 0x10) != 0) {
    s += fmt::format("+ERR {:#06x} ({})", code, alStatusCodeText(code));
  }
  return s;
}

std::string number(double v) {
  if (v == static_cast<double>(static_cast<std::int64_t>(v))) {
    return std::to_string(static_cast<std::int64_t>(v));
  }
  return fmt::format("{:.6g}", v);
}

// The condition a master event is matched as by <Detected condition="...">.
std::string_view conditionOf(master::MasterEventKind kind) {
  switch (kind) {
    case master::MasterEventKind::kSlaveLost:
      return "slave-lost";
    case master::MasterEventKind::kSlaveReturned:
      return "slave-returned";
    case master::MasterEventKind::kSlaveReset:
      return "slave-reset";
    case master::MasterEventKind::kSlaveError:
      return "slave-state";
    case master::MasterEventKind::kSlaveRecovered:
      return "slave-recovered";
    case master::MasterEventKind::kRecoveryFailed:
      return "recovery-failed";
  }
  return "?";
}

// Conditions that are not an error (any-error does not match them).
bool isGoodNews(std::string_view condition) {
  return condition == "slave-returned" || condition == "slave-recovered";
}

// What the master observed in one cycle: its cycle result and its events.
struct Observation {
  std::uint64_t cycle{0};
  SimTime time{0};
  std::string condition;  // wkc-error, frame-lost, emergency, or conditionOf() an event
  std::set<std::string> slaves;
  std::string text;
};

class Run {
 public:
  Run(const Scenario& s, const RunOptions& o) : s_(s), o_(o) {}
  ScenarioResult execute();

 private:
  SimTime sinceOp() const { return clock_.now() - t0_; }
  std::string slaveNameAtPosition(std::size_t position) const;
  void learnStations();
  void observe(std::uint64_t cycle, const std::string& condition, std::set<std::string> slaves,
               const std::string& text);
  void takeEvents(std::uint64_t cycle);
  bool cleanCycle() const;
  std::optional<double> healthStatistic(const Expectation& x) const;
  bool allOp() const;
  void checkTimed(std::uint64_t cycle, bool atEnd);
  ExpectationResult evaluatePoint(const Expectation& x);
  void evaluateWindows();

  const Scenario& s_;
  const RunOptions& o_;
  ScenarioResult r_;
  VirtualClock clock_{kNsPerSecond};
  SimTime t0_{0};
  topology::Network network_;
  std::unique_ptr<master::Master> master_;
  std::vector<Observation> observations_;
  std::vector<std::pair<std::uint64_t, bool>> cleanCycles_;  // cycle, all OP + ok
  std::vector<bool> checked_;
  std::uint64_t badCycles_{0};
  std::uint64_t run_{0};
  std::uint64_t longestRun_{0};
  std::size_t eventsSeen_{0};
  std::size_t emergenciesSeen_{0};
  std::map<std::string, std::pair<std::uint64_t, std::string>> lastLogged_;
  std::map<std::uint16_t, std::string> stationNames_;
  const topology::FaultInjector* faults_{nullptr};
};

std::string Run::slaveNameAtPosition(std::size_t position) const {
  if (position >= master_->slaves().size()) return fmt::format("position {}", position);
  auto it = stationNames_.find(master_->slaves()[position].station);
  return it == stationNames_.end() ? fmt::format("position {}", position) : it->second;
}

// Which simulated slave got which station address (taken once the master is in OP: a power
// cycle clears the address in the ESC until the master's recovery writes it again).
void Run::learnStations() {
  auto& seg = *network_.segment;
  for (std::size_t i = 0; i < seg.size(); ++i) {
    const std::uint16_t station = seg.slave(i).esc().read(reg::kConfiguredStationAddress);
    if (station != 0) stationNames_[station] = seg.slave(i).name();
  }
}

void Run::observe(std::uint64_t cycle, const std::string& condition, std::set<std::string> slaves,
                  const std::string& text) {
  // The log shows a condition when it starts or changes, not every cycle it lasts.
  auto& last = lastLogged_[condition];
  if (last.first + 1 != cycle || last.second != text) {
    r_.log.push_back(fmt::format("{:>12}  cycle {:>6}  master: {}", ms(sinceOp()), cycle, text));
  }
  last = {cycle, text};
  observations_.push_back({cycle, sinceOp(), condition, std::move(slaves), text});
}

bool Run::allOp() const {
  auto& seg = *network_.segment;
  for (std::size_t i = 0; i < seg.size(); ++i) {
    if (seg.slave(i).esc().alStatus() != static_cast<std::uint16_t>(AlState::kOp)) return false;
  }
  return master_->slaves().size() == seg.size();
}

// Every slave in OP (simulator side) and the master exchanging with every one of them: none
// lost, recovering or failed in its health.
bool Run::cleanCycle() const {
  if (!allOp()) return false;
  const auto health = master_->health();
  return health.slaves.size() == network_.segment->size() && health.allOperational();
}

// The master's events since the last call, as observations: what a master reports is what the
// scenario is judged by.
void Run::takeEvents(std::uint64_t cycle) {
  const auto& events = master_->events();
  for (; eventsSeen_ < events.size(); ++eventsSeen_) {
    const master::MasterEvent& e = events[eventsSeen_];
    std::string text = e.text;  // "slave 3 (0x1004 'AI1') lost at cycle 1002": the master's count
    if (auto at = text.rfind(" at cycle "); at != std::string::npos) text.erase(at);
    observe(cycle, std::string(conditionOf(e.kind)), {slaveNameAtPosition(e.position)}, text);
  }
}

// Master health figures, and how often the master reported a condition (Detected's names),
// of one slave when the expectation names one.
std::optional<double> Run::healthStatistic(const Expectation& x) const {
  if (x.name == "slavesLost" || x.name == "slavesRecovered" || x.name == "framesLate") {
    const auto h = master_->health();
    if (x.name == "slavesLost") return static_cast<double>(h.slavesLost);
    if (x.name == "slavesRecovered") return static_cast<double>(h.slavesRecovered);
    return static_cast<double>(h.framesLate);
  }
  static constexpr std::string_view kConditions[] = {
      "wkc-error",   "frame-lost",  "emergency",       "slave-lost",     "slave-returned",
      "slave-reset", "slave-state", "slave-recovered", "recovery-failed"};
  if (std::find(std::begin(kConditions), std::end(kConditions), x.name) == std::end(kConditions)) {
    return std::nullopt;
  }
  std::size_t n = 0;
  for (const auto& o : observations_) {
    if (o.condition == x.name && (x.slave.empty() || o.slaves.count(x.slave) > 0)) ++n;
  }
  return static_cast<double>(n);
}

ExpectationResult Run::evaluatePoint(const Expectation& x) {
  ExpectationResult res{x.line, x.describe(), false, sinceOp(), {}, x.needsRecovery};
  auto& seg = *network_.segment;
  std::optional<std::size_t> slave;
  if (!x.slave.empty()) {
    for (std::size_t i = 0; i < seg.size(); ++i) {
      if (seg.slave(i).name() == x.slave) slave = i;
    }
    if (!slave) {
      res.observed = "no slave named '" + x.slave + "' in the topology";
      return res;
    }
  }
  switch (x.kind) {
    case ExpectKind::kState: {
      const auto& esc = seg.slave(*slave).esc();
      const std::uint16_t status = esc.alStatus();
      const std::uint16_t code = esc.read(reg::kAlStatusCode);
      res.observed = stateText(status, code);
      auto state = alStateFromRaw(static_cast<std::uint16_t>(status & kAlStateMask));
      bool ok = state && toString(*state) == x.state;
      if (x.error) ok = ok && (((status & 0x10) != 0) == *x.error);
      if (x.code) ok = ok && code == *x.code;
      res.passed = ok;
      break;
    }
    case ExpectKind::kRegister: {
      const auto& esc = seg.slave(*slave).esc();
      std::uint32_t raw = x.width == 1   ? esc.reg8(x.address)
                          : x.width == 2 ? esc.reg16(x.address)
                                         : esc.reg32(x.address);
      raw &= x.mask;
      const double v = static_cast<double>(raw);
      res.observed = fmt::format("{} ({:#x})", number(v), static_cast<std::uint64_t>(v));
      res.passed = compareValues(v, x.compare, x.value, x.tolerance);
      break;
    }
    case ExpectKind::kStatistic: {
      const auto& st = master_->statistics();
      std::optional<double> v;
      if (x.name == "framesLost") v = static_cast<double>(st.framesLost);
      if (x.name == "wkcErrors") v = static_cast<double>(st.wkcErrors);
      if (x.name == "cyclesWithErrors") v = static_cast<double>(st.cyclesWithErrors);
      if (x.name == "cycles") v = static_cast<double>(st.cycles);
      if (x.name == "badCycles") v = static_cast<double>(badCycles_);
      if (x.name == "emergencies") v = static_cast<double>(master_->emergencies().size());
      if (x.name == "framesCorrupted") v = static_cast<double>(faults_->framesCorrupted());
      if (auto h = healthStatistic(x)) v = h;
      if (!v) {
        res.observed = "unknown statistic '" + x.name + "'";
        break;
      }
      res.observed = number(*v);
      res.passed = compareValues(*v, x.compare, x.value, x.tolerance);
      break;
    }
    case ExpectKind::kVariable: {
      std::optional<std::size_t> position;
      if (slave) {
        const std::uint16_t station = seg.slave(*slave).esc().read(reg::kConfiguredStationAddress);
        for (const auto& info : master_->slaves()) {
          if (info.station == station) position = info.position;
        }
      }
      std::optional<master::ProcessVariable> var;
      if (!x.variable.empty()) {  // by name (checked at the start of the run)
        if (auto v = master::findVariable(master_->variables(), x.variable); v.ok()) {
          var = master::ProcessVariable{v->position, v->output, v->bitOffset, v->bitLength,
                                        v->index,    v->subindex, {}, v->entry};
        }
      } else if (position) {
        for (const auto& v : master::processVariables(master_->layout())) {
          if (v.position == *position && v.index == x.index && v.subindex == x.subindex) var = v;
        }
      }
      if (!var) {
        res.observed = x.variable.empty()
                           ? fmt::format("no process-data entry {:#06x}:{:02x} of {} in the image",
                                         x.index, x.subindex, x.slave)
                           : "no process variable '" + x.variable + "'";
        break;
      }
      auto image = master_->image();
      std::uint64_t raw = 0;
      for (unsigned b = 0; b < var->bitLength && b < 64; ++b) {
        const std::uint32_t bit = var->bitOffset + b;
        if (bit / 8 < image.size() && ((image[bit / 8] >> (bit % 8)) & 1) != 0) raw |= 1ull << b;
      }
      raw &= x.mask;
      double v = static_cast<double>(raw);
      if (x.isSigned && var->bitLength < 64 && ((raw >> (var->bitLength - 1)) & 1) != 0) {
        v = static_cast<double>(static_cast<std::int64_t>(raw) -
                                (static_cast<std::int64_t>(1) << var->bitLength));
      }
      res.observed = number(v);
      res.passed = compareValues(v, x.compare, x.value, x.tolerance);
      break;
    }
    default:
      break;
  }
  return res;
}

void Run::checkTimed(std::uint64_t cycle, bool atEnd) {
  for (std::size_t i = 0; i < s_.expectations.size(); ++i) {
    const auto& x = s_.expectations[i];
    if (checked_[i]) continue;
    if (x.kind == ExpectKind::kDetected || x.kind == ExpectKind::kBackInOp ||
        x.kind == ExpectKind::kContinuity) {
      continue;
    }
    bool due = atEnd;
    if (x.atCycle && cycle >= *x.atCycle) due = true;
    if (x.atTime && sinceOp() >= *x.atTime) due = true;
    if (!due) continue;
    checked_[i] = true;
    r_.results.push_back(evaluatePoint(x));
  }
}

void Run::evaluateWindows() {
  for (std::size_t i = 0; i < s_.expectations.size(); ++i) {
    const auto& x = s_.expectations[i];
    ExpectationResult res{x.line, x.describe(), false, sinceOp(), {}, x.needsRecovery};
    if (x.kind == ExpectKind::kDetected) {
      const std::uint64_t last = x.afterCycle + x.withinCycles;
      std::vector<std::string> seen;
      for (const auto& o : observations_) {
        if (o.cycle < x.afterCycle) continue;
        const bool match = ((x.condition == "any-error" && !isGoodNews(o.condition)) ||
                            o.condition == x.condition) &&
                           (x.slave.empty() || o.slaves.count(x.slave) > 0);
        if (match && o.cycle <= last) {
          res.passed = true;
          res.at = o.time;
          res.observed = fmt::format("at cycle {} ({} cycles after {}): {}", o.cycle,
                                     o.cycle - x.afterCycle, x.afterCycle, o.text);
          break;
        }
        if (seen.size() < 3) seen.push_back(fmt::format("cycle {}: {}", o.cycle, o.text));
      }
      if (!res.passed) {
        res.observed = seen.empty()
                           ? fmt::format("nothing observed from cycle {} to {}", x.afterCycle, last)
                           : "not within the window; observed " + seen.front();
      }
    } else if (x.kind == ExpectKind::kBackInOp) {
      const std::uint64_t limitCycles =
          static_cast<std::uint64_t>(x.within / std::max<SimTime>(s_.cycleTime, 1));
      std::optional<std::uint64_t> first;
      for (const auto& [c, clean] : cleanCycles_) {
        if (c >= x.afterCycle && clean) {
          first = c;
          break;
        }
      }
      if (first && *first - x.afterCycle <= limitCycles) {
        res.passed = true;
        res.at = static_cast<SimTime>(*first) * s_.cycleTime;
        res.observed = fmt::format(
            "all slaves in OP with a clean cycle at cycle {} ({} after {})", *first,
            ms(static_cast<SimTime>(*first - x.afterCycle) * s_.cycleTime), x.afterCycle);
      } else if (first) {
        res.observed = fmt::format(
            "first back in OP at cycle {} ({} after cycle {}), too late", *first,
            ms(static_cast<SimTime>(*first - x.afterCycle) * s_.cycleTime), x.afterCycle);
      } else {
        std::string states;
        auto& seg = *network_.segment;
        for (std::size_t k = 0; k < seg.size(); ++k) {
          const auto& esc = seg.slave(k).esc();
          states += fmt::format("{}{} {}", k == 0 ? "" : ", ", seg.slave(k).name(),
                                stateText(esc.alStatus(), esc.read(reg::kAlStatusCode)));
        }
        res.observed = "never back in OP after cycle " + std::to_string(x.afterCycle) +
                       "; at the end: " + states;
      }
    } else if (x.kind == ExpectKind::kContinuity) {
      res.passed = badCycles_ <= x.maxBadCycles && longestRun_ <= x.maxConsecutiveBadCycles;
      res.observed = fmt::format("{} cycles without fresh process data, longest run {}", badCycles_,
                                 longestRun_);
    } else {
      continue;
    }
    r_.results.push_back(res);
  }
}

ScenarioResult Run::execute() {
  r_ = startResult(s_, o_);
  if (s_.masterKind != "in-process") {
    r_.error = "not the in-process master (Master kind=\"" + s_.masterKind +
               "\"): runAnyScenario (scenario/external_runner.hpp) runs each kind";
    return r_;
  }
  auto network = buildScenarioNetwork(s_);
  if (!network.ok()) {
    r_.error = network.error().message();
    return r_;
  }
  network_ = std::move(*network);
  topology::Segment& segment = *network_.segment;
  topology::FaultInjector faults(network_, r_.seed);
  faults_ = &faults;
  std::optional<PcapWriter> writer;
  std::optional<topology::PcapCableTap> tap;
  if (!o_.pcapDir.empty()) {
    auto w = PcapWriter::open((o_.pcapDir / (s_.name + ".pcap")).string());
    if (!w.ok()) {
      r_.error = w.error().message();
      return r_;
    }
    writer.emplace(std::move(*w));
    tap.emplace(*writer, kDcEpochUnixNs);
    segment.setCableObserver(0, 0, &*tap);
  }
  auto [masterEnd, networkEnd] = MemoryLink::makePair(256);
  topology::ServerOptions serverOptions;
  serverOptions.idleWait = std::chrono::nanoseconds(0);
  topology::NetworkServer server(networkEnd, segment, clock_, serverOptions);
  master::VirtualBus bus(clock_, [&](SimTime) -> std::optional<SimTime> {
    const bool waiting = networkEnd.pending() > 0;
    const auto before = server.counters().framesAnswered;
    (void)server.step();
    if (waiting && server.counters().framesAnswered != before) {
      return server.counters().lastRoundTrip;
    }
    return std::nullopt;
  });
  master::MasterOptions mo;
  mo.cycleTime = s_.cycleTime;
  mo.recovery = o_.recovery;
  master_ = std::make_unique<master::Master>(masterEnd, bus, mo);
  // Its events and messages name the slaves as the topology does ("slave 5 (0x1006 'Drive2')").
  master_->setSlaveNames(topology::slaveNamesInBusOrder(segment));
  struct ResetFirst {  // the master goes before the link and bus it uses, on every return
    std::unique_ptr<master::Master>& master;
    ~ResetFirst() { master.reset(); }
  } resetFirst{master_};
  if (auto st = master_->start(); !st.ok()) {
    r_.error = "the master did not reach OP: " + st.error().message();
    segment.setCableObserver(0, 0, nullptr);
    return r_;
  }
  // <Variable name="..."> names exist now that the master has scanned.
  if (auto names = checkVariableNames(s_, master_->variables()); !names.ok()) {
    r_.error = names.error().context;
    segment.setCableObserver(0, 0, nullptr);
    return r_;
  }
  master_->resetStatistics();  // the scenario's figures, from the moment all slaves are in OP
  t0_ = clock_.now();
  learnStations();
  checked_.assign(s_.expectations.size(), false);
  std::vector<bool> applied(s_.actions.size(), false);
  const std::uint64_t total = static_cast<std::uint64_t>(s_.duration / s_.cycleTime);
  SimTime pausedUntil = 0;
  SimTime next = t0_;
  std::uint64_t cycle = 0;
  while (cycle < total) {
    if (clock_.now() > next) {
      // A cycle took longer than its period (a frame waited for until it was given up): the
      // cycles in between had no process data.
      const std::uint64_t skipped =
          static_cast<std::uint64_t>((clock_.now() - next + s_.cycleTime - 1) / s_.cycleTime);
      for (std::uint64_t k = 0; k < skipped && cycle < total; ++k, ++cycle) {
        ++badCycles_;
        longestRun_ = std::max(longestRun_, ++run_);
        cleanCycles_.push_back({cycle, false});
      }
      next += static_cast<SimTime>(skipped) * s_.cycleTime;
      if (cycle >= total) break;
    }
    clock_.set(next);
    // The slaves' firmware runs on its own time, frames or not (an SM watchdog expires while
    // no frame reaches the slave, not when the next one does).
    segment.pollSlaves(clock_.now());
    for (std::size_t i = 0; i < s_.actions.size(); ++i) {
      const auto& a = s_.actions[i];
      if (applied[i]) continue;
      if ((a.cycle && cycle >= *a.cycle) || (a.time && sinceOp() >= *a.time)) {
        applied[i] = true;
        std::string what;
        if (const auto* pause = std::get_if<topology::PauseMaster>(&a.fault)) {
          pausedUntil = saturatingAdd(clock_.now(), pause->duration);
          what = fmt::format("the master sends nothing for {} ms",
                             number(static_cast<double>(pause->duration) / kNsPerMs));
        } else {
          auto done = faults.apply(a.fault, clock_.now(), a.action.where);
          if (!done.ok()) {
            r_.error = done.error().context;
            return r_;
          }
          what = *done;
        }
        r_.log.push_back(fmt::format("{:>12}  cycle {:>6}  {}: {}", ms(sinceOp()), cycle,
                                     a.action.text(), what));
      }
    }
    // "At cycle N": after cycle N's actions, before its exchange.
    checkTimed(cycle, false);
    bool good = false;
    if (clock_.now() < pausedUntil) {
      segment.pollSlaves(clock_.now());
    } else {
      auto st = master_->cycle();
      const auto& last = master_->lastCycle();
      good = st.ok() && last.ok();
      if (last.framesLost > 0) {
        observe(cycle, "frame-lost", {}, fmt::format("{} frame(s) lost", last.framesLost));
      }
      if (last.wkcErrors > 0 && last.firstMismatch) {
        std::set<std::string> names;
        for (auto p : last.firstMismatch->slaves) names.insert(slaveNameAtPosition(p));
        observe(cycle, "wkc-error", names, last.firstMismatch->describe(master_->slaves()));
      }
      if (!st.ok() && last.framesLost == 0 && last.wkcErrors == 0) {
        observe(cycle, st.error().code == ErrorCode::kTimeout ? "frame-lost" : "cycle-error", {},
                st.error().message());
      }
      if (master_->emergencies().size() > emergenciesSeen_) {
        emergenciesSeen_ = master_->emergencies().size();
        observe(cycle, "emergency", {}, "emergency received");
      }
      takeEvents(cycle);
    }
    if (good) {
      run_ = 0;
    } else {
      ++badCycles_;
      longestRun_ = std::max(longestRun_, ++run_);
    }
    cleanCycles_.push_back({cycle, good && cleanCycle()});
    ++cycle;
    next += s_.cycleTime;
  }
  r_.cycles = total;
  checkTimed(total, true);
  evaluateWindows();
  std::stable_sort(r_.results.begin(), r_.results.end(),
                   [](const auto& a, const auto& b) { return a.line < b.line; });
  segment.setCableObserver(0, 0, nullptr);
  if (writer) (void)writer->close();
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

ScenarioResult startResult(const Scenario& scenario, const RunOptions& options) {
  ScenarioResult r;
  r.name = scenario.name;
  r.file = scenario.file.filename().string();
  r.seed = options.seed.value_or(scenario.seed);
  r.cycleTime = scenario.cycleTime;
  return r;
}

Result<topology::Network> buildScenarioNetwork(const Scenario& scenario) {
  ECSIM_ASSIGN_OR_RETURN(auto config, loadTopologyFile(scenario.topology));
  return topology::buildNetwork(config);
}

ScenarioResult runScenario(const Scenario& scenario, const RunOptions& options) {
  Run run(scenario, options);
  return run.execute();
}

}  // namespace ecsim::scenario
