// Fault actions as text (a scenario's <Action>, a control line) and their typed, checked form
// (topology/faults.hpp): the verb table, parseFaultAction, parseFault, describe.
#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>

#include "protocol/closest_name.hpp"
#include "topology/faults.hpp"

namespace ecsim::topology {
namespace {

// ---- The verbs and the arguments each takes (checkFaultArguments, ecsim ctl help) ----------
// Keys in alphabetical order; a verb has at most kMaxVerbKeys. pause-master, and the
// durationCycles of a scenario, are not taken on a control line (FaultScope).
constexpr std::size_t kMaxVerbKeys = 6;
struct VerbArguments {
  std::string_view verb;
  std::array<std::string_view, kMaxVerbKeys> keys;
  bool scenarioOnly{false};
};
constexpr std::array<VerbArguments, 21> kVerbArguments{{
    {"loss", {"cable", "rate"}},
    {"corrupt", {"cable", "count", "port", "slave"}},
    {"delay", {"cable", "durationCycles", "durationMs", "ns", "port", "slave"}},
    {"link-down", {"cable", "port", "slave"}},
    {"link-up", {"cable", "port", "slave"}},
    {"power-off", {"slave"}},
    {"power-on", {"slave"}},
    {"power-cycle", {"slave"}},
    {"attach", {"group"}},
    {"detach", {"group"}},
    {"al-error", {"code", "slave", "state"}},
    {"eeprom-checksum", {"slave"}},
    {"mailbox-silent", {"on", "slave"}},
    {"mailbox-ok", {"on", "slave"}},
    {"sdo-abort", {"code", "index", "slave", "sub"}},
    {"sdo-ok", {"slave"}},
    {"drive-fault", {"code", "slave"}},
    {"encoder-fault", {"channel", "kind", "on", "slave"}},
    {"input", {"channel", "signal", "slave"}},
    {"latch", {"level", "slave", "unit"}},
    {"pause-master", {"durationCycles", "durationMs"}, true},
}};
// Counted in the runner's cycles: scenarios only.
constexpr std::string_view kCyclesKey = "durationCycles";

const VerbArguments* verbArguments(std::string_view verb, FaultScope scope) {
  for (const auto& v : kVerbArguments) {
    if (v.verb == verb && (scope == FaultScope::kScenario || !v.scenarioOnly)) return &v;
  }
  return nullptr;
}
// ---- end of the verb table ------------------------------------------------------------------

constexpr std::array<std::pair<std::string_view, AlState>, 5> kStates{{
    {"INIT", AlState::kInit},
    {"PREOP", AlState::kPreOp},
    {"BOOT", AlState::kBootstrap},
    {"SAFEOP", AlState::kSafeOp},
    {"OP", AlState::kOp},
}};
constexpr std::array<std::pair<std::string_view, EncoderFault::Kind>, 3> kEncoderKinds{{
    {"data", EncoderFault::Kind::kData},
    {"frame", EncoderFault::Kind::kFrame},
    {"power", EncoderFault::Kind::kPower},
}};

// A named value of `table`; else "key=X is not A, B or C; did you mean 'B'?".
template <typename T, std::size_t N>
Result<T> named(const FaultAction& a, std::string_view key, std::string_view text,
                const std::array<std::pair<std::string_view, T>, N>& table) {
  std::vector<std::string_view> names;
  for (const auto& [name, value] : table) {
    if (name == text) return value;
    names.push_back(name);
  }
  std::string list;
  for (std::size_t i = 0; i < names.size(); ++i) {
    list += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + std::string(names[i]);
  }
  return a.error(fmt::format("{}={} is not {}{}", key, text, list, didYouMean(text, names)));
}
template <typename T, std::size_t N>
std::string_view nameOf(T value, const std::array<std::pair<std::string_view, T>, N>& table) {
  for (const auto& [name, v] : table) {
    if (v == value) return name;
  }
  return "?";
}

// A value as a control line writes it: in double quotes when it has a space or is empty.
std::string argText(std::string_view v) {
  const bool quote = v.find(' ') != std::string_view::npos || v.empty();
  return quote ? "\"" + std::string(v) + "\"" : std::string(v);
}

Result<std::string> slaveArgument(const FaultAction& a) {
  ECSIM_ASSIGN_OR_RETURN(auto name, a.require("slave"));
  if (name.empty()) return a.error("slave= is empty");
  return std::string(name);
}

// cable=NAME, or slave=NAME port=N.
Result<FaultPlace> placeArgument(const FaultAction& a) {
  FaultPlace at;
  const auto cable = a.get("cable");
  const auto slave = a.get("slave");
  if (cable && (slave || a.get("port"))) {
    return a.error("takes cable=NAME or slave=NAME port=N, not both");
  }
  if (cable) {
    if (cable->empty()) return a.error("cable= is empty");
    at.cable = std::string(*cable);
    return at;
  }
  if (!slave) return a.error("needs cable=NAME or slave=NAME port=N");
  ECSIM_ASSIGN_OR_RETURN(at.slave, slaveArgument(a));
  ECSIM_ASSIGN_OR_RETURN(auto port, a.number("port", 0, kPortCount - 1));
  at.port = static_cast<unsigned>(port);
  return at;
}

// durationMs=T or durationCycles=N (counted in the context's cycle time), exactly one.
Result<SimTime> durationArgument(const FaultAction& a, const FaultContext& context) {
  const bool ms = a.get("durationMs").has_value();
  const bool cycles = a.get(kCyclesKey).has_value();
  if (ms && cycles) return a.error("takes durationMs=T or durationCycles=N, not both");
  if (!ms && !cycles) return a.error("needs durationMs=T or durationCycles=N");
  if (ms) return a.millis("durationMs");
  if (context.cycleTime == 0) {
    return a.error(
        "durationCycles needs our master's cycle time (an external master keeps its own): give "
        "durationMs");
  }
  const auto most = std::max<std::uint64_t>(
      1, kMaxFaultDurationMs * kNsPerMs / static_cast<std::uint64_t>(context.cycleTime));
  ECSIM_ASSIGN_OR_RETURN(auto n, a.number(kCyclesKey, 0, most));
  return saturatingMul(static_cast<SimTime>(n), context.cycleTime);
}

std::string place(const FaultPlace& at) {
  return at.cable.empty() ? fmt::format("slave={} port={}", argText(at.slave), at.port)
                          : "cable=" + argText(at.cable);
}

}  // namespace

std::optional<std::uint64_t> parseNumber(std::string_view text) {
  int base = 10;
  if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
    text.remove_prefix(2);
    base = 16;
  }
  std::uint64_t v = 0;
  auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v, base);
  if (ec != std::errc() || end != text.data() + text.size() || text.empty()) return std::nullopt;
  return v;
}

std::optional<std::string_view> FaultAction::get(std::string_view key) const {
  auto it = args.find(key);
  if (it == args.end()) return std::nullopt;
  return std::string_view(it->second);
}

Error FaultAction::error(std::string_view message) const {
  return makeError(ErrorCode::kInvalidArgument, (where.empty() ? std::string() : where + ": ") +
                                                    verb + ": " + std::string(message));
}

Result<std::string_view> FaultAction::require(std::string_view key) const {
  if (auto v = get(key)) return *v;
  return error("missing argument '" + std::string(key) + "'");
}

Result<std::uint64_t> FaultAction::number(std::string_view key, std::uint64_t lo,
                                          std::uint64_t hi) const {
  ECSIM_ASSIGN_OR_RETURN(auto text, require(key));
  auto v = parseNumber(text);
  if (v && *v >= lo && *v <= hi) return *v;
  const bool hex = text.size() > 1 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X');
  const auto bound = [hex](std::uint64_t b) {
    return hex && b != 0 ? fmt::format("{:#x}", b) : fmt::format("{}", b);
  };
  return error(fmt::format("{}={} is not a number in [{}, {}]", key, text, bound(lo), bound(hi)));
}

Result<std::uint64_t> FaultAction::number(std::string_view key, std::uint64_t lo, std::uint64_t hi,
                                          std::uint64_t fallback) const {
  if (!get(key)) return fallback;
  return number(key, lo, hi);
}

Result<double> FaultAction::real(std::string_view key, double lo, double hi) const {
  ECSIM_ASSIGN_OR_RETURN(auto text, require(key));
  double v = 0;
  auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  // NaN fails both comparisons: written so that it is refused.
  if (ec == std::errc() && end == text.data() + text.size() && v >= lo && v <= hi) return v;
  return error(fmt::format("{}={} is not a number in [{}, {}]", key, text, lo, hi));
}

Result<SimTime> FaultAction::millis(std::string_view key) const {
  ECSIM_ASSIGN_OR_RETURN(auto ms, real(key, 0, static_cast<double>(kMaxFaultDurationMs)));
  return saturatingTime(ms * static_cast<double>(kNsPerMs));
}

std::string FaultAction::text() const {
  std::string out = verb;
  for (const auto& [k, v] : args) out += " " + k + "=" + argText(v);
  return out;
}

std::vector<std::string_view> faultVerbs(FaultScope scope) {
  std::vector<std::string_view> verbs;
  for (const auto& v : kVerbArguments) {
    if (scope == FaultScope::kScenario || !v.scenarioOnly) verbs.push_back(v.verb);
  }
  return verbs;
}

std::vector<std::string_view> faultArguments(std::string_view verb, FaultScope scope) {
  std::vector<std::string_view> keys;
  if (const VerbArguments* v = verbArguments(verb, scope)) {
    for (std::string_view k : v->keys) {
      if (!k.empty() && (scope == FaultScope::kScenario || k != kCyclesKey)) keys.push_back(k);
    }
  }
  return keys;
}

Status checkFaultArguments(const FaultAction& action, FaultScope scope) {
  if (verbArguments(action.verb, scope) == nullptr) {
    return makeError(ErrorCode::kInvalidArgument,
                     (action.where.empty() ? std::string() : action.where + ": ") +
                         unknownNameText("action", action.verb, faultVerbs(scope)));
  }
  const std::vector<std::string_view> keys = faultArguments(action.verb, scope);
  for (const auto& [key, value] : action.args) {
    if (std::find(keys.begin(), keys.end(), key) == keys.end()) {
      return action.error(unknownNameText("argument", key, keys));
    }
  }
  return okStatus();
}

Result<FaultAction> parseFaultAction(std::string_view line) {
  auto fail = [](std::size_t at, const std::string& what) {
    return makeError(ErrorCode::kParse, fmt::format("control: column {}: {}", at + 1, what));
  };
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);  // CR LF (nc -C, telnet)
  for (std::size_t k = 0; k < line.size(); ++k) {
    const auto c = static_cast<unsigned char>(line[k]);
    if ((c < 0x20 && c != '\t') || c == 0x7F) {
      return fail(k, fmt::format("byte {:#04x} is not printable", c));
    }
  }
  const auto isSpace = [](char c) { return c == ' ' || c == '\t'; };
  FaultAction action;
  action.where = "control";
  std::size_t i = 0;
  auto skipSpace = [&] {
    while (i < line.size() && isSpace(line[i])) ++i;
  };
  skipSpace();
  std::size_t start = i;
  while (i < line.size() && !isSpace(line[i])) ++i;
  action.verb = std::string(line.substr(start, i - start));
  if (action.verb.empty()) return makeError(ErrorCode::kParse, "control: empty action");
  while (true) {
    skipSpace();
    if (i >= line.size()) break;
    start = i;
    while (i < line.size() && line[i] != '=' && !isSpace(line[i])) ++i;
    if (i >= line.size() || line[i] != '=') return fail(start, "expected key=value");
    if (i == start) return fail(start, "empty argument name");
    std::string key(line.substr(start, i - start));
    ++i;
    std::string value;
    if (i < line.size() && line[i] == '"') {
      const std::size_t close = line.find('"', i + 1);
      if (close == std::string_view::npos) return fail(i, "unterminated quote");
      value = std::string(line.substr(i + 1, close - i - 1));
      i = close + 1;
    } else {
      const std::size_t from = i;
      while (i < line.size() && !isSpace(line[i])) ++i;
      value = std::string(line.substr(from, i - from));
    }
    if (!action.args.emplace(key, std::move(value)).second) {
      return fail(start, "argument '" + key + "' given twice");
    }
  }
  ECSIM_TRY(checkFaultArguments(action));
  return action;
}

// ---- Typed faults ---------------------------------------------------------------------------

Result<Fault> parseFault(const FaultAction& a, const FaultContext& context) {
  ECSIM_TRY(checkFaultArguments(a, context.scope));
  const std::string& v = a.verb;
  if (v == "loss") {
    Loss f;
    ECSIM_ASSIGN_OR_RETURN(f.rate, a.real("rate", 0, 1));
    if (auto cable = a.get("cable")) {
      if (cable->empty()) return a.error("cable= is empty");
      f.cable = std::string(*cable);
    }
    return Fault{f};
  }
  if (v == "corrupt") {
    Corrupt f;
    ECSIM_ASSIGN_OR_RETURN(f.at, placeArgument(a));
    ECSIM_ASSIGN_OR_RETURN(f.count, a.number("count", 0, kMaxCorruptCount, 1));
    return Fault{f};
  }
  if (v == "delay") {
    Delay f;
    ECSIM_ASSIGN_OR_RETURN(f.at, placeArgument(a));
    ECSIM_ASSIGN_OR_RETURN(auto ns, a.number("ns", 0, kMaxDelaySpikeNs));
    f.extra = static_cast<SimTime>(ns);
    ECSIM_ASSIGN_OR_RETURN(f.duration, durationArgument(a, context));
    return Fault{f};
  }
  if (v == "link-down" || v == "link-up") {
    ECSIM_ASSIGN_OR_RETURN(auto at, placeArgument(a));
    if (v == "link-up") return Fault{LinkUp{at}};
    return Fault{LinkDown{at}};
  }
  if (v == "attach" || v == "detach") {
    ECSIM_ASSIGN_OR_RETURN(auto group, a.require("group"));
    return Fault{HotConnect{std::string(group), v == "attach"}};
  }
  if (v == "pause-master") {
    PauseMaster f;
    ECSIM_ASSIGN_OR_RETURN(f.duration, durationArgument(a, context));
    return Fault{f};
  }
  // The remaining verbs address one slave.
  ECSIM_ASSIGN_OR_RETURN(auto slave, slaveArgument(a));
  if (v == "power-off") return Fault{PowerOff{slave}};
  if (v == "power-on") return Fault{PowerOn{slave}};
  if (v == "power-cycle") return Fault{PowerCycle{slave}};
  if (v == "eeprom-checksum") return Fault{EepromChecksum{slave}};
  if (v == "sdo-ok") return Fault{SdoOk{slave}};
  if (v == "al-error") {
    AlError f;
    f.slave = slave;
    ECSIM_ASSIGN_OR_RETURN(auto code, a.number("code", 0, 0xFFFF));
    f.code = static_cast<std::uint16_t>(code);
    if (auto st = a.get("state")) {
      ECSIM_ASSIGN_OR_RETURN(f.state, named(a, "state", *st, kStates));
    }
    return Fault{f};
  }
  if (v == "mailbox-silent" || v == "mailbox-ok") {
    ECSIM_ASSIGN_OR_RETURN(auto on, a.number("on", 0, 1, v == "mailbox-silent" ? 1 : 0));
    return Fault{MailboxSilent{slave, on != 0}};
  }
  if (v == "sdo-abort") {
    SdoAbortFault f;
    f.slave = slave;
    ECSIM_ASSIGN_OR_RETURN(auto index, a.number("index", 0, 0xFFFF));
    ECSIM_ASSIGN_OR_RETURN(auto code, a.number("code", 0, 0xFFFFFFFF, f.code));
    f.index = static_cast<std::uint16_t>(index);
    f.code = static_cast<std::uint32_t>(code);
    if (a.get("sub")) {
      ECSIM_ASSIGN_OR_RETURN(auto sub, a.number("sub", 0, 0xFF));
      f.subindex = static_cast<std::uint8_t>(sub);
    }
    return Fault{f};
  }
  if (v == "drive-fault") {
    DriveFault f;
    f.slave = slave;
    ECSIM_ASSIGN_OR_RETURN(auto code, a.number("code", 0, 0xFFFF, f.code));
    f.code = static_cast<std::uint16_t>(code);
    return Fault{f};
  }
  if (v == "encoder-fault") {
    EncoderFault f;
    f.slave = slave;
    if (auto kind = a.get("kind")) {
      ECSIM_ASSIGN_OR_RETURN(f.kind, named(a, "kind", *kind, kEncoderKinds));
    }
    ECSIM_ASSIGN_OR_RETURN(auto on, a.number("on", 0, 1, 1));
    ECSIM_ASSIGN_OR_RETURN(auto channel, a.number("channel", 1, kMaxFaultChannel, 1));
    f.on = on != 0;
    f.channel = static_cast<unsigned>(channel);
    return Fault{f};
  }
  if (v == "input") {
    Input f;
    f.slave = slave;
    ECSIM_ASSIGN_OR_RETURN(auto channel, a.number("channel", 1, kMaxFaultChannel));
    ECSIM_ASSIGN_OR_RETURN(auto text, a.require("signal"));
    auto signal = slavesim::devices::parseSignal(text, context.baseDir);
    if (!signal.ok()) return a.error(signal.error().context);
    f.channel = static_cast<unsigned>(channel);
    f.text = std::string(text);
    f.signal = std::move(*signal);
    return Fault{std::move(f)};
  }
  if (v == "latch") {
    Latch f;
    f.slave = slave;
    ECSIM_ASSIGN_OR_RETURN(auto unit, a.number("unit", 0, 1));
    ECSIM_ASSIGN_OR_RETURN(auto level, a.number("level", 0, 1));
    f.unit = static_cast<unsigned>(unit);
    f.level = level != 0;
    return Fault{f};
  }
  return a.error("unknown action");  // a verb of the table without a case here
}

Result<Fault> parseFaultLine(std::string_view line) {
  ECSIM_ASSIGN_OR_RETURN(auto action, parseFaultAction(line));
  return parseFault(action);
}

namespace {
struct VerbOf {
  std::string_view operator()(const LinkDown&) const { return "link-down"; }
  std::string_view operator()(const LinkUp&) const { return "link-up"; }
  std::string_view operator()(const Loss&) const { return "loss"; }
  std::string_view operator()(const Corrupt&) const { return "corrupt"; }
  std::string_view operator()(const Delay&) const { return "delay"; }
  std::string_view operator()(const PowerOff&) const { return "power-off"; }
  std::string_view operator()(const PowerOn&) const { return "power-on"; }
  std::string_view operator()(const PowerCycle&) const { return "power-cycle"; }
  std::string_view operator()(const HotConnect& f) const { return f.attach ? "attach" : "detach"; }
  std::string_view operator()(const AlError&) const { return "al-error"; }
  std::string_view operator()(const EepromChecksum&) const { return "eeprom-checksum"; }
  std::string_view operator()(const MailboxSilent& f) const {
    return f.silent ? "mailbox-silent" : "mailbox-ok";
  }
  std::string_view operator()(const SdoAbortFault&) const { return "sdo-abort"; }
  std::string_view operator()(const SdoOk&) const { return "sdo-ok"; }
  std::string_view operator()(const DriveFault&) const { return "drive-fault"; }
  std::string_view operator()(const EncoderFault&) const { return "encoder-fault"; }
  std::string_view operator()(const Input&) const { return "input"; }
  std::string_view operator()(const Latch&) const { return "latch"; }
  std::string_view operator()(const PauseMaster&) const { return "pause-master"; }
};

std::string ms(SimTime t) {
  return fmt::format("{}", static_cast<double>(t) / static_cast<double>(kNsPerMs));
}

// The arguments, in the order a reader expects them.
struct Arguments {
  std::string operator()(const LinkDown& f) const { return place(f.at); }
  std::string operator()(const LinkUp& f) const { return place(f.at); }
  std::string operator()(const Loss& f) const {
    return fmt::format("rate={}", f.rate) + (f.cable.empty() ? "" : " cable=" + argText(f.cable));
  }
  std::string operator()(const Corrupt& f) const {
    return fmt::format("{} count={}", place(f.at), f.count);
  }
  std::string operator()(const Delay& f) const {
    return fmt::format("{} ns={} durationMs={}", place(f.at), f.extra, ms(f.duration));
  }
  std::string operator()(const PowerOff& f) const { return "slave=" + argText(f.slave); }
  std::string operator()(const PowerOn& f) const { return "slave=" + argText(f.slave); }
  std::string operator()(const PowerCycle& f) const { return "slave=" + argText(f.slave); }
  std::string operator()(const HotConnect& f) const { return "group=" + argText(f.group); }
  std::string operator()(const AlError& f) const {
    return fmt::format("slave={} code={:#06x}", argText(f.slave), f.code) +
           (f.state ? " state=" + std::string(nameOf(*f.state, kStates)) : "");
  }
  std::string operator()(const EepromChecksum& f) const { return "slave=" + argText(f.slave); }
  std::string operator()(const MailboxSilent& f) const { return "slave=" + argText(f.slave); }
  std::string operator()(const SdoAbortFault& f) const {
    return fmt::format("slave={} index={:#06x}", argText(f.slave), f.index) +
           (f.subindex ? fmt::format(" sub={}", *f.subindex) : "") +
           fmt::format(" code={:#010x}", f.code);
  }
  std::string operator()(const SdoOk& f) const { return "slave=" + argText(f.slave); }
  std::string operator()(const DriveFault& f) const {
    return fmt::format("slave={} code={:#06x}", argText(f.slave), f.code);
  }
  std::string operator()(const EncoderFault& f) const {
    return fmt::format("slave={} kind={} on={} channel={}", argText(f.slave),
                       nameOf(f.kind, kEncoderKinds), f.on ? 1 : 0, f.channel);
  }
  std::string operator()(const Input& f) const {
    return fmt::format("slave={} channel={} signal={}", argText(f.slave), f.channel,
                       argText(f.text));
  }
  std::string operator()(const Latch& f) const {
    return fmt::format("slave={} unit={} level={}", argText(f.slave), f.unit, f.level ? 1 : 0);
  }
  std::string operator()(const PauseMaster& f) const { return "durationMs=" + ms(f.duration); }
};
}  // namespace

std::string_view verbOf(const Fault& fault) {
  return std::visit(VerbOf{}, fault);
}

std::string describe(const Fault& fault) {
  return std::string(verbOf(fault)) + " " + std::visit(Arguments{}, fault);
}

std::string_view toString(EncoderFault::Kind kind) {
  return nameOf(kind, kEncoderKinds);
}

}  // namespace ecsim::topology
