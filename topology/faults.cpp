#include "topology/faults.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <charconv>

#include "protocol/al_status.hpp"
#include "protocol/closest_name.hpp"
#include "protocol/mailbox.hpp"
#include "protocol/sdo.hpp"
#include "slavesim/devices/device_models.hpp"
#include "slavesim/devices/signal.hpp"
#include "slavesim/process_data.hpp"

namespace ecsim::topology {
namespace {

constexpr std::size_t kSiiChecksumByte = 14;  // word 7, low byte: CRC-8 of words 0-6
constexpr std::uint16_t kOvercurrent = 0x2310;
constexpr std::uint16_t kPositionSensorFault = 0x7305;

// ---- The verbs and the arguments each takes (checkFaultArguments) --------------------------
// Keys in alphabetical order; a verb has at most kMaxVerbKeys.
constexpr std::size_t kMaxVerbKeys = 5;
struct VerbArguments {
  std::string_view verb;
  std::array<std::string_view, kMaxVerbKeys> keys;
};
constexpr std::array<VerbArguments, 18> kVerbArguments{{
    {"loss", {"cable", "rate"}},
    {"corrupt", {"cable", "count", "port", "slave"}},
    {"delay", {"cable", "durationMs", "ns", "port", "slave"}},
    {"link-down", {"cable", "port", "slave"}},
    {"link-up", {"cable", "port", "slave"}},
    {"power-off", {"slave"}},
    {"power-on", {"slave"}},
    {"power-cycle", {"slave"}},
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
}};

const VerbArguments* verbArguments(std::string_view verb) {
  for (const auto& v : kVerbArguments) {
    if (v.verb == verb) return &v;
  }
  return nullptr;
}
// ---- end of the verb table ------------------------------------------------------------------

std::optional<AlState> stateFromName(std::string_view name) {
  if (name == "INIT") return AlState::kInit;
  if (name == "PREOP") return AlState::kPreOp;
  if (name == "BOOT") return AlState::kBootstrap;
  if (name == "SAFEOP") return AlState::kSafeOp;
  if (name == "OP") return AlState::kOp;
  return std::nullopt;
}

// Wraps a slave's mailbox server: silent (requests swallowed, nothing answered) or aborting
// SDO requests for chosen objects with a chosen code; everything else goes to the real server.
class FaultyMailbox final : public slavesim::MailboxServer {
 public:
  explicit FaultyMailbox(std::unique_ptr<slavesim::MailboxServer> inner)
      : inner_(std::move(inner)) {}

  void onRequest(slavesim::Esc& esc, ConstBytes mailbox, SimTime now) override {
    if (silent) return;
    if (auto abort = matchAbort(mailbox)) {
      std::array<std::uint8_t, 64> out{};
      MailboxHeader header;
      if (auto h = MailboxHeader::decode(mailbox); h.ok()) header.counter = h->counter;
      if (auto n = encodeSdoResponseMailbox(out, SdoResponse{*abort}, header); n.ok()) {
        (void)esc.pdiMailboxSend(ConstBytes(out.data(), *n));
      }
      return;
    }
    if (inner_) inner_->onRequest(esc, mailbox, now);
  }
  void poll(slavesim::Esc& esc, SimTime now) override {
    if (!silent && inner_) inner_->poll(esc, now);
  }

  struct Rule {
    std::uint16_t index{0};
    std::optional<std::uint8_t> subindex;
    std::uint32_t code{0};
  };
  bool silent{false};
  std::vector<Rule> aborts;

 private:
  std::optional<SdoAbort> matchAbort(ConstBytes mailbox) const {
    if (aborts.empty()) return std::nullopt;
    auto request = decodeSdoRequestMailbox(mailbox);
    if (!request.ok()) return std::nullopt;
    std::uint16_t index = 0;
    std::uint8_t sub = 0;
    if (const auto* up = std::get_if<SdoInitiateUploadRequest>(&request->sdo)) {
      index = up->index;
      sub = up->subindex;
    } else if (const auto* down = std::get_if<SdoInitiateDownloadRequest>(&request->sdo)) {
      index = down->index;
      sub = down->subindex;
    } else {
      return std::nullopt;
    }
    for (const auto& r : aborts) {
      if (r.index == index && (!r.subindex || *r.subindex == sub)) {
        return SdoAbort{index, sub, r.code};
      }
    }
    return std::nullopt;
  }

  std::unique_ptr<slavesim::MailboxServer> inner_;
};

FaultyMailbox& faultyMailbox(slavesim::Slave& slave) {
  if (auto* f = dynamic_cast<FaultyMailbox*>(slave.mailboxServer())) return *f;
  auto wrapper = std::make_unique<FaultyMailbox>(slave.takeMailboxServer());
  FaultyMailbox& ref = *wrapper;
  slave.setMailboxServer(std::move(wrapper));
  return ref;
}

// An encoder terminal's fault (slavesim/devices/encoder_terminal.hpp): kind=data (default),
// frame or power, on=0 clears, channel=N (default 1).
Result<std::string> encoderFault(const FaultAction& a, slavesim::Slave& slave) {
  auto& encoder = *slavesim::devices::encoderTerminalOf(slave);
  ECSIM_ASSIGN_OR_RETURN(auto channel, a.number("channel", 1, encoder.channels(), 1));
  ECSIM_ASSIGN_OR_RETURN(auto on, a.number("on", 0, 1, 1));
  namespace ef = slavesim::devices::encoder_fault;
  const std::string_view kind = a.get("kind").value_or("data");
  std::uint8_t bit = ef::kData;
  if (kind == "frame") {
    bit = ef::kFrame;
  } else if (kind == "power") {
    bit = ef::kPower;
  } else if (kind != "data") {
    return a.error("kind must be data, frame or power" +
                   didYouMean(kind, {"data", "frame", "power"}));
  }
  const auto ch = static_cast<unsigned>(channel);
  const std::uint8_t faults = on != 0 ? static_cast<std::uint8_t>(encoder.fault(ch) | bit)
                                      : static_cast<std::uint8_t>(encoder.fault(ch) & ~bit);
  encoder.setFault(ch, faults);
  return fmt::format("{}: encoder channel {} {} {}", slave.name(), ch, kind,
                     on != 0 ? "fault" : "fault cleared");
}

}  // namespace

// ---- FaultAction ----------------------------------------------------------------------------

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
  for (const auto& [k, v] : args) {
    const bool quote = v.find(' ') != std::string::npos || v.empty();
    out += " " + k + "=" + (quote ? "\"" + v + "\"" : v);
  }
  return out;
}

std::vector<std::string_view> faultVerbs() {
  std::vector<std::string_view> verbs;
  for (const auto& v : kVerbArguments) verbs.push_back(v.verb);
  return verbs;
}

std::vector<std::string_view> faultArguments(std::string_view verb) {
  std::vector<std::string_view> keys;
  if (const VerbArguments* v = verbArguments(verb)) {
    for (std::string_view k : v->keys) {
      if (!k.empty()) keys.push_back(k);
    }
  }
  return keys;
}

Status checkFaultArguments(const FaultAction& action) {
  if (verbArguments(action.verb) == nullptr) {
    return makeError(ErrorCode::kInvalidArgument,
                     (action.where.empty() ? std::string() : action.where + ": ") +
                         unknownNameText("action", action.verb, faultVerbs()));
  }
  const std::vector<std::string_view> keys = faultArguments(action.verb);
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

// ---- FaultInjector --------------------------------------------------------------------------

FaultInjector::FaultInjector(Network& network, std::uint64_t seed)
    : network_(network), segment_(*network.segment), random_(seed) {
  segment_.setWireFaults(this);
}

FaultInjector::~FaultInjector() {
  segment_.setWireFaults(nullptr);
}

bool FaultInjector::handles(std::string_view verb) {
  return verbArguments(verb) != nullptr;
}

Result<std::size_t> FaultInjector::slaveIndex(std::string_view name) const {
  for (std::size_t i = 0; i < segment_.size(); ++i) {
    if (segment_.slave(i).name() == name) return i;
  }
  std::vector<std::string_view> names;
  for (std::size_t i = 0; i < segment_.size(); ++i) names.push_back(segment_.slave(i).name());
  return makeError(ErrorCode::kNotFound,
                   "no slave named '" + std::string(name) + "'" + didYouMean(name, names));
}

std::optional<FaultInjector::End> FaultInjector::peer(End end) const {
  const PortLink& l = segment_.ports(end.slave)[end.port];
  if (l.slave == kNoSlave) return std::nullopt;
  return End{static_cast<std::size_t>(l.slave), l.port};
}

Result<FaultInjector::End> FaultInjector::cableEnd(const FaultAction& action) const {
  if (auto name = action.get("cable")) {
    const CableRef* c = network_.findCable(*name);
    if (c == nullptr) {
      std::vector<std::string_view> names;
      for (const auto& cable : network_.cables) names.push_back(cable.name);
      return action.error("no cable named '" + std::string(*name) + "'" + didYouMean(*name, names));
    }
    return End{c->slave, c->port};
  }
  if (auto slave = action.get("slave")) {
    auto s = slaveIndex(*slave);
    if (!s.ok()) return action.error(s.error().context);
    ECSIM_ASSIGN_OR_RETURN(auto port, action.number("port", 0, kPortCount - 1));
    return End{*s, static_cast<unsigned>(port)};
  }
  return action.error("needs cable=NAME or slave=NAME port=N");
}

void FaultInjector::setCable(End end, bool up) {
  segment_.setLinkUp(end.slave, end.port, up);
  if (auto p = peer(end)) segment_.setLinkUp(p->slave, p->port, up);
}

bool FaultInjector::corrupts(std::size_t slave, unsigned port, SimTime /*time*/) {
  if (!anyWireFault_) return false;
  const End end{slave, port};
  if (auto it = corruptCount_.find(end); it != corruptCount_.end()) {
    if (--it->second == 0) corruptCount_.erase(it);
    refreshAny();
    ++framesCorrupted_;
    return true;
  }
  if (auto it = lossRate_.find(end); it != lossRate_.end() && random_.uniform() < it->second) {
    ++framesCorrupted_;
    return true;
  }
  return false;
}

SimTime FaultInjector::extraDelay(std::size_t slave, unsigned port, SimTime time) {
  if (spikes_.empty()) return 0;
  SimTime extra = 0;
  for (const auto& s : spikes_) {
    if (time >= s.until) continue;
    if ((s.end.slave == slave && s.end.port == port) ||
        (peer(s.end) && peer(s.end)->slave == slave && peer(s.end)->port == port)) {
      extra = saturatingAdd(extra, s.extra);
    }
  }
  return extra;
}

Result<std::string> FaultInjector::powerOff(std::size_t s) {
  auto& slave = segment_.slave(s);
  if (!slave.powered()) return std::string(slave.name() + " is already off");
  slave.powerOff();
  poweredOff_.insert(s);
  for (unsigned p = 0; p < kPortCount; ++p) {
    if (s == 0 && p == 0) {
      segment_.setLinkUp(0, 0, false);
    } else if (auto other = peer({s, p})) {
      segment_.setLinkUp(other->slave, other->port, false);
    }
  }
  return slave.name() + " powered off";
}

Result<std::string> FaultInjector::powerOn(std::size_t s, SimTime now) {
  auto& slave = segment_.slave(s);
  // Slave::powerOn also cold-starts the device: dictionary values back to power-up, the model
  // re-created (a drive keeps its shaft angle and state file).
  slave.powerOn(now);
  poweredOff_.erase(s);
  if (!slave.coldStartStatus().ok()) {
    return makeError(ErrorCode::kState,
                     slave.name() + ": device restart: " + slave.coldStartStatus().error().context);
  }
  for (unsigned p = 0; p < kPortCount; ++p) {
    const End end{s, p};
    std::optional<End> other = (s == 0 && p == 0) ? std::optional<End>() : peer(end);
    const bool cut = cablesDown_.count(end) > 0 || (other && cablesDown_.count(*other) > 0) ||
                     (other && poweredOff_.count(other->slave) > 0);
    if (cut) continue;
    if (s == 0 && p == 0) segment_.setLinkUp(0, 0, true);
    if (other) {
      segment_.setLinkUp(other->slave, other->port, true);
      segment_.setLinkUp(s, p, true);
    }
  }
  segment_.refreshLinkStatus();
  const bool running = slave.firmwareRunning();
  return slave.name() + " powered on" +
         (running ? std::string() : std::string(" (EEPROM not loaded: PDI not operational)"));
}

Result<std::string> FaultInjector::apply(const FaultAction& a, SimTime now) {
  const std::string& v = a.verb;
  if (v == "loss") {
    ECSIM_ASSIGN_OR_RETURN(auto rate, a.real("rate", 0, 1));
    End end{0, 0};
    if (a.get("cable")) {
      ECSIM_ASSIGN_OR_RETURN(end, cableEnd(a));
    }
    if (rate == 0)
      lossRate_.erase(end);
    else
      lossRate_[end] = rate;
    refreshAny();
    return fmt::format("frame loss {:.4f} at slave {} port {}", rate, end.slave, end.port);
  }
  if (v == "corrupt") {
    ECSIM_ASSIGN_OR_RETURN(auto end, cableEnd(a));
    ECSIM_ASSIGN_OR_RETURN(auto count, a.number("count", 0, kMaxCorruptCount, 1));
    if (count == 0) {
      corruptCount_.erase(end);
      refreshAny();
      return fmt::format("corruption entering {} port {} cleared", segment_.slave(end.slave).name(),
                         end.port);
    }
    auto& pending = corruptCount_[end];
    pending = std::min(pending + count, kMaxCorruptCount);
    refreshAny();
    return fmt::format("{} frame(s) corrupted entering {} port {}", pending,
                       segment_.slave(end.slave).name(), end.port);
  }
  if (v == "delay") {
    ECSIM_ASSIGN_OR_RETURN(auto end, cableEnd(a));
    ECSIM_ASSIGN_OR_RETURN(auto ns, a.number("ns", 0, kMaxDelaySpikeNs));
    ECSIM_ASSIGN_OR_RETURN(auto duration, a.millis("durationMs"));
    const std::optional<End> other = peer(end);
    const auto sameCable = [&](const Spike& s) {
      return s.end == end || (other && s.end == *other);
    };
    spikes_.erase(
        std::remove_if(spikes_.begin(), spikes_.end(),
                       [&](const Spike& s) { return s.until <= now || (ns == 0 && sameCable(s)); }),
        spikes_.end());
    refreshAny();
    if (ns == 0) return std::string("delay spikes on the cable removed");
    if (duration == 0) return std::string("no delay: durationMs=0");
    if (spikes_.size() >= kMaxDelaySpikes) {
      return a.error(
          fmt::format("{} delay spikes are active, the most at once (ns=0 removes a "
                      "cable's spikes)",
                      spikes_.size()));
    }
    spikes_.push_back({end, static_cast<SimTime>(ns), saturatingAdd(now, duration)});
    refreshAny();
    return fmt::format("cable delay +{} ns for {} ms", ns, a.get("durationMs").value_or(""));
  }
  if (v == "link-down" || v == "link-up") {
    ECSIM_ASSIGN_OR_RETURN(auto end, cableEnd(a));
    const bool up = v == "link-up";
    if (up) {
      cablesDown_.erase(end);
      if (auto p = peer(end)) cablesDown_.erase(*p);
    } else {
      cablesDown_.insert(end);
    }
    setCable(end, up);
    return fmt::format("link {} at {} port {}", up ? "up" : "down",
                       segment_.slave(end.slave).name(), end.port);
  }
  if (v == "input") {
    ECSIM_ASSIGN_OR_RETURN(auto name, a.require("slave"));
    auto s = slaveIndex(name);
    if (!s.ok()) return a.error(s.error().context);
    ECSIM_ASSIGN_OR_RETURN(auto text, a.require("signal"));
    auto signal = slavesim::devices::parseSignal(text);
    if (!signal.ok()) return a.error(signal.error().context);
    auto& slave = segment_.slave(*s);
    auto* di = slavesim::devices::digitalInputsOf(slave);
    auto* ai = slavesim::devices::analogInputsOf(slave);
    auto* enc = slavesim::devices::encoderTerminalOf(slave);
    const unsigned channels = di != nullptr    ? di->channels()
                              : ai != nullptr  ? ai->channels()
                              : enc != nullptr ? enc->channels()
                                               : 0;
    if (channels == 0) return a.error(slave.name() + " has no scriptable inputs");
    ECSIM_ASSIGN_OR_RETURN(auto ch, a.number("channel", 1, channels));
    const auto channel = static_cast<unsigned>(ch);
    // The script's time starts now: a square wave set at cycle 0 is high for its first half
    // period however long the bring-up before cycle 0 took.
    const auto script = signal->startingAt(now);
    if (di != nullptr) {
      di->setScript(channel, script);
    } else if (ai != nullptr) {
      ai->setScript(channel, script);
    } else {
      enc->setScript(channel, script);  // shaft position in turns
    }
    return fmt::format("{} input {} = {}", slave.name(), channel, text);
  }
  // The remaining verbs address one slave.
  ECSIM_ASSIGN_OR_RETURN(auto name, a.require("slave"));
  auto index = slaveIndex(name);
  if (!index.ok()) return a.error(index.error().context);
  const std::size_t s = *index;
  auto& slave = segment_.slave(s);
  if (v == "power-off") return powerOff(s);
  if (v == "power-on") return powerOn(s, now);
  if (v == "power-cycle") {
    if (auto off = powerOff(s); !off.ok()) return off.takeError();
    return powerOn(s, now);
  }
  if (v == "al-error") {
    ECSIM_ASSIGN_OR_RETURN(auto code, a.number("code", 0, 0xFFFF));
    AlState target = std::min(slave.state(), AlState::kSafeOp);
    if (auto st = a.get("state")) {
      auto parsed = stateFromName(*st);
      if (!parsed) {
        return a.error("state must be INIT, PREOP, SAFEOP or OP" +
                       didYouMean(*st, {"INIT", "PREOP", "SAFEOP", "OP"}));
      }
      target = *parsed;
    }
    slave.stateMachine().raiseError(slave.esc(), target, static_cast<std::uint16_t>(code));
    return fmt::format("{}: AL error {:#06x} ({}), now {}+ERR", slave.name(), code,
                       alStatusCodeText(static_cast<std::uint16_t>(code)), toString(target));
  }
  if (v == "eeprom-checksum") {
    auto& esc = slave.esc();
    if (esc.sii().size() <= kSiiChecksumByte) return a.error("the slave has no EEPROM");
    esc.writeSiiByte(kSiiChecksumByte,
                     static_cast<std::uint8_t>(esc.sii()[kSiiChecksumByte] ^ 0x5A));
    if (auto off = powerOff(s); !off.ok()) return off.takeError();
    return powerOn(s, now);
  }
  if (v == "mailbox-silent" || v == "mailbox-ok") {
    ECSIM_ASSIGN_OR_RETURN(auto on, a.number("on", 0, 1, v == "mailbox-silent" ? 1 : 0));
    if (slave.mailboxServer() == nullptr) return a.error(slave.name() + " has no mailbox");
    faultyMailbox(slave).silent = on != 0;
    return fmt::format("{}: mailbox {}", slave.name(), on != 0 ? "silent" : "answering");
  }
  if (v == "sdo-abort" || v == "sdo-ok") {
    FaultyMailbox::Rule rule;
    if (v == "sdo-abort") {
      ECSIM_ASSIGN_OR_RETURN(auto objIndex, a.number("index", 0, 0xFFFF));
      // Default: object does not exist.
      ECSIM_ASSIGN_OR_RETURN(auto code, a.number("code", 0, 0xFFFFFFFF, 0x06020000));
      rule.index = static_cast<std::uint16_t>(objIndex);
      rule.code = static_cast<std::uint32_t>(code);
      if (a.get("sub")) {
        ECSIM_ASSIGN_OR_RETURN(auto sub, a.number("sub", 0, 0xFF));
        rule.subindex = static_cast<std::uint8_t>(sub);
      }
    }
    if (slave.mailboxServer() == nullptr) return a.error(slave.name() + " has no mailbox");
    auto& mbx = faultyMailbox(slave);
    if (v == "sdo-ok") {
      mbx.aborts.clear();
      return slave.name() + ": SDO aborts removed";
    }
    // One rule per object: a new code replaces the old (the list stays as long as the
    // objects named, at most 65,536 x 257).
    std::erase_if(mbx.aborts, [&](const FaultyMailbox::Rule& r) {
      return r.index == rule.index && r.subindex == rule.subindex;
    });
    mbx.aborts.push_back(rule);
    const auto objIndex = rule.index;
    const auto code = rule.code;
    return fmt::format("{}: SDO {:#06x} aborted with {:#010x} ({})", slave.name(), objIndex, code,
                       sdoAbortText(static_cast<std::uint32_t>(code)));
  }
  if (v == "latch") {
    ECSIM_ASSIGN_OR_RETURN(auto unit, a.number("unit", 0, 1));
    ECSIM_ASSIGN_OR_RETURN(auto level, a.number("level", 0, 1));
    if (slave.esc().dcUnit() != slavesim::Esc::DcUnit::kFull) {
      return a.error(slave.name() + "'s ESC has no DC latch unit");
    }
    // The edge (if the level changes) at the action's time (esc_latch.cpp).
    slave.setLatchSignal(static_cast<unsigned>(unit), level != 0, now);
    return fmt::format("{}: LATCH{} = {}", slave.name(), unit, level);
  }
  if (v == "encoder-fault") {
    if (slavesim::devices::encoderTerminalOf(slave) != nullptr) return encoderFault(a, slave);
  }
  if (v == "drive-fault" || v == "encoder-fault") {
    std::uint16_t code = kPositionSensorFault;
    if (v == "drive-fault") {
      ECSIM_ASSIGN_OR_RETURN(auto c, a.number("code", 0, 0xFFFF, kOvercurrent));
      code = static_cast<std::uint16_t>(c);
    }
    auto* drive = slavesim::devices::driveOf(slave);
    if (drive == nullptr) {
      return a.error(slave.name() + (v == "encoder-fault"
                                         ? " is neither an encoder terminal nor a CiA 402 drive"
                                         : " is not a CiA 402 drive"));
    }
    drive->injectFault(code);
    return fmt::format("{}: drive fault {:#06x}", slave.name(), code);
  }
  return a.error("unknown action");
}

}  // namespace ecsim::topology
