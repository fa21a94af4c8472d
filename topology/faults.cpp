#include "topology/faults.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <array>

#include "protocol/al_status.hpp"
#include "protocol/closest_name.hpp"
#include "protocol/mailbox.hpp"
#include "protocol/sdo.hpp"
#include "slavesim/devices/device_models.hpp"
#include "slavesim/process_data.hpp"

namespace ecsim::topology {
namespace {

constexpr std::size_t kSiiChecksumByte = 14;  // word 7, low byte: CRC-8 of words 0-6
constexpr std::uint16_t kPositionSensorFault = 0x7305;

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

Error fail(std::string message) {
  return makeError(ErrorCode::kInvalidArgument, std::move(message));
}

}  // namespace

// ---- FaultInjector --------------------------------------------------------------------------

FaultInjector::FaultInjector(Network& network, std::uint64_t seed)
    : network_(network), segment_(*network.segment), random_(seed) {
  segment_.setWireFaults(this);
}

FaultInjector::~FaultInjector() {
  segment_.setWireFaults(nullptr);
}

bool FaultInjector::handles(std::string_view verb) {
  const auto verbs = faultVerbs(FaultScope::kControl);
  return std::find(verbs.begin(), verbs.end(), verb) != verbs.end();
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

Result<std::size_t> FaultInjector::slaveNamed(std::string_view name) const {
  auto s = slaveIndex(name);
  if (!s.ok()) return fail(s.error().context);
  return *s;
}

Result<FaultInjector::End> FaultInjector::cableEnd(const FaultPlace& at) const {
  if (!at.cable.empty()) {
    const CableRef* c = network_.findCable(at.cable);
    if (c == nullptr) {
      std::vector<std::string_view> names;
      for (const auto& cable : network_.cables) names.push_back(cable.name);
      return fail("no cable named '" + at.cable + "'" + didYouMean(at.cable, names));
    }
    return End{c->slave, c->port};
  }
  ECSIM_ASSIGN_OR_RETURN(auto s, slaveNamed(at.slave));
  return End{s, at.port};
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

Result<std::string> FaultInjector::apply(const Fault& fault, SimTime now, std::string_view where) {
  auto done = std::visit([&](const auto& f) { return on(f, now); }, fault);
  if (done.ok()) return done;
  return makeError(done.error().code, (where.empty() ? std::string() : std::string(where) + ": ") +
                                          std::string(verbOf(fault)) + ": " + done.error().context);
}

Result<std::string> FaultInjector::on(const Loss& f, SimTime /*now*/) {
  End end{0, 0};  // the master's cable
  if (!f.cable.empty()) {
    ECSIM_ASSIGN_OR_RETURN(end, cableEnd(FaultPlace{f.cable, {}, 0}));
  }
  if (f.rate == 0)
    lossRate_.erase(end);
  else
    lossRate_[end] = f.rate;
  refreshAny();
  return fmt::format("frame loss {:.4f} at slave {} port {}", f.rate, end.slave, end.port);
}

Result<std::string> FaultInjector::on(const Corrupt& f, SimTime /*now*/) {
  ECSIM_ASSIGN_OR_RETURN(auto end, cableEnd(f.at));
  if (f.count == 0) {
    corruptCount_.erase(end);
    refreshAny();
    return fmt::format("corruption entering {} port {} cleared", segment_.slave(end.slave).name(),
                       end.port);
  }
  auto& pending = corruptCount_[end];
  pending = std::min(pending + f.count, kMaxCorruptCount);
  refreshAny();
  return fmt::format("{} frame(s) corrupted entering {} port {}", pending,
                     segment_.slave(end.slave).name(), end.port);
}

Result<std::string> FaultInjector::on(const Delay& f, SimTime now) {
  ECSIM_ASSIGN_OR_RETURN(auto end, cableEnd(f.at));
  const std::optional<End> other = peer(end);
  const auto sameCable = [&](const Spike& s) { return s.end == end || (other && s.end == *other); };
  spikes_.erase(std::remove_if(spikes_.begin(), spikes_.end(),
                               [&](const Spike& s) {
                                 return s.until <= now || (f.extra == 0 && sameCable(s));
                               }),
                spikes_.end());
  refreshAny();
  if (f.extra == 0) return std::string("delay spikes on the cable removed");
  if (f.duration == 0) return std::string("no delay: duration 0");
  if (spikes_.size() >= kMaxDelaySpikes) {
    return fail(
        fmt::format("{} delay spikes are active, the most at once (ns=0 removes a cable's spikes)",
                    spikes_.size()));
  }
  spikes_.push_back({end, f.extra, saturatingAdd(now, f.duration)});
  refreshAny();
  return fmt::format("cable delay +{} ns for {} ms", f.extra,
                     static_cast<double>(f.duration) / static_cast<double>(kNsPerMs));
}

Result<std::string> FaultInjector::setLink(const FaultPlace& at, bool up) {
  ECSIM_ASSIGN_OR_RETURN(auto end, cableEnd(at));
  if (up) {
    cablesDown_.erase(end);
    if (auto p = peer(end)) cablesDown_.erase(*p);
  } else {
    cablesDown_.insert(end);
  }
  setCable(end, up);
  return fmt::format("link {} at {} port {}", up ? "up" : "down", segment_.slave(end.slave).name(),
                     end.port);
}

Result<std::string> FaultInjector::on(const LinkDown& f, SimTime /*now*/) {
  return setLink(f.at, false);
}

Result<std::string> FaultInjector::on(const LinkUp& f, SimTime /*now*/) {
  return setLink(f.at, true);
}

Result<std::string> FaultInjector::on(const Input& f, SimTime now) {
  ECSIM_ASSIGN_OR_RETURN(auto s, slaveNamed(f.slave));
  auto& slave = segment_.slave(s);
  auto* di = slavesim::devices::digitalInputsOf(slave);
  auto* ai = slavesim::devices::analogInputsOf(slave);
  auto* enc = slavesim::devices::encoderTerminalOf(slave);
  const unsigned channels = di != nullptr    ? di->channels()
                            : ai != nullptr  ? ai->channels()
                            : enc != nullptr ? enc->channels()
                                             : 0;
  if (channels == 0) return fail(slave.name() + " has no scriptable inputs");
  if (f.channel < 1 || f.channel > channels) {
    return fail(fmt::format("channel={} is not a number in [1, {}] ({}'s channels)", f.channel,
                            channels, slave.name()));
  }
  // The script's time starts now: a square wave set at cycle 0 is high for its first half
  // period however long the bring-up before cycle 0 took.
  const auto script = f.signal.startingAt(now);
  if (di != nullptr) {
    di->setScript(f.channel, script);
  } else if (ai != nullptr) {
    ai->setScript(f.channel, script);
  } else {
    enc->setScript(f.channel, script);  // shaft position in turns
  }
  return fmt::format("{} input {} = {}", slave.name(), f.channel, f.text);
}

Result<std::string> FaultInjector::on(const PowerOff& f, SimTime /*now*/) {
  ECSIM_ASSIGN_OR_RETURN(auto s, slaveNamed(f.slave));
  return powerOff(s);
}

Result<std::string> FaultInjector::on(const PowerOn& f, SimTime now) {
  ECSIM_ASSIGN_OR_RETURN(auto s, slaveNamed(f.slave));
  return powerOn(s, now);
}

Result<std::string> FaultInjector::on(const PowerCycle& f, SimTime now) {
  ECSIM_ASSIGN_OR_RETURN(auto s, slaveNamed(f.slave));
  if (auto off = powerOff(s); !off.ok()) return off.takeError();
  return powerOn(s, now);
}

// Detached, a group's slaves are without power as a tool taken off its changer is: the
// junction's port loses its link (and its ESC closes it), the rest of the network runs on.
// Attached again they power up (INIT, station address 0, EEPROM loaded) for the master to find.
Result<std::string> FaultInjector::on(const HotConnect& f, SimTime now) {
  const auto group = std::find_if(network_.groups.begin(), network_.groups.end(),
                                  [&](const HotConnectGroup& g) { return g.name == f.group; });
  if (group == network_.groups.end()) {
    std::vector<std::string_view> names;
    for (const auto& g : network_.groups) names.push_back(g.name);
    return fail("no group named '" + f.group + "'" + didYouMean(f.group, names) +
                (names.empty() ? " (the topology has no <Group>)" : ""));
  }
  for (const std::size_t s : group->slaves) {
    if (f.attach) {
      if (auto on = powerOn(s, now); !on.ok()) return on.takeError();
    } else if (segment_.slave(s).powered()) {
      if (auto off = powerOff(s); !off.ok()) return off.takeError();
    }
  }
  return fmt::format("group {} {} ({} slave(s))", f.group, f.attach ? "attached" : "detached",
                     group->slaves.size());
}

Result<std::string> FaultInjector::on(const AlError& f, SimTime /*now*/) {
  ECSIM_ASSIGN_OR_RETURN(auto s, slaveNamed(f.slave));
  auto& slave = segment_.slave(s);
  const AlState target = f.state.value_or(std::min(slave.state(), AlState::kSafeOp));
  slave.stateMachine().raiseError(slave.esc(), target, f.code);
  return fmt::format("{}: AL error {:#06x} ({}), now {}+ERR", slave.name(), f.code,
                     alStatusCodeText(f.code), toString(target));
}

Result<std::string> FaultInjector::on(const EepromChecksum& f, SimTime now) {
  ECSIM_ASSIGN_OR_RETURN(auto s, slaveNamed(f.slave));
  auto& esc = segment_.slave(s).esc();
  if (esc.sii().size() <= kSiiChecksumByte) return fail("the slave has no EEPROM");
  esc.writeSiiByte(kSiiChecksumByte, static_cast<std::uint8_t>(esc.sii()[kSiiChecksumByte] ^ 0x5A));
  if (auto off = powerOff(s); !off.ok()) return off.takeError();
  return powerOn(s, now);
}

Result<std::string> FaultInjector::on(const MailboxSilent& f, SimTime /*now*/) {
  ECSIM_ASSIGN_OR_RETURN(auto s, slaveNamed(f.slave));
  auto& slave = segment_.slave(s);
  if (slave.mailboxServer() == nullptr) return fail(slave.name() + " has no mailbox");
  faultyMailbox(slave).silent = f.silent;
  return fmt::format("{}: mailbox {}", slave.name(), f.silent ? "silent" : "answering");
}

Result<std::string> FaultInjector::on(const SdoAbortFault& f, SimTime /*now*/) {
  ECSIM_ASSIGN_OR_RETURN(auto s, slaveNamed(f.slave));
  auto& slave = segment_.slave(s);
  if (slave.mailboxServer() == nullptr) return fail(slave.name() + " has no mailbox");
  auto& mbx = faultyMailbox(slave);
  // One rule per object: a new code replaces the old (the list stays as long as the objects
  // named, at most 65,536 x 257).
  std::erase_if(mbx.aborts, [&](const FaultyMailbox::Rule& r) {
    return r.index == f.index && r.subindex == f.subindex;
  });
  mbx.aborts.push_back({f.index, f.subindex, f.code});
  return fmt::format("{}: SDO {:#06x} aborted with {:#010x} ({})", slave.name(), f.index, f.code,
                     sdoAbortText(f.code));
}

Result<std::string> FaultInjector::on(const SdoOk& f, SimTime /*now*/) {
  ECSIM_ASSIGN_OR_RETURN(auto s, slaveNamed(f.slave));
  auto& slave = segment_.slave(s);
  if (slave.mailboxServer() == nullptr) return fail(slave.name() + " has no mailbox");
  faultyMailbox(slave).aborts.clear();
  return slave.name() + ": SDO aborts removed";
}

Result<std::string> FaultInjector::on(const Latch& f, SimTime now) {
  ECSIM_ASSIGN_OR_RETURN(auto s, slaveNamed(f.slave));
  auto& slave = segment_.slave(s);
  if (slave.esc().dcUnit() != slavesim::Esc::DcUnit::kFull) {
    return fail(slave.name() + "'s ESC has no DC latch unit");
  }
  // The edge (if the level changes) at the action's time (esc_latch.cpp).
  slave.setLatchSignal(f.unit, f.level, now);
  return fmt::format("{}: LATCH{} = {}", slave.name(), f.unit, f.level ? 1 : 0);
}

Result<std::string> FaultInjector::on(const DriveFault& f, SimTime /*now*/) {
  ECSIM_ASSIGN_OR_RETURN(auto s, slaveNamed(f.slave));
  auto& slave = segment_.slave(s);
  auto* drive = slavesim::devices::driveOf(slave);
  if (drive == nullptr) return fail(slave.name() + " is not a CiA 402 drive");
  drive->injectFault(f.code);
  return fmt::format("{}: drive fault {:#06x}", slave.name(), f.code);
}

// On an encoder terminal (slavesim/devices/encoder_terminal.hpp) the channel's status bits; on
// a CiA 402 drive its position sensor fault.
Result<std::string> FaultInjector::on(const EncoderFault& f, SimTime /*now*/) {
  ECSIM_ASSIGN_OR_RETURN(auto s, slaveNamed(f.slave));
  auto& slave = segment_.slave(s);
  if (auto* encoder = slavesim::devices::encoderTerminalOf(slave)) {
    if (f.channel > encoder->channels()) {
      return fail(fmt::format("channel={} is not a number in [1, {}] ({}'s channels)", f.channel,
                              encoder->channels(), slave.name()));
    }
    namespace ef = slavesim::devices::encoder_fault;
    const std::uint8_t bit = f.kind == EncoderFault::Kind::kFrame   ? ef::kFrame
                             : f.kind == EncoderFault::Kind::kPower ? ef::kPower
                                                                    : ef::kData;
    const std::uint8_t old = encoder->fault(f.channel);
    encoder->setFault(f.channel, f.on ? static_cast<std::uint8_t>(old | bit)
                                      : static_cast<std::uint8_t>(old & ~bit));
    return fmt::format("{}: encoder channel {} {} {}", slave.name(), f.channel, toString(f.kind),
                       f.on ? "fault" : "fault cleared");
  }
  auto* drive = slavesim::devices::driveOf(slave);
  if (drive == nullptr)
    return fail(slave.name() + " is neither an encoder terminal nor a CiA 402 drive");
  drive->injectFault(kPositionSensorFault);
  return fmt::format("{}: drive fault {:#06x}", slave.name(), kPositionSensorFault);
}

Result<std::string> FaultInjector::on(const PauseMaster& /*f*/, SimTime /*now*/) {
  return fail("a scenario action of the runner's master: no network fault");
}

}  // namespace ecsim::topology
