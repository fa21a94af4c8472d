// Reads scenario files (docs/scenarios.md) with tinyxml2; errors name file and line.
#include <tinyxml2.h>

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>

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

class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  Error error(const XMLElement* e, const std::string& what) const {
    return makeError(
        ErrorCode::kParse,
        file_ + ", line " + std::to_string(e == nullptr ? 0 : e->GetLineNum()) + ": " + what);
  }
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

Result<TimedAction> readAction(const Reader& r, const XMLElement* e) {
  TimedAction a;
  a.line = e->GetLineNum();
  ECSIM_ASSIGN_OR_RETURN(a.cycle, r.number(e, "cycle", 0, kMaxCycles));
  ECSIM_ASSIGN_OR_RETURN(a.time, r.millis(e, "timeMs"));
  if (a.cycle.has_value() == a.time.has_value()) {
    return r.error(e, "an Action needs exactly one of cycle=\"N\" and timeMs=\"T\"");
  }
  auto verb = Reader::attr(e, "do");
  if (!verb) return r.error(e, "an Action needs do=\"VERB\"");
  a.action.verb = *verb;
  a.action.where = r.where(e);
  for (const auto* at = e->FirstAttribute(); at != nullptr; at = at->Next()) {
    const std::string key = at->Name();
    if (key == "cycle" || key == "timeMs" || key == "do") continue;
    a.action.args[key] = at->Value();
  }
  const bool runnerVerb = a.action.verb == "pause-master";
  if (!runnerVerb && !topology::FaultInjector::handles(a.action.verb)) {
    return r.error(e, "unknown action \"" + a.action.verb + "\"");
  }
  if (!runnerVerb) ECSIM_TRY(topology::checkFaultArguments(a.action));
  return a;
}

Result<Expectation> readExpectation(const Reader& r, const XMLElement* e) {
  Expectation x;
  x.line = e->GetLineNum();
  const std::string tag = e->Name();
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
    ECSIM_ASSIGN_OR_RETURN(auto after, r.number(e, "afterCycle", 0, kMaxCycles));
    ECSIM_ASSIGN_OR_RETURN(auto within, r.number(e, "withinCycles", 0, kMaxCycles));
    if (!within) return r.error(e, "Detected needs withinCycles=\"N\"");
    x.afterCycle = after.value_or(0);
    x.withinCycles = *within;
  } else if (tag == "BackInOp") {
    x.kind = ExpectKind::kBackInOp;
    ECSIM_ASSIGN_OR_RETURN(auto after, r.number(e, "afterCycle", 0, kMaxCycles));
    ECSIM_ASSIGN_OR_RETURN(auto within, r.millis(e, "withinMs"));
    ECSIM_ASSIGN_OR_RETURN(x.afterTime, r.millis(e, "afterMs"));
    if (!within) return r.error(e, "BackInOp needs withinMs=\"T\"");
    if (after && x.afterTime) return r.error(e, "BackInOp takes afterCycle or afterMs, not both");
    x.afterCycle = after.value_or(0);
    x.within = *within;
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
          const std::string shown =
              x.text.size() > 60 ? x.text.substr(0, 60) + "..." : x.text;
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
    ECSIM_TRY(needSlave());
    ECSIM_TRY(needValue());
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

}  // namespace

std::string_view toString(Compare c) {
  switch (c) {
    case Compare::kEq:
      return "==";
    case Compare::kNe:
      return "!=";
    case Compare::kLt:
      return "<";
    case Compare::kLe:
      return "<=";
    case Compare::kGt:
      return ">";
    case Compare::kGe:
      return ">=";
  }
  return "?";
}

bool compareValues(double observed, Compare c, double expected, double tolerance) {
  switch (c) {
    case Compare::kEq:
      return std::fabs(observed - expected) <= tolerance;
    case Compare::kNe:
      return std::fabs(observed - expected) > tolerance;
    case Compare::kLt:
      return observed < expected;
    case Compare::kLe:
      return observed <= expected;
    case Compare::kGt:
      return observed > expected;
    case Compare::kGe:
      return observed >= expected;
  }
  return false;
}

Result<Scenario> loadScenario(const std::filesystem::path& path) {
  ECSIM_ASSIGN_OR_RETURN(const std::string text, readRegularFile(path, kMaxXmlFileBytes));
  return parseScenario(text, path);
}

Result<Scenario> parseScenario(std::string_view xml, const std::filesystem::path& path) {
  Reader r(path.string());
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.data(), xml.size()) != tinyxml2::XML_SUCCESS) {
    return makeError(
        ErrorCode::kParse,
        path.string() + ", line " + std::to_string(doc.ErrorLineNum()) + ": " + doc.ErrorStr());
  }
  const XMLElement* root = doc.RootElement();
  if (root == nullptr || std::string_view(root->Name()) != "Scenario") {
    return r.error(root, "the root element must be <Scenario>");
  }
  Scenario s;
  s.file = path;
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
  if (const auto* d = root->FirstChildElement("Description"); d && d->GetText()) {
    s.description = d->GetText();
  }
  if (const auto* m = root->FirstChildElement("Master")) {
    s.masterKind = Reader::attr(m, "kind").value_or("in-process");
    if (s.masterKind != "in-process" && s.masterKind != "external") {
      return r.error(m, "Master kind must be in-process or external");
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
    for (const auto* e = t->FirstChildElement(); e != nullptr; e = e->NextSiblingElement()) {
      if (std::string_view(e->Name()) != "Action") {
        return r.error(e, "the Timeline holds <Action> elements only");
      }
      ECSIM_ASSIGN_OR_RETURN(auto a, readAction(r, e));
      s.actions.push_back(std::move(a));
    }
  }
  if (const auto* x = root->FirstChildElement("Expect")) {
    for (const auto* e = x->FirstChildElement(); e != nullptr; e = e->NextSiblingElement()) {
      ECSIM_ASSIGN_OR_RETURN(auto exp, readExpectation(r, e));
      s.expectations.push_back(std::move(exp));
    }
  }
  if (s.expectations.empty()) return r.error(root, "a scenario needs at least one expectation");
  ECSIM_TRY(checkMasterKind(s));
  return s;
}

Status checkMasterKind(const Scenario& s) {
  const bool external = s.masterKind == "external";
  auto refuse = [&](int line, const std::string& what) -> Status {
    return makeError(ErrorCode::kParse,
                     s.file.string() + ", line " + std::to_string(line) + ": " + what);
  };
  for (const auto& a : s.actions) {
    if (external && a.action.verb == "pause-master") {
      return refuse(a.line,
                    "pause-master needs our master: an external master sends what it sends");
    }
  }
  for (const auto& x : s.expectations) {
    const char* inner = x.kind == ExpectKind::kDetected     ? "Detected"
                        : x.kind == ExpectKind::kStatistic  ? "Statistic"
                        : x.kind == ExpectKind::kVariable   ? "Variable"
                        : x.kind == ExpectKind::kContinuity ? "Continuity"
                                                            : nullptr;
    if (external && inner != nullptr) {
      return refuse(x.line, std::string(inner) +
                                " looks inside the master, which an external master does not "
                                "show: judge it by State, Register, BackInOp, ExitStatus or "
                                "Output");
    }
    const bool commandOnly = x.kind == ExpectKind::kExitStatus || x.kind == ExpectKind::kOutput;
    if (!external && commandOnly) {
      return refuse(x.line, std::string(x.kind == ExpectKind::kOutput ? "Output" : "ExitStatus") +
                                " judges an external master's command (Master kind=\"external\")");
    }
    if (!external && x.afterTime) {
      return refuse(x.line, "BackInOp afterMs is for external masters; ours counts afterCycle");
    }
  }
  return okStatus();
}

}  // namespace ecsim::scenario
