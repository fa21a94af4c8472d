#include "slavesim/devices/io_terminals.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>

#include "slavesim/devices/error_register.hpp"

namespace ecsim::slavesim::devices {
namespace {

constexpr std::uint16_t kAnalogInputBase = 0x6000;
constexpr std::uint16_t kAnalogSettingsBase = 0x8000;
constexpr std::uint16_t kChannelStride = 0x10;
constexpr std::uint8_t kSubStatus = 0x01;
constexpr std::uint8_t kSubValue = 0x11;
constexpr std::uint8_t kSubFilterOn = 0x01;
constexpr std::uint8_t kSubLimit1On = 0x02;
constexpr std::uint8_t kSubLimit2On = 0x03;
constexpr std::uint8_t kSubLimit1 = 0x11;
constexpr std::uint8_t kSubLimit2 = 0x12;
constexpr std::uint8_t kSubFilterMs = 0x13;

// Status bits of an analog channel (examples/README.md, ECS3102).
constexpr std::uint16_t kStatusUnderrange = 1u << 0;
constexpr std::uint16_t kStatusOverrange = 1u << 1;
constexpr unsigned kStatusLimit1Shift = 2;
constexpr unsigned kStatusLimit2Shift = 4;
constexpr std::uint16_t kStatusError = 1u << 6;
constexpr std::uint16_t kStatusToggle = 1u << 15;
constexpr std::int64_t kRawFullScale = kAnalogRawFullScale;

// Conversions done in one step at most; beyond it the channel is taken as settled.
constexpr std::int64_t kMaxConversionsPerStep = 10000;

Error missing(std::uint16_t index, unsigned sub) {
  return makeError(ErrorCode::kNotFound, "IO terminal: dictionary has no entry " +
                                             std::to_string(index) + ":" + std::to_string(sub));
}

constexpr std::size_t kMaxDigitalOutputs = 32;  // OutputChange::outputs has 32 bits

Result<std::vector<DigitalChannel>> channelRefs(coe::ObjectDictionary& od, std::uint16_t index,
                                                unsigned channels) {
  std::vector<DigitalChannel> refs;
  for (unsigned c = 1; c <= channels; ++c) {
    ObjectRef r(od, index, static_cast<std::uint8_t>(c));
    if (!r) return missing(index, c);
    refs.push_back({r, 0});
  }
  return refs;
}

unsigned limitCode(bool enabled, std::int64_t value, std::int64_t limit) {
  if (!enabled) return 0;
  if (value > limit) return 1;
  if (value < limit) return 2;
  return 3;
}

}  // namespace

// ---- digital inputs ---------------------------------------------------------------------------

Result<std::unique_ptr<DigitalInputTerminal>> DigitalInputTerminal::create(
    coe::ObjectDictionary& od, std::uint16_t index, unsigned channels) {
  ECSIM_ASSIGN_OR_RETURN(auto refs, channelRefs(od, index, channels));
  return create(std::move(refs));
}

std::unique_ptr<DigitalInputTerminal> DigitalInputTerminal::create(
    std::vector<DigitalChannel> channels) {
  std::unique_ptr<DigitalInputTerminal> t(new DigitalInputTerminal());
  for (const DigitalChannel& c : channels) t->channels_.push_back({c, std::nullopt});
  return t;
}

void DigitalInputTerminal::setScript(unsigned channel, Signal signal) {
  if (channel >= 1 && channel <= channels_.size())
    channels_[channel - 1].script = std::move(signal);
}

void DigitalInputTerminal::clearScript(unsigned channel) {
  if (channel >= 1 && channel <= channels_.size()) channels_[channel - 1].script.reset();
}

bool DigitalInputTerminal::input(unsigned channel) const {
  return channel >= 1 && channel <= channels_.size() && channels_[channel - 1].value.get();
}

void DigitalInputTerminal::step(coe::ObjectDictionary& /*od*/, AlState /*state*/, SimTime now) {
  if (!syncActive()) latch(now);
}

void DigitalInputTerminal::sync(coe::ObjectDictionary& /*od*/, unsigned signal, AlState /*state*/,
                                SimTime now) {
  if (signal == 0 && syncActive()) latch(now);
}

void DigitalInputTerminal::latch(SimTime now) {
  for (Channel& c : channels_) {
    if (c.script) c.value.set(c.script->value(now) >= 0.5);
  }
}

// ---- digital outputs --------------------------------------------------------------------------

Result<std::unique_ptr<DigitalOutputTerminal>> DigitalOutputTerminal::create(
    coe::ObjectDictionary& od, std::uint16_t index, unsigned channels) {
  if (channels > kMaxDigitalOutputs) {
    return makeError(ErrorCode::kInvalidArgument, "digital outputs: at most 32 channels");
  }
  ECSIM_ASSIGN_OR_RETURN(auto refs, channelRefs(od, index, channels));
  return create(std::move(refs));
}

Result<std::unique_ptr<DigitalOutputTerminal>> DigitalOutputTerminal::create(
    std::vector<DigitalChannel> channels) {
  if (channels.size() > kMaxDigitalOutputs) {
    return makeError(ErrorCode::kInvalidArgument,
                     "digital outputs: " + std::to_string(channels.size()) +
                         " channels, at most 32");
  }
  std::unique_ptr<DigitalOutputTerminal> t(new DigitalOutputTerminal());
  t->channels_ = std::move(channels);
  return t;
}

bool DigitalOutputTerminal::output(unsigned channel) const {
  return channel >= 1 && channel <= channels_.size() && ((outputs_ >> (channel - 1)) & 1u) != 0;
}

void DigitalOutputTerminal::enableLog(std::size_t capacity) {
  logCapacity_ = capacity;
  log_.clear();
  log_.reserve(capacity);
}

Status DigitalOutputTerminal::writeLogCsv(const std::filesystem::path& path) const {
  std::ofstream out(path);
  if (!out) return makeError(ErrorCode::kIo, path.string() + ": cannot write output log");
  out << "time_ns,outputs";
  for (std::size_t c = 1; c <= channels_.size(); ++c) out << ",out" << c;
  out << "\n";
  for (const OutputChange& change : log_) {
    out << change.time << "," << change.outputs;
    for (std::size_t c = 0; c < channels_.size(); ++c) out << "," << ((change.outputs >> c) & 1u);
    out << "\n";
  }
  out.flush();
  if (!out) return makeError(ErrorCode::kIo, path.string() + ": write failed");
  return okStatus();
}

void DigitalOutputTerminal::step(coe::ObjectDictionary& /*od*/, AlState state, SimTime now) {
  // With SYNC0 the outputs change at the pulses; leaving OP still makes them safe at once.
  if (!syncActive() || state != AlState::kOp) apply(state, now);
}

void DigitalOutputTerminal::sync(coe::ObjectDictionary& /*od*/, unsigned signal, AlState state,
                                 SimTime now) {
  if (signal == 0 && syncActive()) apply(state, now);
}

void DigitalOutputTerminal::apply(AlState state, SimTime now) {
  std::uint32_t next = 0;
  if (state == AlState::kOp) {
    for (std::size_t c = 0; c < channels_.size(); ++c) {
      if (channels_[c].get()) next |= 1u << c;
    }
  }
  if (next == outputs_) return;
  outputs_ = next;
  if (log_.size() < logCapacity_) log_.push_back({now, next});
  if (observer_) observer_(now, next);
}

// ---- analog inputs ----------------------------------------------------------------------------

Result<std::unique_ptr<AnalogInputTerminal>> AnalogInputTerminal::create(
    coe::ObjectDictionary& od, unsigned channels, AnalogInputOptions options) {
  std::vector<AnalogChannelObjects> objects;
  for (unsigned c = 0; c < channels; ++c) {
    const auto in = static_cast<std::uint16_t>(kAnalogInputBase + kChannelStride * c);
    const auto set = static_cast<std::uint16_t>(kAnalogSettingsBase + kChannelStride * c);
    AnalogChannelObjects ch;
    ch.status = ObjectRef(od, in, kSubStatus);
    ch.value = ObjectRef(od, in, kSubValue);
    if (!ch.status) return missing(in, kSubStatus);
    if (!ch.value) return missing(in, kSubValue);
    // Settings are optional (absent: filter and limits off).
    ch.filterOn = ObjectRef(od, set, kSubFilterOn);
    ch.limit1On = ObjectRef(od, set, kSubLimit1On);
    ch.limit2On = ObjectRef(od, set, kSubLimit2On);
    ch.limit1 = ObjectRef(od, set, kSubLimit1);
    ch.limit2 = ObjectRef(od, set, kSubLimit2);
    ch.filterMs = ObjectRef(od, set, kSubFilterMs);
    objects.push_back(ch);
  }
  return create(std::move(objects), od, options);
}

Result<std::unique_ptr<AnalogInputTerminal>> AnalogInputTerminal::create(
    std::vector<AnalogChannelObjects> channels, coe::ObjectDictionary& od,
    AnalogInputOptions options) {
  if (options.conversionPeriod <= 0 || options.fullScaleVolts <= 0.0) {
    return makeError(ErrorCode::kInvalidArgument,
                     "analog inputs: conversion period and full scale must be > 0");
  }
  std::unique_ptr<AnalogInputTerminal> t(new AnalogInputTerminal());
  t->options_ = options;
  for (AnalogChannelObjects& c : channels) {
    if (!c.value) return makeError(ErrorCode::kNotFound, "analog inputs: a channel has no value");
    Channel ch;
    ch.objects = c;
    t->channels_.push_back(std::move(ch));
  }
  t->errorRegister_ = ObjectRef(od, error_register::kIndex, 0);
  return t;
}

void AnalogInputTerminal::setScript(unsigned channel, Signal volts) {
  if (channel < 1 || channel > channels_.size()) return;
  // The filter keeps its state: a new script is a new signal at the same input.
  channels_[channel - 1].script = std::move(volts);
}

void AnalogInputTerminal::clearScript(unsigned channel) {
  if (channel >= 1 && channel <= channels_.size()) channels_[channel - 1].script.reset();
}

double AnalogInputTerminal::volts(unsigned channel) const {
  return channel >= 1 && channel <= channels_.size() ? channels_[channel - 1].filtered : 0.0;
}

std::int16_t AnalogInputTerminal::rawValue(double volts) const {
  const double raw = std::round(volts / options_.fullScaleVolts * kRawFullScale);
  return static_cast<std::int16_t>(std::clamp(raw, -32768.0, 32767.0));
}

void AnalogInputTerminal::convert(Channel& c, SimTime t) {
  const double x = c.script->value(t);
  const double tauMs = static_cast<double>(c.objects.filterMs.get(10));
  if (c.objects.filterOn.get() != 0 && tauMs > 0.0 && c.primed) {
    const double period = static_cast<double>(options_.conversionPeriod) / kNsPerMs;
    c.filtered += (1.0 - std::exp(-period / tauMs)) * (x - c.filtered);
  } else {
    c.filtered = x;
  }
  c.primed = true;
  c.toggle = !c.toggle;
}

void AnalogInputTerminal::step(coe::ObjectDictionary& /*od*/, AlState /*state*/, SimTime now) {
  if (!syncActive()) update(now);
}

void AnalogInputTerminal::sync(coe::ObjectDictionary& /*od*/, unsigned signal, AlState /*state*/,
                               SimTime now) {
  if (signal == 0 && syncActive()) update(now);
}

void AnalogInputTerminal::update(SimTime now) {
  if (!started_) {
    started_ = true;
    nextConversion_ = now;
  }
  if (now < nextConversion_) return;
  const SimTime period = options_.conversionPeriod;
  std::int64_t pending = (now - nextConversion_) / period + 1;
  if (pending > kMaxConversionsPerStep) {
    // Long gap: the filters have settled; convert the last few periods only.
    nextConversion_ += (pending - kMaxConversionsPerStep) * period;
    pending = kMaxConversionsPerStep;
  }
  for (Channel& c : channels_) {
    if (!c.script) continue;
    for (std::int64_t k = 0; k < pending; ++k) convert(c, nextConversion_ + k * period);
    AnalogChannelObjects& o = c.objects;
    const double scaled = c.filtered / options_.fullScaleVolts * kRawFullScale;
    const double lowest = o.unsignedValue ? 0.0 : -static_cast<double>(kRawFullScale);
    const std::int64_t raw = rawValue(c.filtered);
    const std::int64_t value = o.unsignedValue ? std::max<std::int64_t>(raw, 0) : raw;
    std::uint16_t status = 0;
    if (scaled < lowest) status |= kStatusUnderrange;
    if (scaled > static_cast<double>(kRawFullScale)) status |= kStatusOverrange;
    if ((status & (kStatusUnderrange | kStatusOverrange)) != 0) status |= kStatusError;
    status = static_cast<std::uint16_t>(
        status | limitCode(o.limit1On.get() != 0, value, o.limit1.get()) << kStatusLimit1Shift);
    status = static_cast<std::uint16_t>(
        status | limitCode(o.limit2On.get() != 0, value, o.limit2.get()) << kStatusLimit2Shift);
    if (c.toggle) status |= kStatusToggle;
    o.value.set(value);
    o.status.set(status);
    o.underrange.set((status & kStatusUnderrange) != 0);
    o.overrange.set((status & kStatusOverrange) != 0);
    o.error.set((status & kStatusError) != 0);
    o.toggle.set(c.toggle);
    c.error = (status & kStatusError) != 0;
  }
  // Under- or overrange of a voltage input: generic + voltage, as long as a channel shows it.
  std::uint8_t reg = 0;
  for (const Channel& c : channels_) {
    if (c.script ? c.error : (c.objects.status.getUnsigned() & kStatusError) != 0) {
      reg |= error_register::kGeneric | error_register::kVoltage;
    }
  }
  errorRegister_.set(reg);
  nextConversion_ += pending * period;
}

}  // namespace ecsim::slavesim::devices
