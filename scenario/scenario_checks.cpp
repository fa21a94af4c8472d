// What a scenario is checked against besides its own file (scenario/scenario.hpp): its
// topology's names, the master's process-variable names, what its kind of master can be judged
// on; and how expectations compare values.
#include <fmt/core.h>

#include <algorithm>
#include <cmath>

#include "config/topology_file.hpp"
#include "master/variables.hpp"
#include "protocol/closest_name.hpp"
#include "scenario/scenario.hpp"

namespace ecsim::scenario {

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

Status checkTopologyNames(const Scenario& s, const TopologyConfig& topology) {
  std::vector<std::string_view> slaves;
  for (const auto& slave : topology.slaves) slaves.push_back(slave.name);
  std::vector<std::string_view> cables{"master"};
  for (const auto& link : topology.links) cables.push_back(link.name);
  if (topology.redundantPort) cables.push_back("redundant");
  std::vector<std::string_view> groups;
  for (const auto& g : topology.groups) groups.push_back(g.name);
  auto check = [&](int line, std::string_view what, std::string_view name,
                   const std::vector<std::string_view>& names) -> Status {
    if (std::find(names.begin(), names.end(), name) != names.end()) return okStatus();
    return makeError(ErrorCode::kParse,
                     fmt::format("{}, line {}: no {} '{}' in the topology{}", s.file.string(), line,
                                 what, name, didYouMean(name, names)));
  };
  for (const auto& a : s.actions) {
    if (auto slave = a.action.get("slave")) ECSIM_TRY(check(a.line, "slave", *slave, slaves));
    if (auto cable = a.action.get("cable")) ECSIM_TRY(check(a.line, "cable", *cable, cables));
    if (auto group = a.action.get("group")) ECSIM_TRY(check(a.line, "group", *group, groups));
  }
  for (const auto& x : s.expectations) {
    if (!x.slave.empty()) ECSIM_TRY(check(x.line, "slave", x.slave, slaves));
  }
  return okStatus();
}

Status checkVariableNames(const Scenario& s, const std::vector<master::VariableInfo>& variables) {
  for (const auto& x : s.expectations) {
    if (x.kind != ExpectKind::kVariable || x.variable.empty()) continue;
    if (auto v = master::findVariable(variables, x.variable); !v.ok()) {
      return makeError(ErrorCode::kNotFound,
                       fmt::format("{}, line {}: {}", s.file.string(), x.line, v.error().context));
    }
  }
  return okStatus();
}

Status checkMasterKind(const Scenario& s) {
  const bool external = s.masterKind == "external";
  auto refuse = [&](int line, const std::string& what) -> Status {
    return makeError(ErrorCode::kParse,
                     s.file.string() + ", line " + std::to_string(line) + ": " + what);
  };
  for (const auto& a : s.actions) {
    if (external && std::holds_alternative<topology::PauseMaster>(a.fault)) {
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
  }
  return okStatus();
}

}  // namespace ecsim::scenario
