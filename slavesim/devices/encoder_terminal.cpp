#include "slavesim/devices/encoder_terminal.hpp"

#include <numbers>
#include <string>

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

Result<std::unique_ptr<SsiEncoderTerminal>> SsiEncoderTerminal::create(
    coe::ObjectDictionary& od, const EncoderTerminalOptions& options) {
  std::unique_ptr<SsiEncoderTerminal> t(new SsiEncoderTerminal(options));
  double angle = options.initialShaftAngle;
  if (!options.stateFile.empty()) {
    ECSIM_ASSIGN_OR_RETURN(auto file, DeviceStateFile::open(options.stateFile));
    if (file.loaded()) angle = file.loaded()->shaftAngle;
    t->stateSaver_.emplace(std::move(file), options.stateSaveInterval);
  }
  for (unsigned c = 0; c < kMaxChannels; ++c) {
    const auto index = static_cast<std::uint16_t>(kInputBase + kChannelStride * c);
    ObjectRef counter(od, index, kSubCounter);
    if (!counter) break;
    Channel ch(options.encoder);
    ch.counter = counter;
    ch.dataError = ObjectRef(od, index, kSubDataError);
    ch.frameError = ObjectRef(od, index, kSubFrameError);
    ch.powerFailure = ObjectRef(od, index, kSubPowerFailure);
    ch.txPdoState = ObjectRef(od, index, kSubTxPdoState);
    ch.txPdoToggle = ObjectRef(od, index, kSubTxPdoToggle);
    ch.angle = angle;
    ch.encoder.powerOn(angle);
    t->channels_.push_back(std::move(ch));
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
  if (latched_ && now == lastLatch_) return;
  latched_ = true;
  lastLatch_ = now;
  std::uint8_t reg = 0;
  for (Channel& c : channels_) {
    if (c.script) c.angle = c.script->value(now) * kTurn;
    const bool valid = c.faults == kNone;
    // A faulted encoder's reading is the last valid one (Encoder::setFault).
    c.encoder.setFault(!valid);
    const EncoderReading r = c.encoder.read(c.angle);
    c.counter.set(static_cast<std::int64_t>(static_cast<std::uint32_t>(r.reported)));
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
