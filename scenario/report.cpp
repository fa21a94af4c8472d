// Text report and JUnit XML of scenario runs. Nothing here reads a clock: the same run gives
// the same bytes.
#include <fmt/core.h>

#include <map>

#include "config/xml_util.hpp"
#include "scenario/engine.hpp"

namespace ecsim::scenario {
namespace {

std::string when(const Expectation& x) {
  if (x.atCycle) return fmt::format(" at cycle {}", *x.atCycle);
  if (x.atTime) {
    return fmt::format(" at {:.3f} ms", static_cast<double>(*x.atTime) / kNsPerMs);
  }
  return " at the end";
}

std::string valueText(double v) {
  if (v == static_cast<double>(static_cast<std::int64_t>(v))) {
    return std::to_string(static_cast<std::int64_t>(v));
  }
  return fmt::format("{:.6g}", v);
}

std::string xmlEscape(std::string_view text) {
  return xml::escapeText(text);
}

}  // namespace

std::string Expectation::describe() const {
  const std::string cmp = fmt::format("{} {}", toString(compare), valueText(value));
  switch (kind) {
    case ExpectKind::kState: {
      std::string s = fmt::format("State {} is {}", slave, state);
      if (error) s += *error ? "+ERR" : " without error";
      if (code) s += fmt::format(" code {:#06x}", *code);
      return s + when(*this);
    }
    case ExpectKind::kDetected:
      return fmt::format("Detected {}{} within {} cycles after cycle {}", condition,
                         slave.empty() ? "" : " of " + slave, withinCycles, afterCycle);
    case ExpectKind::kBackInOp:
      if (afterTime) {
        return fmt::format("BackInOp within {:.3f} ms after {:.3f} ms",
                           static_cast<double>(within) / kNsPerMs,
                           static_cast<double>(*afterTime) / kNsPerMs);
      }
      return fmt::format("BackInOp within {:.3f} ms after cycle {}",
                         static_cast<double>(within) / kNsPerMs, afterCycle);
    case ExpectKind::kRegister:
      return fmt::format(
          "Register {} {:#06x} ({} byte{}{}) {}{}", slave, address, width, width == 1 ? "" : "s",
          mask == 0xFFFFFFFF ? std::string() : fmt::format(", mask {:#x}", mask), cmp, when(*this));
    case ExpectKind::kStatistic:
      return fmt::format("Statistic {} {}{}", name, cmp, when(*this));
    case ExpectKind::kContinuity: {
      std::string s = "Continuity:";
      if (maxBadCycles != UINT64_MAX) s += fmt::format(" at most {} bad cycles", maxBadCycles);
      if (maxConsecutiveBadCycles != UINT64_MAX) {
        s += fmt::format(" at most {} in a row", maxConsecutiveBadCycles);
      }
      return s;
    }
    case ExpectKind::kVariable:
      if (!variable.empty()) return fmt::format("Variable {} {}{}", variable, cmp, when(*this));
      return fmt::format("Variable {} {:#06x}:{:02x} {}{}", slave, index, subindex, cmp,
                         when(*this));
    case ExpectKind::kExitStatus:
      return fmt::format("ExitStatus {}", cmp);
    case ExpectKind::kOutput:
      return fmt::format("Output {} \"{}\"{}{}", isRegex ? "matches" : "contains", text,
                         countLines ? fmt::format(" in {} lines", cmp) : std::string(),
                         afterTime ? fmt::format(" within {:.3f} ms after {:.3f} ms",
                                                 static_cast<double>(within) / kNsPerMs,
                                                 static_cast<double>(*afterTime) / kNsPerMs)
                                   : std::string());
  }
  return "?";
}

std::string formatReport(const ScenarioResult& r) {
  // The in-process master is the default and not named (its reports stay as they were).
  const std::string master =
      r.master.empty() || r.master == "in-process" ? "" : ", master " + r.master;
  std::string out = fmt::format("scenario {} ({}){}, seed {}: {} cycles of {} us\n", r.name,
                                r.file, master, r.seed, r.cycles, r.cycleTime / kNsPerUs);
  for (const auto& line : r.log) out += line + "\n";
  if (!r.error.empty()) {
    out += fmt::format("ERROR  {}\n", r.error);
    return out + fmt::format("result: {} did not run\n", r.name);
  }
  for (const auto& x : r.results) {
    out += fmt::format("{}  {}, line {}: {}\n", x.passed ? "PASS" : "FAIL", r.file, x.line, x.what);
    out += fmt::format("        at {:.3f} ms: {}{}\n", static_cast<double>(x.at) / kNsPerMs,
                       x.observed, x.needsRecovery ? " [needs recovery]" : "");
  }
  out += fmt::format("result: {} {} ({} of {} expectations failed)\n", r.name,
                     r.passed() ? "PASSED" : "FAILED", r.failures(), r.results.size());
  return out;
}

namespace {

std::string seconds(double s) {
  return fmt::format("{:.3f}", s);
}

// Testcase names of one suite: what each expectation expects, made unique in file order.
std::vector<std::string> testcaseNames(const ScenarioResult& r) {
  std::vector<std::string> names;
  std::map<std::string, int> seen;
  for (const auto& x : r.results) {
    const int n = ++seen[x.what];
    names.push_back(n == 1 ? x.what : fmt::format("{} #{}", x.what, n));
  }
  return names;
}

}  // namespace

std::string formatJunit(const std::vector<ScenarioResult>& results, const JunitContext& context) {
  std::size_t tests = 0, failures = 0, errors = 0;
  double total = 0.0;
  for (const auto& r : results) {
    tests += r.error.empty() ? r.results.size() : 1;
    failures += r.failures();
    errors += r.error.empty() ? 0 : 1;
    total += r.wallSeconds;
  }
  std::string out = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  out += fmt::format(
      "<testsuites name=\"ecsim scenarios\" tests=\"{}\" failures=\"{}\" errors=\"{}\" "
      "time=\"{}\">\n",
      tests, failures, errors, seconds(total));
  for (const auto& r : results) {
    const std::size_t cases = r.error.empty() ? r.results.size() : 1;
    out += fmt::format(
        "  <testsuite name=\"{}\" tests=\"{}\" failures=\"{}\" errors=\"{}\" skipped=\"0\" "
        "time=\"{}\"",
        xmlEscape(r.name), cases, r.failures(), r.error.empty() ? 0 : 1, seconds(r.wallSeconds));
    if (!context.timestamp.empty()) {
      out += fmt::format(" timestamp=\"{}\"", xmlEscape(context.timestamp));
    }
    if (!context.hostname.empty()) out += fmt::format(" hostname=\"{}\"", xmlEscape(context.hostname));
    out += fmt::format(" file=\"{}\">\n", xmlEscape(r.file));
    out += fmt::format(
        "    <properties>\n      <property name=\"seed\" value=\"{}\"/>\n"
        "      <property name=\"cycleTimeUs\" value=\"{}\"/>\n"
        "      <property name=\"cycles\" value=\"{}\"/>\n    </properties>\n",
        r.seed, r.cycleTime / kNsPerUs, r.cycles);
    const std::string caseTime = seconds(cases == 0 ? 0.0 : r.wallSeconds / static_cast<double>(cases));
    const std::string classname = "scenario." + xmlEscape(r.name);
    if (!r.error.empty()) {
      out += fmt::format(
          "    <testcase name=\"run\" classname=\"{}\" time=\"{}\">\n"
          "      <error message=\"{}\" type=\"ScenarioError\">{}</error>\n    </testcase>\n",
          classname, caseTime, xmlEscape(r.error), xmlEscape(r.error));
    }
    const std::vector<std::string> names = testcaseNames(r);
    for (std::size_t i = 0; i < r.results.size(); ++i) {
      const auto& x = r.results[i];
      out += fmt::format(
          "    <testcase name=\"{}\" classname=\"{}\" time=\"{}\" file=\"{}\" line=\"{}\"",
          xmlEscape(names[i]), classname, caseTime, xmlEscape(r.file), x.line);
      if (x.passed) {
        out += "/>\n";
        continue;
      }
      const std::string message =
          fmt::format("at {:.3f} ms: {}", static_cast<double>(x.at) / kNsPerMs, x.observed);
      out += fmt::format(
          ">\n      <failure message=\"{}\" type=\"ExpectationFailed\">{}, line {}: {}\n"
          "expected: {}\nobserved {}{}</failure>\n    </testcase>\n",
          xmlEscape(message), xmlEscape(r.file), x.line, xmlEscape(x.what), xmlEscape(x.what),
          xmlEscape(message), x.needsRecovery ? " [needs recovery]" : "");
    }
    std::string log;
    for (const auto& line : r.log) log += line + "\n";
    out += fmt::format("    <system-out>{}</system-out>\n", xmlEscape(log));
    out += "  </testsuite>\n";
  }
  return out + "</testsuites>\n";
}

}  // namespace ecsim::scenario
