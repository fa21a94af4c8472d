#include "slavesim/devices/encoder_terminal.hpp"

#include <algorithm>
#include <numbers>
#include <string>
#include <string_view>

#include "slavesim/coe/data_types.hpp"
#include "slavesim/coe/standard_objects.hpp"

#include "slavesim/devices/device_state.hpp"
#include "slavesim/devices/error_register.hpp"

namespace ecsim::slavesim::devices {
namespace {

// Subindexes of a channel's input object (EJ5002 revision 0x00110000, DT6000).
constexpr std::uint8_t kSubDataError = 0x01;
constexpr std::uint8_t kSubFrameError = 0x02;
constexpr std::uint8_t kSubPowerFailure = 0x03;
constexpr std::uint8_t kSubTxPdoState = 0x0F;
constexpr std::uint8_t kSubTxPdoToggle = 0x10;
constexpr std::uint8_t kSubCounter = 0x11;

constexpr double kTurn = 2.0 * std::numbers::pi;

}  // namespace

Result<double> SsiEncoderTerminal::powerUpAngle() {
  double angle = options_.initialShaftAngle;
  if (!options_.stateFile.empty()) {
    ECSIM_ASSIGN_OR_RETURN(auto file, DeviceStateFile::open(options_.stateFile));
    if (file.loaded()) angle = file.loaded()->shaftAngle;
    stateSaver_.emplace(std::move(file), options_.stateSaveInterval);
  }
  return angle;
}

SsiEncoderTerminal::Channel& SsiEncoderTerminal::addChannel(double angle) {
  Channel& ch = channels_.emplace_back(options_.encoder);
  ch.angle = angle;
  ch.encoder.powerOn(angle);
  return ch;
}

Result<std::unique_ptr<SsiEncoderTerminal>> SsiEncoderTerminal::create(
    coe::ObjectDictionary& od, const EncoderTerminalOptions& options) {
  std::unique_ptr<SsiEncoderTerminal> t(new SsiEncoderTerminal(options));
  ECSIM_ASSIGN_OR_RETURN(const double angle, t->powerUpAngle());
  for (unsigned c = 0; c < kMaxChannels; ++c) {
    const auto index = static_cast<std::uint16_t>(kInputBase + kChannelStride * c);
    ObjectRef counter(od, index, kSubCounter);
    if (!counter) break;
    Channel& ch = t->addChannel(angle);
    ch.counter = counter;
    ch.dataError = ObjectRef(od, index, kSubDataError);
    ch.frameError = ObjectRef(od, index, kSubFrameError);
    ch.powerFailure = ObjectRef(od, index, kSubPowerFailure);
    ch.txPdoState = ObjectRef(od, index, kSubTxPdoState);
    ch.txPdoToggle = ObjectRef(od, index, kSubTxPdoToggle);
  }
  if (t->channels_.empty()) {
    return makeError(ErrorCode::kNotFound,
                     "SSI encoder terminal: dictionary has no counter value 0x6000:11");
  }
  t->errorRegister_ = ObjectRef(od, error_register::kIndex, 0);
  t->latch(0);  // the first reading, so the inputs are valid from the start
  t->latched_ = false;
  return t;
}

Result<std::unique_ptr<SsiEncoderTerminal>> SsiEncoderTerminal::createForCounters(
    coe::ObjectDictionary& od, const EncoderTerminalOptions& options) {
  const std::vector<CounterChannel> found = counterValueChannels(od);
  if (found.empty()) {
    return makeError(ErrorCode::kNotFound,
                     "encoder: no TxPDO maps a \"Counter value\" or an unsigned \"Value\" entry");
  }
  std::unique_ptr<SsiEncoderTerminal> t(new SsiEncoderTerminal(options));
  ECSIM_ASSIGN_OR_RETURN(const double angle, t->powerUpAngle());
  // An entry of the channel object when it has the expected name (EJ5101 0x6010:0F/:10).
  auto named = [&od](std::uint16_t index, std::uint8_t sub, std::string_view name) {
    const coe::Entry* e = od.findEntry(index, sub);
    return e != nullptr && e->name.find(name) != std::string::npos ? ObjectRef(od, index, sub)
                                                                 : ObjectRef();
  };
  for (std::size_t c = 0; c < found.size() && c < kMaxChannels; ++c) {
    Channel& ch = t->addChannel(angle);
    const CounterEntry& counter = found[c].counter.index != 0 ? found[c].counter : found[c].compact;
    ch.counter = ObjectRef(od, counter.index, counter.subindex);
    if (found[c].counter.index != 0 && found[c].compact.index != 0) {
      ch.compactCounter = ObjectRef(od, found[c].compact.index, found[c].compact.subindex);
    }
    ch.txPdoState = named(counter.index, kSubTxPdoState, "TxPDO State");
    ch.txPdoToggle = named(counter.index, kSubTxPdoToggle, "TxPDO Toggle");
  }
  t->errorRegister_ = ObjectRef(od, error_register::kIndex, 0);
  t->latch(0);
  t->latched_ = false;
  return t;
}

std::vector<CounterChannel> counterValueChannels(const coe::ObjectDictionary& od) {
  std::vector<CounterEntry> counters, compacts;
  auto add = [](std::vector<CounterEntry>& list, CounterEntry e) {
    for (const CounterEntry& x : list) {
      if (x.index == e.index && x.subindex == e.subindex) return;
    }
    list.push_back(e);
  };
  for (const auto& [index, object] : od.objects()) {
    if (!coe::isTxPdoMappingIndex(index)) continue;
    for (const coe::Entry& slot : object.entries) {
      if (slot.subindex == 0) continue;
      const auto mapped = coe::MappedObject::fromRaw(
          static_cast<std::uint32_t>(coe::readRawValue(ConstBytes(slot.value), slot.bitLength)));
      if (mapped.isPadding()) continue;
      const coe::Entry* e = od.findEntry(mapped.index, mapped.subindex);
      if (e == nullptr) continue;
      const CounterEntry where{mapped.index, mapped.subindex};
      if (e->name == "Counter value") {
        add(counters, where);
      } else if (e->name == "Value" && (e->dataType == coe::data_type::kUnsigned16 ||
                                        e->dataType == coe::data_type::kUnsigned32)) {
        add(compacts, where);
      }
    }
  }
  const auto byIndex = [](const CounterEntry& a, const CounterEntry& b) {
    return a.index != b.index ? a.index < b.index : a.subindex < b.subindex;
  };
  std::sort(counters.begin(), counters.end(), byIndex);
  std::sort(compacts.begin(), compacts.end(), byIndex);
  std::vector<CounterChannel> channels(std::max(counters.size(), compacts.size()));
  for (std::size_t n = 0; n < counters.size(); ++n) channels[n].counter = counters[n];
  for (std::size_t n = 0; n < compacts.size(); ++n) channels[n].compact = compacts[n];
  return channels;
}

SsiEncoderTerminal::~SsiEncoderTerminal() {
  (void)saveState();
}

Status SsiEncoderTerminal::saveState() const {
  if (!stateSaver_ || channels_.empty()) return okStatus();
  return stateSaver_->save(DeviceState{channels_.front().angle});
}

void SsiEncoderTerminal::setShaftAngle(unsigned channel, double rad) {
  if (channel >= 1 && channel <= channels_.size()) channels_[channel - 1].angle = rad;
}

double SsiEncoderTerminal::shaftAngle(unsigned channel) const {
  return channel >= 1 && channel <= channels_.size() ? channels_[channel - 1].angle : 0.0;
}

void SsiEncoderTerminal::setScript(unsigned channel, Signal turns) {
  if (channel >= 1 && channel <= channels_.size()) channels_[channel - 1].script = std::move(turns);
}

void SsiEncoderTerminal::clearScript(unsigned channel) {
  if (channel >= 1 && channel <= channels_.size()) channels_[channel - 1].script.reset();
}

void SsiEncoderTerminal::setFault(unsigned channel, std::uint8_t faults) {
  if (channel >= 1 && channel <= channels_.size()) channels_[channel - 1].faults = faults;
}

std::uint8_t SsiEncoderTerminal::fault(unsigned channel) const {
  return channel >= 1 && channel <= channels_.size() ? channels_[channel - 1].faults
                                                     : encoder_fault::kNone;
}

void SsiEncoderTerminal::step(coe::ObjectDictionary& /*od*/, AlState /*state*/, SimTime now) {
  if (!syncActive()) latch(now);
}

void SsiEncoderTerminal::sync(coe::ObjectDictionary& /*od*/, unsigned signal, AlState /*state*/,
                              SimTime now) {
  if (signal == 0 && syncActive()) latch(now);
}

void SsiEncoderTerminal::latch(SimTime now) {
  using namespace encoder_fault;
  // One SSI reading per point in time: a second firmware step at the same time (polled before
  // and after a frame) reads nothing new.
  if (latched_ && now == lastLatch_) {
    // The held reading again: a 2006-era device's made-up object (EL5101 0x3101:02 "Value")
    // is mapped by its RxPDO as well, and the outputs just copied in overwrote it.
    for (Channel& c : channels_) {
      c.counter.set(c.reported);
      c.compactCounter.set(c.reported);
    }
    return;
  }
  latched_ = true;
  lastLatch_ = now;
  std::uint8_t reg = 0;
  for (Channel& c : channels_) {
    if (c.script) c.angle = c.script->value(now) * kTurn;
    const bool valid = c.faults == kNone;
    // A faulted encoder's reading is the last valid one (Encoder::setFault).
    c.encoder.setFault(!valid);
    const EncoderReading r = c.encoder.read(c.angle);
    c.reported = static_cast<std::uint32_t>(r.reported);
    c.counter.set(c.reported);
    c.compactCounter.set(c.reported);
    // An encoder without supply sends no data: a data error too.
    c.dataError.set((c.faults & (kData | kPower)) != 0 ? 1 : 0);
    c.frameError.set((c.faults & kFrame) != 0 ? 1 : 0);
    c.powerFailure.set((c.faults & kPower) != 0 ? 1 : 0);
    c.txPdoState.set(valid ? 0 : 1);
    if (valid) c.toggle = !c.toggle;
    c.txPdoToggle.set(c.toggle ? 1 : 0);
    if (!valid) reg |= error_register::kGeneric;
    if ((c.faults & kPower) != 0) reg |= error_register::kVoltage;
  }
  errorRegisterValue_ = reg;
  errorRegister_.set(reg);
  if (stateSaver_) (void)stateSaver_->tick(now, DeviceState{channels_.front().angle});
}

}  // namespace ecsim::slavesim::devices
