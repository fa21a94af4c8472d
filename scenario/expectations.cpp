#include "scenario/expectations.hpp"

#include <fmt/core.h>

#include <algorithm>

#include "master/master.hpp"
#include "master/process_image.hpp"
#include "protocol/al_status.hpp"
#include "protocol/registers.hpp"
#include "scenario/command_output.hpp"
#include "topology/faults.hpp"
#include "topology/segment.hpp"

namespace ecsim::scenario {
namespace {

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
    case master::MasterEventKind::kRingBroken:
      return "ring-broken";
    case master::MasterEventKind::kRingWhole:
      return "ring-whole";
  }
  return "?";
}

// Conditions that are not an error (any-error does not match them).
bool isGoodNews(std::string_view condition) {
  return condition == "slave-returned" || condition == "slave-recovered" ||
         condition == "ring-whole";
}

bool isPoint(ExpectKind kind) {
  return kind == ExpectKind::kState || kind == ExpectKind::kRegister ||
         kind == ExpectKind::kStatistic || kind == ExpectKind::kVariable;
}

constexpr std::string_view kNeedsOurMaster =
    "not judged: an external master does not show its internals";

}  // namespace

std::string msText(SimTime t) {
  return fmt::format("{:.3f} ms", static_cast<double>(t) / static_cast<double>(kNsPerMs));
}

std::vector<std::string> RunLog::lines(SimTime origin) const {
  std::vector<Entry> sorted = entries_;
  std::stable_sort(sorted.begin(), sorted.end(),
                   [](const auto& a, const auto& b) { return a.at < b.at; });
  std::vector<std::string> out;
  out.reserve(sorted.size());
  for (const auto& e : sorted)
    out.push_back(fmt::format("{:>12}  {}", msText(e.at - origin), e.text));
  return out;
}

Judge::Judge(const Scenario& scenario, const topology::Segment& segment, RunLog& log)
    : s_(scenario),
      segment_(segment),
      log_(log),
      checked_(scenario.expectations.size(), false),
      afterAt_(scenario.expectations.size()),
      backAt_(scenario.expectations.size()) {}

// Which simulated slave got which station address, taken once the master is in OP (a power
// cycle clears the address in the ESC until the master's recovery writes it again).
void Judge::attach(const master::Master* master, const topology::FaultInjector* faults) {
  master_ = master;
  faults_ = faults;
  for (std::size_t i = 0; i < segment_.size(); ++i) {
    const std::uint16_t station = segment_.slave(i).esc().read(reg::kConfiguredStationAddress);
    if (station != 0) stationNames_[station] = segment_.slave(i).name();
  }
}

bool Judge::allOp() const {
  for (std::size_t i = 0; i < segment_.size(); ++i) {
    if (segment_.slave(i).esc().alStatus() != static_cast<std::uint16_t>(AlState::kOp)) {
      return false;
    }
  }
  return segment_.size() > 0;
}

std::optional<std::size_t> Judge::slaveIndex(const std::string& name) const {
  for (std::size_t i = 0; i < segment_.size(); ++i) {
    if (segment_.slave(i).name() == name) return i;
  }
  return std::nullopt;
}

std::string Judge::statesText() const {
  std::string states;
  for (std::size_t k = 0; k < segment_.size(); ++k) {
    const auto& esc = segment_.slave(k).esc();
    states += fmt::format("{}{} {}", k == 0 ? "" : ", ", segment_.slave(k).name(),
                          stateText(esc.alStatus(), esc.read(reg::kAlStatusCode)));
  }
  return states;
}

void Judge::observe(std::uint64_t cycle, SimTime at, SimTime since, const std::string& condition,
                    std::set<std::string> slaves, const std::string& text) {
  auto& last = lastLogged_[condition];
  if (last.first + 1 != cycle || last.second != text) {
    log_.add(at, fmt::format("cycle {:>6}  master: {}", cycle, text));
  }
  last = {cycle, text};
  observations_.push_back({cycle, since, condition, std::move(slaves), text});
}

std::string Judge::slaveNameAtPosition(std::size_t position) const {
  if (master_ == nullptr || position >= master_->slaves().size()) {
    return fmt::format("position {}", position);
  }
  auto it = stationNames_.find(master_->slaves()[position].station);
  return it == stationNames_.end() ? fmt::format("position {}", position) : it->second;
}

void Judge::takeEvents(std::uint64_t cycle, SimTime at, SimTime since) {
  const auto& events = master_->events();
  for (; eventsSeen_ < events.size(); ++eventsSeen_) {
    const master::MasterEvent& e = events[eventsSeen_];
    std::string text = e.text;  // "slave 3 (0x1004 'AI1') lost at cycle 1002": the master's count
    if (auto cut = text.rfind(" at cycle "); cut != std::string::npos) text.erase(cut);
    observe(cycle, at, since, std::string(conditionOf(e.kind)), {slaveNameAtPosition(e.position)},
            text);
  }
}

void Judge::checkDue(std::uint64_t cycle, SimTime since) {
  for (std::size_t i = 0; i < s_.expectations.size(); ++i) {
    const auto& x = s_.expectations[i];
    if (checked_[i] || !isPoint(x.kind)) continue;
    if ((x.atCycle && cycle >= *x.atCycle) || (x.atTime && since >= *x.atTime)) {
      checked_[i] = true;
      results_.push_back(evaluatePoint(x, since));
    }
  }
}

void Judge::sample(std::uint64_t cycle, SimTime since, std::optional<bool> good, bool clean) {
  if (good) {
    if (*good) {
      run_ = 0;
    } else {
      ++badCycles_;
      longestRun_ = std::max(longestRun_, ++run_);
    }
  }
  for (std::size_t i = 0; i < s_.expectations.size(); ++i) {
    const auto& x = s_.expectations[i];
    if (x.kind != ExpectKind::kBackInOp) continue;
    if (!afterAt_[i] && (x.afterTime ? since >= *x.afterTime : cycle >= x.afterCycle)) {
      afterAt_[i] = Point{cycle, since};
    }
    if (afterAt_[i] && !backAt_[i] && clean) backAt_[i] = Point{cycle, since};
  }
}

std::optional<double> Judge::statistic(const Expectation& x) const {
  const auto& st = master_->statistics();
  if (x.name == "framesLost") return static_cast<double>(st.framesLost);
  if (x.name == "wkcErrors") return static_cast<double>(st.wkcErrors);
  if (x.name == "cyclesWithErrors") return static_cast<double>(st.cyclesWithErrors);
  if (x.name == "cycles") return static_cast<double>(st.cycles);
  if (x.name == "badCycles") return static_cast<double>(badCycles_);
  if (x.name == "emergencies") return static_cast<double>(master_->emergencies().size());
  if (x.name == "framesCorrupted") {
    return faults_ ? static_cast<double>(faults_->framesCorrupted()) : 0.0;
  }
  if (x.name == "slavesLost" || x.name == "slavesRecovered" || x.name == "framesLate") {
    const auto h = master_->health();
    if (x.name == "slavesLost") return static_cast<double>(h.slavesLost);
    if (x.name == "slavesRecovered") return static_cast<double>(h.slavesRecovered);
    return static_cast<double>(h.framesLate);
  }
  // How often the master reported a condition (Detected's names), of one slave when the
  // expectation names one.
  static constexpr std::string_view kConditions[] = {
      "wkc-error",       "frame-lost",  "emergency",   "slave-lost",
      "slave-returned",  "slave-reset", "slave-state", "slave-recovered",
      "recovery-failed", "ring-broken", "ring-whole"};
  if (std::find(std::begin(kConditions), std::end(kConditions), x.name) == std::end(kConditions)) {
    return std::nullopt;
  }
  std::size_t n = 0;
  for (const auto& o : observations_) {
    if (o.condition == x.name && (x.slave.empty() || o.slaves.count(x.slave) > 0)) ++n;
  }
  return static_cast<double>(n);
}

ExpectationResult Judge::evaluatePoint(const Expectation& x, SimTime since) const {
  ExpectationResult res{x.line, x.describe(), false, since, {}, x.needsRecovery};
  std::optional<std::size_t> slave;
  if (!x.slave.empty()) {
    slave = slaveIndex(x.slave);
    if (!slave) {
      res.observed = "no slave named '" + x.slave + "' in the topology";
      return res;
    }
  }
  const bool inner = x.kind == ExpectKind::kStatistic || x.kind == ExpectKind::kVariable;
  if (inner && master_ == nullptr) {
    res.observed = kNeedsOurMaster;
    return res;
  }
  if (x.kind == ExpectKind::kState) {
    const auto& esc = segment_.slave(*slave).esc();
    const std::uint16_t status = esc.alStatus();
    const std::uint16_t code = esc.read(reg::kAlStatusCode);
    res.observed = stateText(status, code);
    auto state = alStateFromRaw(static_cast<std::uint16_t>(status & kAlStateMask));
    bool ok = state && toString(*state) == x.state;
    if (x.error) ok = ok && (((status & 0x10) != 0) == *x.error);
    if (x.code) ok = ok && code == *x.code;
    res.passed = ok;
  } else if (x.kind == ExpectKind::kRegister) {
    const auto& esc = segment_.slave(*slave).esc();
    std::uint32_t raw = x.width == 1   ? esc.reg8(x.address)
                        : x.width == 2 ? esc.reg16(x.address)
                                       : esc.reg32(x.address);
    raw &= x.mask;
    const double v = static_cast<double>(raw);
    res.observed = fmt::format("{} ({:#x})", number(v), raw);
    res.passed = compareValues(v, x.compare, x.value, x.tolerance);
  } else if (x.kind == ExpectKind::kStatistic) {
    const auto v = statistic(x);
    if (!v) {
      res.observed = "unknown statistic '" + x.name + "'";
      return res;
    }
    res.observed = number(*v);
    res.passed = compareValues(*v, x.compare, x.value, x.tolerance);
  } else if (x.kind == ExpectKind::kVariable) {
    std::optional<std::size_t> position;
    if (slave) {
      const std::uint16_t station =
          segment_.slave(*slave).esc().read(reg::kConfiguredStationAddress);
      for (const auto& info : master_->slaves()) {
        if (info.station == station) position = info.position;
      }
    }
    std::optional<master::ProcessVariable> var;
    if (!x.variable.empty()) {  // by name (checked when the master reached OP)
      if (auto v = master::findVariable(master_->variables(), x.variable); v.ok()) {
        var = master::ProcessVariable{v->position, v->output,   v->bitOffset, v->bitLength,
                                      v->index,    v->subindex, {},           v->entry};
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
      return res;
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
  }
  return res;
}

ExpectationResult Judge::evaluateDetected(const Expectation& x, SimTime since) const {
  ExpectationResult res{x.line, x.describe(), false, since, {}, x.needsRecovery};
  if (master_ == nullptr) {
    res.observed = kNeedsOurMaster;
    return res;
  }
  const std::uint64_t last = x.afterCycle + x.withinCycles;
  std::vector<std::string> seen;
  for (const auto& o : observations_) {
    if (o.cycle < x.afterCycle) continue;
    const bool match =
        ((x.condition == "any-error" && !isGoodNews(o.condition)) || o.condition == x.condition) &&
        (x.slave.empty() || o.slaves.count(x.slave) > 0);
    if (match && o.cycle <= last) {
      res.passed = true;
      res.at = o.since;
      res.observed = fmt::format("at cycle {} ({} cycles after {}): {}", o.cycle,
                                 o.cycle - x.afterCycle, x.afterCycle, o.text);
      return res;
    }
    if (seen.size() < 3) seen.push_back(fmt::format("cycle {}: {}", o.cycle, o.text));
  }
  res.observed = seen.empty()
                     ? fmt::format("nothing observed from cycle {} to {}", x.afterCycle, last)
                     : "not within the window; observed " + seen.front();
  return res;
}

// Back in OP: the first clean tick at or after the expectation's "after" (cycle or time),
// within its time. A clean tick: every slave in OP (simulator side) while process data flows;
// with our master also a cycle without error and the master exchanging with every slave.
ExpectationResult Judge::evaluateBackInOp(std::size_t i, const RunEnd& end) const {
  const auto& x = s_.expectations[i];
  const SimTime since = end.zero ? end.at - *end.zero : 0;
  ExpectationResult res{x.line, x.describe(), false, since, {}, x.needsRecovery};
  if (!end.zero) {
    res.observed = "the network never had all slaves in OP";
    return res;
  }
  const std::string after =
      x.afterTime ? msText(*x.afterTime) : fmt::format("cycle {}", x.afterCycle);
  if (!afterAt_[i]) {
    res.observed = "the run ended before " + after;
    return res;
  }
  if (!backAt_[i]) {
    res.observed = "never back in OP after " + after + "; at the end: " + statesText();
    return res;
  }
  const SimTime took = backAt_[i]->since - afterAt_[i]->since;
  const std::string afterShort = x.afterTime ? msText(*x.afterTime) : std::to_string(x.afterCycle);
  if (took <= x.within) {
    res.passed = true;
    res.at = backAt_[i]->since;
    res.observed = fmt::format("all slaves in OP with a clean cycle at cycle {} ({} after {})",
                               backAt_[i]->cycle, msText(took), afterShort);
  } else {
    res.observed = fmt::format("first back in OP at cycle {} ({} after {}), too late",
                               backAt_[i]->cycle, msText(took), after);
  }
  return res;
}

ExpectationResult Judge::evaluateCommand(std::size_t i, const RunEnd& end,
                                         const CommandFacts* command) const {
  const auto& x = s_.expectations[i];
  const SimTime origin = end.zero.value_or(command != nullptr ? command->start : end.at);
  ExpectationResult res{x.line, x.describe(), false, end.at - origin, {}, x.needsRecovery};
  if (command == nullptr || command->output == nullptr) {
    res.observed = "not judged: no command was run (Master kind=\"external\" runs one)";
    return res;
  }
  if (x.kind == ExpectKind::kExitStatus) {
    if (!command->exitStatus) {
      res.observed = "no exit status (" + command->exitHow + ")";
      return res;
    }
    res.passed = compareValues(*command->exitStatus, x.compare, x.value, x.tolerance);
    res.observed = fmt::format("exit status {}{}", *command->exitStatus, command->exitHow);
    return res;
  }
  if (x.afterTime && !end.zero) {
    res.observed = "the network never had all slaves in OP: no time zero to count afterMs from";
    return res;
  }
  const CommandOutput& output = *command->output;
  const OutputTally& tally = output.tallies()[i];
  if (x.countLines) {
    res.passed = compareValues(static_cast<double>(tally.found), x.compare, x.value, x.tolerance);
  } else {
    res.passed = tally.found > 0;
  }
  const std::string window = x.afterTime ? fmt::format(" seen from {} to {}", msText(*x.afterTime),
                                                       msText(*x.afterTime + x.within))
                                         : std::string();
  if (!tally.first) {
    res.observed = fmt::format("not found in the {} lines of output{}", output.lineCount(), window);
  } else {
    res.observed =
        fmt::format("{} of {} lines{}, the first at {}: '{}'", tally.found, output.lineCount(),
                    window, msText(tally.first->at - origin), tally.first->text);
  }
  return res;
}

std::vector<ExpectationResult> Judge::finish(const RunEnd& end, const CommandFacts* command) {
  const SimTime since = end.zero ? end.at - *end.zero : 0;
  std::vector<ExpectationResult> out = results_;
  // What is due at the end (no time given, or a time after the last tick of a run that went
  // its full duration) is judged on the state at the end.
  for (std::size_t i = 0; i < s_.expectations.size(); ++i) {
    const auto& x = s_.expectations[i];
    if (checked_[i] || !isPoint(x.kind)) continue;
    const bool timed = x.atCycle || x.atTime;
    if (end.zero && (!timed || end.ranToEnd)) {
      out.push_back(evaluatePoint(x, since));
    } else {
      out.push_back({x.line, x.describe(), false, since,
                     !end.zero
                         ? "not reached: the network never had all slaves in OP"
                         : "not reached: the run ended at " + msText(since) + " (" + end.text + ")",
                     x.needsRecovery});
    }
  }
  for (std::size_t i = 0; i < s_.expectations.size(); ++i) {
    const auto& x = s_.expectations[i];
    switch (x.kind) {
      case ExpectKind::kDetected:
        out.push_back(evaluateDetected(x, since));
        break;
      case ExpectKind::kBackInOp:
        out.push_back(evaluateBackInOp(i, end));
        break;
      case ExpectKind::kContinuity: {
        ExpectationResult res{x.line, x.describe(), false, since, {}, x.needsRecovery};
        if (master_ == nullptr) {
          res.observed = kNeedsOurMaster;
        } else {
          res.passed = badCycles_ <= x.maxBadCycles && longestRun_ <= x.maxConsecutiveBadCycles;
          res.observed = fmt::format("{} cycles without fresh process data, longest run {}",
                                     badCycles_, longestRun_);
        }
        out.push_back(res);
        break;
      }
      case ExpectKind::kExitStatus:
      case ExpectKind::kOutput:
        out.push_back(evaluateCommand(i, end, command));
        break;
      default:
        break;
    }
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const auto& a, const auto& b) { return a.line < b.line; });
  return out;
}

}  // namespace ecsim::scenario
