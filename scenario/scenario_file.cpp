// Reads scenario files (docs/scenarios.md) with tinyxml2; errors name file and line.
#include <tinyxml2.h>

#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <sstream>

#include "config/topology_file.hpp"
#include "config/xml_util.hpp"
#include "protocol/closest_name.hpp"
#include "protocol/read_file.hpp"
#include "scenario/command_output.hpp"
#include "scenario/scenario.hpp"

namespace ecsim::scenario {
namespace {

using tinyxml2::XMLElement;

// Ranges of a scenario's numbers (docs/scenarios.md): times at most a day, as for the fault
// actions; cycle counts at most those of a day at the shortest cycle (50 us).
constexpr double kMaxMs = static_cast<double>(topology::kMaxFaultDurationMs);
constexpr std::uint64_t kMaxCycles = 2'000'000'000;
constexpr std::uint64_t kMinCycleUs = 50;
constexpr std::uint64_t kMaxCycleUs = 1'000'000;

// What each element takes (docs/scenarios.md); anything else is an error (xml::checkNames).
// Every expectation takes needsRecovery; `when` is cycle/atMs.
const xml::Names kScenarioNames{{"name", "topology", "cycleUs", "durationMs", "seed"},
                                {"Description", "Master", "Timeline", "Expect"},
                                {"Description", "Master", "Timeline", "Expect"}};
const xml::Names kDescriptionNames{{}};
const xml::Names kMasterNames{{"kind", "command", "startTimeoutMs", "stopGraceMs", "timeZero"}};
const xml::Names kTimelineNames{{}, {"Action"}};
const std::map<std::string_view, xml::Names, std::less<>> kExpectationNames{
    {"State", {{"slave", "state", "error", "code", "cycle", "atMs", "needsRecovery"}}},
    {"Detected",
     {{"condition", "slave", "afterCycle", "afterMs", "withinCycles", "withinMs",
       "needsRecovery"}}},
    {"BackInOp", {{"afterCycle", "afterMs", "withinCycles", "withinMs", "needsRecovery"}}},
    {"Register",
     {{"slave", "address", "width", "mask", "op", "value", "tolerance", "cycle", "atMs",
       "needsRecovery"}}},
    {"Statistic",
     {{"name", "slave", "op", "value", "tolerance", "cycle", "atMs", "needsRecovery"}}},
    {"Continuity", {{"maxBadCycles", "maxConsecutiveBadCycles", "needsRecovery"}}},
    {"Variable",
     {{"name", "slave", "entry", "mask", "signed", "op", "value", "tolerance", "cycle", "atMs",
       "needsRecovery"}}},
    // cycle and atMs are refused below with the reason (judged when the command has ended).
    {"ExitStatus", {{"op", "value", "tolerance", "needsRecovery", "cycle", "atMs"}}},
    {"Output",
     {{"contains", "matches", "op", "value", "tolerance", "afterMs", "withinMs", "needsRecovery",
       "cycle", "atMs"}}},
};
const xml::Names kExpectNames = [] {  // the expectations above
  xml::Names names{{}};
  for (const auto& [tag, attributes] : kExpectationNames) names.children.push_back(tag);
  return names;
}();
// An <Action>'s own attributes; the others are its verb's arguments.
constexpr std::array<std::string_view, 3> kActionAttributes{"cycle", "timeMs", "do"};

class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)), ctx_(file_) {}
  const xml::Context& context() const { return ctx_; }
  // The scenario's folder: relative files of its actions are found there.
  std::filesystem::path folder() const { return std::filesystem::path(file_).parent_path(); }

  Error error(const XMLElement* e, const std::string& what) const { return ctx_.error(e, what); }
  std::string where(const XMLElement* e) const {
    return file_ + ", line " + std::to_string(e->GetLineNum());
  }

  static std::optional<std::string> attr(const XMLElement* e, const char* name) {
    const char* v = e->Attribute(name);
    if (v == nullptr) return std::nullopt;
    return std::string(v);
  }
  // An integer attribute (decimal or 0x hex) in [lo, hi]; nullopt when absent. Values that do
  // not fit are refused with the range, never truncated.
  Result<std::optional<std::uint64_t>> number(const XMLElement* e, const char* name,
                                              std::uint64_t lo, std::uint64_t hi) const {
    auto text = attr(e, name);
    if (!text) return std::optional<std::uint64_t>();
    auto v = topology::parseNumber(*text);
    if (!v || *v < lo || *v > hi) {
      return error(e, fmt::format("{}=\"{}\" is not a number in [{}, {}]", name, *text, lo, hi));
    }
    return std::optional<std::uint64_t>(*v);
  }
  // A finite real attribute in [lo, hi]; nullopt when absent.
  Result<std::optional<double>> real(const XMLElement* e, const char* name,
                                     double lo = -std::numeric_limits<double>::max(),
                                     double hi = std::numeric_limits<double>::max()) const {
    auto text = attr(e, name);
    if (!text) return std::optional<double>();
    double v = 0;
    if (auto n = topology::parseNumber(*text)) {
      v = static_cast<double>(*n);
    } else {
      char* end = nullptr;
      v = std::strtod(text->c_str(), &end);
      if (end == text->c_str() || *end != '\0') v = std::nan("");
    }
    if (!(v >= lo && v <= hi)) {  // NaN fails: refused with the rest
      constexpr double kMax = std::numeric_limits<double>::max();
      const std::string range = hi == kMax ? (lo == -kMax ? std::string("finite number")
                                                          : fmt::format("finite number >= {}", lo))
                                           : fmt::format("number in [{}, {}]", lo, hi);
      return error(e, fmt::format("{}=\"{}\" is not a {}", name, *text, range));
    }
    return std::optional<double>(v);
  }
  // A time in milliseconds, [0, kMaxMs], as nanoseconds.
  Result<std::optional<SimTime>> millis(const XMLElement* e, const char* name) const {
    ECSIM_ASSIGN_OR_RETURN(auto v, real(e, name, 0, kMaxMs));
    if (!v) return std::optional<SimTime>();
    return std::optional<SimTime>(saturatingTime(*v * static_cast<double>(kNsPerMs)));
  }
  Result<std::optional<bool>> boolean(const XMLElement* e, const char* name) const {
    auto text = attr(e, name);
    if (!text) return std::optional<bool>();
    if (*text == "true" || *text == "1") return std::optional<bool>(true);
    if (*text == "false" || *text == "0") return std::optional<bool>(false);
    return error(e, std::string(name) + "=\"" + *text + "\" is not true or false");
  }

 private:
  std::string file_;
  xml::Context ctx_;
};

Result<Compare> parseCompare(const Reader& r, const XMLElement* e) {
  const auto op = Reader::attr(e, "op").value_or("eq");
  if (op == "eq") return Compare::kEq;
  if (op == "ne") return Compare::kNe;
  if (op == "lt") return Compare::kLt;
  if (op == "le") return Compare::kLe;
  if (op == "gt") return Compare::kGt;
  if (op == "ge") return Compare::kGe;
  return r.error(e, "op=\"" + op + "\" is not one of eq, ne, lt, le, gt, ge");
}

// `cycleTime`: our master's, for durationCycles (0 for an external master, which keeps its own).
Result<TimedAction> readAction(const Reader& r, const XMLElement* e, SimTime cycleTime) {
  TimedAction a;
  a.line = e->GetLineNum();
  a.action.where = r.where(e);
  auto verb = Reader::attr(e, "do");
  if (!verb) return r.error(e, "an Action needs do=\"VERB\"");
  a.action.verb = *verb;
  const std::vector<std::string_view> verbs = topology::faultVerbs(topology::FaultScope::kScenario);
  if (std::find(verbs.begin(), verbs.end(), a.action.verb) == verbs.end()) {
    return r.error(e, unknownNameText("action", a.action.verb, verbs));
  }
  // Its verb's arguments and the Action's own attributes; a misspelt one is an error naming the
  // closest of them ("delay: unknown argument 'durationMS'; did you mean 'durationMs'?").
  std::vector<std::string_view> keys =
      topology::faultArguments(a.action.verb, topology::FaultScope::kScenario);
  keys.insert(keys.end(), kActionAttributes.begin(), kActionAttributes.end());
  for (const auto* at = e->FirstAttribute(); at != nullptr; at = at->Next()) {
    if (std::find(keys.begin(), keys.end(), at->Name()) == keys.end()) {
      return a.action.error(unknownNameText("argument", at->Name(), keys));
    }
  }
  ECSIM_TRY(xml::checkNames(r.context(), e, {keys}));  // and no child elements
  ECSIM_ASSIGN_OR_RETURN(a.cycle, r.number(e, "cycle", 0, kMaxCycles));
  ECSIM_ASSIGN_OR_RETURN(a.time, r.millis(e, "timeMs"));
  if (a.cycle.has_value() == a.time.has_value()) {
    return r.error(e, "an Action needs exactly one of cycle=\"N\" and timeMs=\"T\"");
  }
  for (const auto* at = e->FirstAttribute(); at != nullptr; at = at->Next()) {
    const std::string key = at->Name();
    if (key == "cycle" || key == "timeMs" || key == "do") continue;
    a.action.args[key] = at->Value();
  }
  // Every argument now, not when the timeline reaches the action.
  ECSIM_ASSIGN_OR_RETURN(a.fault,
                         topology::parseFault(a.action, {topology::FaultScope::kScenario, cycleTime,
                                                         r.folder()}));
  return a;
}

// Cycles of our master in a time: the first cycle starting at or after `t` (a moment), or as
// many cycles as cover `t` (a span).
std::uint64_t cyclesIn(SimTime t, SimTime cycleTime) {
  return cycleTime == 0 ? 0 : static_cast<std::uint64_t>((t + cycleTime - 1) / cycleTime);
}

// At most one of a moment's or span's two forms, NAMEMs and NAMECycle(s) (docs/scenarios.md:
// "either, never both").
Status notBoth(const Reader& r, const XMLElement* e, const char* cycles, const char* ms) {
  if (e->Attribute(cycles) != nullptr && e->Attribute(ms) != nullptr) {
    return r.error(e, fmt::format("{} takes {}=\"N\" or {}=\"T\", not both", e->Name(), cycles,
                                  ms));
  }
  return okStatus();
}

// `cycleTime`: our master's, which converts times to cycles and back (0 for an external master,
// whose cycles are the process-data frames it sends).
Result<Expectation> readExpectation(const Reader& r, const XMLElement* e, SimTime cycleTime) {
  Expectation x;
  x.line = e->GetLineNum();
  const std::string tag = e->Name();
  const auto table = kExpectationNames.find(tag);
  if (table == kExpectationNames.end()) {  // kExpectNames lists them all
    return r.error(e, "unknown expectation <" + tag + ">");
  }
  ECSIM_TRY(xml::checkNames(r.context(), e, table->second));
  ECSIM_TRY(notBoth(r, e, "cycle", "atMs"));
  ECSIM_TRY(notBoth(r, e, "afterCycle", "afterMs"));
  ECSIM_TRY(notBoth(r, e, "withinCycles", "withinMs"));
  ECSIM_ASSIGN_OR_RETURN(x.atCycle, r.number(e, "cycle", 0, kMaxCycles));
  ECSIM_ASSIGN_OR_RETURN(x.atTime, r.millis(e, "atMs"));
  ECSIM_ASSIGN_OR_RETURN(auto needs, r.boolean(e, "needsRecovery"));
  x.needsRecovery = needs.value_or(false);
  x.slave = Reader::attr(e, "slave").value_or("");
  ECSIM_ASSIGN_OR_RETURN(x.compare, parseCompare(r, e));
  ECSIM_ASSIGN_OR_RETURN(auto value, r.real(e, "value"));
  ECSIM_ASSIGN_OR_RETURN(auto tolerance,
                         r.real(e, "tolerance", 0, std::numeric_limits<double>::max()));
  x.value = value.value_or(0);
  x.tolerance = tolerance.value_or(0);
  auto needSlave = [&]() -> Status {
    if (x.slave.empty()) return r.error(e, tag + " needs slave=\"NAME\"");
    return okStatus();
  };
  auto needValue = [&]() -> Status {
    if (!value) return r.error(e, tag + " needs value=\"N\"");
    return okStatus();
  };
  if (tag == "State") {
    x.kind = ExpectKind::kState;
    ECSIM_TRY(needSlave());
    x.state = Reader::attr(e, "state").value_or("");
    if (x.state != "INIT" && x.state != "PREOP" && x.state != "SAFEOP" && x.state != "OP" &&
        x.state != "BOOT") {
      return r.error(e, "State needs state=\"INIT|PREOP|SAFEOP|OP|BOOT\"");
    }
    ECSIM_ASSIGN_OR_RETURN(x.error, r.boolean(e, "error"));
    ECSIM_ASSIGN_OR_RETURN(auto code, r.number(e, "code", 0, 0xFFFF));
    if (code) x.code = static_cast<std::uint16_t>(*code);
  } else if (tag == "Detected") {
    x.kind = ExpectKind::kDetected;
    x.condition = Reader::attr(e, "condition").value_or("");
    if (std::find(std::begin(kDetectableConditions), std::end(kDetectableConditions),
                  x.condition) == std::end(kDetectableConditions)) {
      std::string names;
      for (std::string_view c : kDetectableConditions) {
        names += (names.empty() ? "" : ", ") + std::string(c);
      }
      return r.error(e, "condition must be one of " + names);
    }
    // Counted in cycles; times are converted with the cycle time (our master's only).
    ECSIM_ASSIGN_OR_RETURN(auto after, r.number(e, "afterCycle", 0, kMaxCycles));
    ECSIM_ASSIGN_OR_RETURN(auto afterMs, r.millis(e, "afterMs"));
    ECSIM_ASSIGN_OR_RETURN(auto within, r.number(e, "withinCycles", 0, kMaxCycles));
    ECSIM_ASSIGN_OR_RETURN(auto withinMs, r.millis(e, "withinMs"));
    if (!within && !withinMs) {
      return r.error(e, "Detected needs withinCycles=\"N\" or withinMs=\"T\"");
    }
    x.afterCycle = after ? *after : afterMs ? cyclesIn(*afterMs, cycleTime) : 0;
    x.withinCycles = within ? *within : cyclesIn(*withinMs, cycleTime);
  } else if (tag == "BackInOp") {
    x.kind = ExpectKind::kBackInOp;
    ECSIM_ASSIGN_OR_RETURN(auto after, r.number(e, "afterCycle", 0, kMaxCycles));
    ECSIM_ASSIGN_OR_RETURN(auto afterMs, r.millis(e, "afterMs"));
    ECSIM_ASSIGN_OR_RETURN(auto within, r.millis(e, "withinMs"));
    ECSIM_ASSIGN_OR_RETURN(auto withinCycles, r.number(e, "withinCycles", 0, kMaxCycles));
    if (!within && !withinCycles) {
      return r.error(e, "BackInOp needs withinMs=\"T\" or withinCycles=\"N\"");
    }
    if (withinCycles && cycleTime == 0) {
      return r.error(e, "withinCycles needs our master's cycle time (an external master keeps "
                        "its own): give withinMs");
    }
    x.within = within ? *within : saturatingMul(static_cast<SimTime>(*withinCycles), cycleTime);
    x.afterCycle = after.value_or(0);
    if (afterMs && cycleTime != 0) {
      x.afterCycle = cyclesIn(*afterMs, cycleTime);  // ours: the cycle starting then
    } else {
      x.afterTime = afterMs;  // an external master's: a time after time zero
    }
  } else if (tag == "ExitStatus" || tag == "Output") {
    // External masters: judged once the command has ended.
    if (x.atCycle || x.atTime) {
      return r.error(e, tag + " is checked when the command has ended: no cycle or atMs");
    }
    if (tag == "ExitStatus") {
      x.kind = ExpectKind::kExitStatus;
      ECSIM_TRY(needValue());
    } else {
      x.kind = ExpectKind::kOutput;
      auto contains = Reader::attr(e, "contains");
      auto matches = Reader::attr(e, "matches");
      if (contains.has_value() == matches.has_value() ||
          (contains ? *contains : *matches).empty()) {
        return r.error(e, "Output needs exactly one of contains=\"TEXT\" and matches=\"REGEX\"");
      }
      ECSIM_ASSIGN_OR_RETURN(x.afterTime, r.millis(e, "afterMs"));
      ECSIM_ASSIGN_OR_RETURN(auto within, r.millis(e, "withinMs"));
      if (x.afterTime.has_value() != within.has_value()) {
        return r.error(e, "Output takes afterMs and withinMs together");
      }
      x.within = within.value_or(0);
      x.isRegex = matches.has_value();
      x.text = contains ? *contains : *matches;
      x.countLines = value.has_value();
      if (!x.countLines && Reader::attr(e, "op")) {
        return r.error(e, "Output with op=\"...\" needs value=\"N\" (a number of lines)");
      }
      if (x.isRegex) {
        if (auto p = OutputPattern::compile(x.text); !p.ok()) {
          const std::string shown = x.text.size() > 60 ? x.text.substr(0, 60) + "..." : x.text;
          return r.error(e, "matches=\"" + shown + "\": " + p.error().context);
        }
      }
    }
  } else if (tag == "Register") {
    x.kind = ExpectKind::kRegister;
    ECSIM_TRY(needSlave());
    ECSIM_TRY(needValue());
    ECSIM_ASSIGN_OR_RETURN(auto address, r.number(e, "address", 0, 0x0FFF));
    ECSIM_ASSIGN_OR_RETURN(auto width, r.number(e, "width", 1, 4));
    if (!address || *address >= 0x1000)
      return r.error(e, "Register needs address=\"0x0000-0x0FFF\"");
    x.address = static_cast<std::uint16_t>(*address);
    x.width = static_cast<unsigned>(width.value_or(1));
    ECSIM_ASSIGN_OR_RETURN(auto mask, r.number(e, "mask", 0, 0xFFFFFFFF));
    x.mask = static_cast<std::uint32_t>(mask.value_or(0xFFFFFFFF));
    if (x.width != 1 && x.width != 2 && x.width != 4) return r.error(e, "width must be 1, 2 or 4");
  } else if (tag == "Statistic") {
    x.kind = ExpectKind::kStatistic;
    ECSIM_TRY(needValue());
    x.name = Reader::attr(e, "name").value_or("");
    if (x.name.empty()) return r.error(e, "Statistic needs name=\"...\"");
  } else if (tag == "Continuity") {
    x.kind = ExpectKind::kContinuity;
    ECSIM_ASSIGN_OR_RETURN(auto bad, r.number(e, "maxBadCycles", 0, kMaxCycles));
    ECSIM_ASSIGN_OR_RETURN(auto run, r.number(e, "maxConsecutiveBadCycles", 0, kMaxCycles));
    if (!bad && !run) {
      return r.error(e, "Continuity needs maxBadCycles and/or maxConsecutiveBadCycles");
    }
    x.maxBadCycles = bad.value_or(UINT64_MAX);
    x.maxConsecutiveBadCycles = run.value_or(UINT64_MAX);
  } else if (tag == "Variable") {
    x.kind = ExpectKind::kVariable;
    ECSIM_TRY(needValue());
    // By the master's name for it ("Drive1.Statusword", looked up when the master has scanned:
    // checkVariableNames), or by slave and entry.
    if (auto name = Reader::attr(e, "name")) {
      if (name->empty()) return r.error(e, "Variable name=\"\" is empty");
      if (e->Attribute("slave") != nullptr || e->Attribute("entry") != nullptr) {
        return r.error(e, "Variable takes name=\"SLAVE.ENTRY\" or slave and entry, not both");
      }
      x.variable = *name;
      ECSIM_ASSIGN_OR_RETURN(auto mask, r.number(e, "mask", 0, 0xFFFFFFFF));
      x.mask = static_cast<std::uint32_t>(mask.value_or(0xFFFFFFFF));
      ECSIM_ASSIGN_OR_RETURN(auto isSigned, r.boolean(e, "signed"));
      x.isSigned = isSigned.value_or(false);
      return x;
    }
    if (x.slave.empty()) {
      return r.error(e, "Variable needs name=\"SLAVE.ENTRY\" or slave=\"NAME\" entry=\"0xINDEX:SUB\"");
    }
    const auto entry = Reader::attr(e, "entry").value_or("");
    const auto colon = entry.find(':');
    auto index = topology::parseNumber(entry.substr(0, colon));
    auto sub = colon == std::string::npos ? std::optional<std::uint64_t>()
                                          : topology::parseNumber(entry.substr(colon + 1));
    if (!index || !sub || *index > 0xFFFF || *sub > 0xFF) {
      return r.error(e, "Variable needs entry=\"0xINDEX:SUB\"");
    }
    x.index = static_cast<std::uint16_t>(*index);
    x.subindex = static_cast<std::uint8_t>(*sub);
    ECSIM_ASSIGN_OR_RETURN(auto mask, r.number(e, "mask", 0, 0xFFFFFFFF));
    x.mask = static_cast<std::uint32_t>(mask.value_or(0xFFFFFFFF));
    ECSIM_ASSIGN_OR_RETURN(auto isSigned, r.boolean(e, "signed"));
    x.isSigned = isSigned.value_or(false);
  } else {
    return r.error(e, "unknown expectation <" + tag + ">");
  }
  return x;
}

// Before anything runs: no action and no expectation after the end of the run. Ours runs the
// cycles 0 .. durationMs/cycleUs - 1 and checks at the end what is due then; an external
// master runs durationMs after time zero and counts its own cycles (frames), which are not
// known before.
struct RunEnd {
  bool external;
  std::uint64_t cycles;    // ours: the number of cycles
  SimTime lastCycleStart;  // ours: when the last cycle starts
  SimTime duration;
};
RunEnd runEnd(const Scenario& s) {
  const auto cycles = static_cast<std::uint64_t>(s.duration / s.cycleTime);
  return {s.masterKind == "external", cycles, static_cast<SimTime>(cycles - 1) * s.cycleTime,
          s.duration};
}
std::string msText(SimTime t) {
  return fmt::format("{}", static_cast<double>(t) / static_cast<double>(kNsPerMs));
}
Error afterTheEnd(const Reader& r, const XMLElement* e, const char* attribute,
                  const std::string& end) {
  return r.error(e, fmt::format("{}=\"{}\" is after the end of the run ({})", attribute,
                                e->Attribute(attribute), end));
}

Status checkWithinRun(const Reader& r, const XMLElement* e, const Scenario& s,
                      const TimedAction& a) {
  const RunEnd end = runEnd(s);
  const std::string duration = "durationMs=" + msText(end.duration) + " after time zero";
  if (end.external) {
    if (a.time && *a.time > end.duration) return afterTheEnd(r, e, "timeMs", duration);
    return okStatus();
  }
  if (a.cycle && *a.cycle >= end.cycles) {
    return afterTheEnd(r, e, "cycle", fmt::format("its last cycle is {}", end.cycles - 1));
  }
  if (a.time && *a.time > end.lastCycleStart) {
    return afterTheEnd(r, e, "timeMs",
                       "its last cycle starts at " + msText(end.lastCycleStart) + " ms");
  }
  return okStatus();
}

Status checkWithinRun(const Reader& r, const XMLElement* e, const Scenario& s,
                      const Expectation& x) {
  const RunEnd end = runEnd(s);
  const std::string duration = "durationMs=" + msText(end.duration);
  const std::string cycles = fmt::format("{} cycles", end.cycles);
  if (x.atTime && *x.atTime > end.duration) return afterTheEnd(r, e, "atMs", duration);
  if (x.afterTime && *x.afterTime > end.duration) return afterTheEnd(r, e, "afterMs", duration);
  if (end.external) return okStatus();
  if (x.atCycle && *x.atCycle > end.cycles) return afterTheEnd(r, e, "cycle", cycles);
  const bool window = x.kind == ExpectKind::kDetected || x.kind == ExpectKind::kBackInOp;
  const char* after = e->Attribute("afterCycle") != nullptr ? "afterCycle"
                      : e->Attribute("afterMs") != nullptr  ? "afterMs"
                                                            : nullptr;
  if (window && after != nullptr && x.afterCycle >= end.cycles) {
    return afterTheEnd(r, e, after, fmt::format("its last cycle is {}", end.cycles - 1));
  }
  return okStatus();
}

}  // namespace

Result<Scenario> loadScenario(const std::filesystem::path& path) {
  ECSIM_ASSIGN_OR_RETURN(const std::string text, readRegularFile(path, kMaxXmlFileBytes));
  ECSIM_ASSIGN_OR_RETURN(Scenario s, parseScenario(text, path));
  auto topology = loadTopologyFile(s.topology);
  if (!topology.ok()) {
    return makeError(topology.error().code,
                     fmt::format("{}, line {}: topology=\"{}\": {}", path.string(), s.line,
                                 s.topology.filename().string(), topology.error().context));
  }
  ECSIM_TRY(checkTopologyNames(s, *topology));
  return s;
}

Result<Scenario> parseScenario(std::string_view xml, const std::filesystem::path& path) {
  Reader r(path.string());
  tinyxml2::XMLDocument doc;
  ECSIM_TRY(xml::parseDocument(xml, r.context(), doc));
  const XMLElement* root = doc.RootElement();
  if (root == nullptr || std::string_view(root->Name()) != "Scenario") {
    return r.error(root, "the root element must be <Scenario>");
  }
  ECSIM_TRY(xml::checkNames(r.context(), root, kScenarioNames));
  Scenario s;
  s.file = path;
  s.line = root->GetLineNum();
  s.name = Reader::attr(root, "name").value_or(path.stem().string());
  auto topology = Reader::attr(root, "topology");
  if (!topology) return r.error(root, "Scenario needs topology=\"PATH\"");
  s.topology = path.parent_path() / *topology;
  ECSIM_ASSIGN_OR_RETURN(auto cycleUs, r.number(root, "cycleUs", kMinCycleUs, kMaxCycleUs));
  ECSIM_ASSIGN_OR_RETURN(auto duration, r.millis(root, "durationMs"));
  ECSIM_ASSIGN_OR_RETURN(auto seed,
                         r.number(root, "seed", 0, std::numeric_limits<std::uint64_t>::max()));
  if (cycleUs) s.cycleTime = saturatingMul(static_cast<SimTime>(*cycleUs), kNsPerUs);
  if (duration) s.duration = *duration;
  if (s.duration < s.cycleTime) return r.error(root, "durationMs is shorter than one cycle");
  s.seed = seed.value_or(1);
  if (const auto* d = root->FirstChildElement("Description")) {
    ECSIM_TRY(xml::checkNames(r.context(), d, kDescriptionNames));
    if (d->GetText() != nullptr) s.description = d->GetText();
  }
  if (const auto* m = root->FirstChildElement("Master")) {
    ECSIM_TRY(xml::checkNames(r.context(), m, kMasterNames));
    s.masterKind = Reader::attr(m, "kind").value_or("in-process");
    if (s.masterKind != "in-process" && s.masterKind != "veth" && s.masterKind != "external") {
      return r.error(m, "Master kind must be in-process, veth or external");
    }
    s.masterCommand = Reader::attr(m, "command").value_or("");
    s.masterLine = m->GetLineNum();
    if (s.masterKind == "external" && s.masterCommand.empty()) {
      return r.error(m, "an external Master needs command=\"...\"");
    }
    ECSIM_ASSIGN_OR_RETURN(auto startTimeout, r.millis(m, "startTimeoutMs"));
    ECSIM_ASSIGN_OR_RETURN(auto stopGrace, r.millis(m, "stopGraceMs"));
    const auto timeZero = Reader::attr(m, "timeZero");
    if (s.masterKind != "external" && (startTimeout || stopGrace || timeZero)) {
      return r.error(m, "startTimeoutMs, stopGraceMs and timeZero are for external masters only");
    }
    if (startTimeout) s.startTimeout = *startTimeout;
    if (stopGrace) s.stopGrace = *stopGrace;
    if (timeZero && *timeZero != "op" && *timeZero != "start") {
      return r.error(m, "timeZero=\"" + *timeZero + "\" is not op or start");
    }
    s.timeFromStart = timeZero.value_or("op") == "start";
  }
  if (const auto* t = root->FirstChildElement("Timeline")) {
    ECSIM_TRY(xml::checkNames(r.context(), t, kTimelineNames));
    for (const auto* e = t->FirstChildElement(); e != nullptr; e = e->NextSiblingElement()) {
      if (std::string_view(e->Name()) != "Action") {
        return r.error(e, "the Timeline holds <Action> elements only");
      }
      ECSIM_ASSIGN_OR_RETURN(
          auto a, readAction(r, e, s.masterKind == "external" ? SimTime{0} : s.cycleTime));
      ECSIM_TRY(checkWithinRun(r, e, s, a));
      s.actions.push_back(std::move(a));
    }
  }
  if (const auto* x = root->FirstChildElement("Expect")) {
    ECSIM_TRY(xml::checkNames(r.context(), x, kExpectNames));
    for (const auto* e = x->FirstChildElement(); e != nullptr; e = e->NextSiblingElement()) {
      ECSIM_ASSIGN_OR_RETURN(
          auto exp, readExpectation(r, e, s.masterKind == "external" ? SimTime{0} : s.cycleTime));
      ECSIM_TRY(checkWithinRun(r, e, s, exp));
      s.expectations.push_back(std::move(exp));
    }
  }
  if (s.expectations.empty()) return r.error(root, "a scenario needs at least one expectation");
  ECSIM_TRY(checkMasterKind(s));
  return s;
}

}  // namespace ecsim::scenario
