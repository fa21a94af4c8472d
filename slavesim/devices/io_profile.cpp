#include "slavesim/devices/io_profile.hpp"

#include <algorithm>
#include <cctype>
#include <string>
#include <string_view>

#include "slavesim/coe/standard_objects.hpp"

namespace ecsim::slavesim::devices {
namespace {

// Application objects (CiA 301: manufacturer-specific 0x2000-0x5FFF, profile 0x6000-0x9FFF);
// 1-bit entries elsewhere are communication objects (0x1C32 sync errors, 0x1800 TxPDO toggles).
constexpr std::uint16_t kFirstApplicationIndex = 0x2000;
constexpr std::uint16_t kLastApplicationIndex = 0x9FFF;
constexpr unsigned kBitsPerByte = 8;
constexpr std::uint16_t kAnalogValueBits = 16;
// Byte-wide entries count as digital only up to this many channels (the most a
// DigitalOutputTerminal takes): more bytes are data (EL6001: 22 "Data In" bytes), not IO.
constexpr std::size_t kMaxByteChannels = 32;
constexpr std::size_t kMaxDigitalOutputChannels = 32;

struct Mapped {
  const coe::Entry* entry;
  std::uint16_t index;
  std::uint8_t subindex;
  std::uint16_t pdo;
};

bool application(std::uint16_t index) {
  return index >= kFirstApplicationIndex && index <= kLastApplicationIndex;
}

bool nameHas(const std::string& name, std::string_view word) {
  auto it = std::search(name.begin(), name.end(), word.begin(), word.end(), [](char a, char b) {
    return std::tolower(static_cast<unsigned char>(a)) == std::tolower(static_cast<unsigned char>(b));
  });
  return it != name.end();
}

// The application entries the PDOs assigned to the SMs of one direction map, in SM, PDO and
// mapping order.
std::vector<Mapped> mappedEntries(coe::ObjectDictionary& od, bool outputs) {
  std::vector<Mapped> out;
  const coe::Object* types = od.find(coe::kSmTypesIndex);
  if (types == nullptr) return out;
  const std::uint8_t want = outputs ? coe::kSmTypeOutputs : coe::kSmTypeInputs;
  for (const coe::Entry& t : types->entries) {
    if (t.subindex == 0 || t.value.empty() || t.value[0] != want) continue;
    for (std::uint16_t pdo : coe::assignedPdos(od, t.subindex - 1u)) {
      for (const coe::MappedObject& m : coe::mappedObjects(od, pdo)) {
        if (m.isPadding() || !application(m.index)) continue;
        const coe::Entry* e = od.findEntry(m.index, m.subindex);
        if (e != nullptr) out.push_back({e, m.index, m.subindex, pdo});
      }
    }
  }
  return out;
}

bool analogValue(const Mapped& m) {
  return m.entry->bitLength == kAnalogValueBits &&
         (m.entry->dataType == coe::data_type::kInteger16 || m.entry->dataType == coe::data_type::kUnsigned16);
}

}  // namespace

std::vector<DigitalChannel> digitalChannelsOf(coe::ObjectDictionary& od, bool outputs) {
  const std::vector<Mapped> entries = mappedEntries(od, outputs);
  std::vector<DigitalChannel> channels;
  for (const Mapped& m : entries) {
    if (m.entry->bitLength == 1) channels.push_back({ObjectRef(od, m.index, m.subindex), 0});
  }
  if (!channels.empty()) return channels;
  for (const Mapped& m : entries) {
    if (m.entry->bitLength != kBitsPerByte || coe::isSignedType(m.entry->dataType) ||
        nameHas(m.entry->name, "status")) {
      continue;
    }
    for (unsigned bit = 0; bit < kBitsPerByte; ++bit) {
      channels.push_back({ObjectRef(od, m.index, m.subindex), static_cast<std::uint8_t>(bit)});
    }
  }
  if (channels.size() > kMaxByteChannels) channels.clear();
  return channels;
}

std::vector<AnalogChannelObjects> analogInputChannelsOf(coe::ObjectDictionary& od) {
  const std::vector<Mapped> entries = mappedEntries(od, false);
  std::vector<AnalogChannelObjects> channels;
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const Mapped& m = entries[i];
    if (!analogValue(m) || !nameHas(m.entry->name, "value")) continue;
    AnalogChannelObjects c;
    c.value = ObjectRef(od, m.index, m.subindex);
    c.unsignedValue = m.entry->dataType == coe::data_type::kUnsigned16;
    // Old layout: a Status byte (or word) mapped before the value in the same PDO.
    for (std::size_t j = i; j-- > 0 && entries[j].pdo == m.pdo;) {
      const coe::Entry& s = *entries[j].entry;
      if (s.bitLength > 1 && nameHas(s.name, "status")) {
        c.status = ObjectRef(od, entries[j].index, entries[j].subindex);
        break;
      }
    }
    // MDP 5001: single status bits in the value's own object.
    if (const coe::Object* object = od.find(m.index); object != nullptr) {
      for (const coe::Entry& e : object->entries) {
        if (e.bitLength != 1) continue;
        ObjectRef bit(od, m.index, e.subindex);
        if (nameHas(e.name, "underrange")) {
          c.underrange = bit;
        } else if (nameHas(e.name, "overrange")) {
          c.overrange = bit;
        } else if (nameHas(e.name, "toggle")) {
          c.toggle = bit;
        } else if (nameHas(e.name, "error")) {
          c.error = bit;
        }
      }
    }
    channels.push_back(c);
  }
  return channels;
}

std::vector<AnalogOutputChannel> analogOutputChannelsOf(coe::ObjectDictionary& od) {
  std::vector<AnalogOutputChannel> channels;
  for (const Mapped& m : mappedEntries(od, true)) {
    if (!analogValue(m) || !(nameHas(m.entry->name, "value") || nameHas(m.entry->name, "output"))) {
      continue;
    }
    channels.push_back({ObjectRef(od, m.index, m.subindex), m.entry->dataType == coe::data_type::kUnsigned16});
  }
  return channels;
}

// ---- analog outputs ---------------------------------------------------------------------------

AnalogOutputTerminal::AnalogOutputTerminal(std::vector<AnalogOutputChannel> channels,
                                           double fullScaleVolts)
    : channels_(std::move(channels)), values_(channels_.size(), 0), fullScaleVolts_(fullScaleVolts) {}

std::int64_t AnalogOutputTerminal::raw(unsigned channel) const {
  return channel >= 1 && channel <= values_.size() ? values_[channel - 1] : 0;
}

double AnalogOutputTerminal::volts(unsigned channel) const {
  return static_cast<double>(raw(channel)) / kAnalogRawFullScale * fullScaleVolts_;
}

void AnalogOutputTerminal::step(coe::ObjectDictionary& /*od*/, AlState state, SimTime /*now*/) {
  if (!syncActive() || state != AlState::kOp) apply(state);
}

void AnalogOutputTerminal::sync(coe::ObjectDictionary& /*od*/, unsigned signal, AlState state,
                                SimTime /*now*/) {
  if (signal == 0 && syncActive()) apply(state);
}

void AnalogOutputTerminal::apply(AlState state) {
  for (std::size_t c = 0; c < channels_.size(); ++c) {
    values_[c] = state == AlState::kOp ? channels_[c].value.get() : 0;
  }
}

// ---- the device -------------------------------------------------------------------------------

template <typename F>
void IoDevice::each(F&& f) {
  // Outputs first: a loopback input of this device sees this step's outputs.
  Application* parts[] = {digitalOutputs.get(), analogOutputs.get(), digitalInputs.get(),
                          analogInputs.get()};
  for (Application* a : parts) {
    if (a == nullptr) continue;
    a->setSyncActive(syncActive());
    f(*a);
  }
}

void IoDevice::step(coe::ObjectDictionary& od, AlState state, SimTime now) {
  each([&](Application& a) { a.step(od, state, now); });
}

void IoDevice::sync(coe::ObjectDictionary& od, unsigned signal, AlState state, SimTime now) {
  each([&](Application& a) { a.sync(od, signal, state, now); });
}

Result<std::unique_ptr<IoDevice>> makeDigitalIo(coe::ObjectDictionary& od) {
  auto inputs = digitalChannelsOf(od, false);
  auto outputs = digitalChannelsOf(od, true);
  if (inputs.empty() && outputs.empty()) {
    return makeError(ErrorCode::kNotFound,
                     "profile io: the device's assigned PDOs map no digital entries (1-bit or "
                     "byte-wide unsigned entries of 0x2000-0x9FFF)");
  }
  auto device = std::make_unique<IoDevice>();
  if (!inputs.empty()) device->digitalInputs = DigitalInputTerminal::create(std::move(inputs));
  if (!outputs.empty()) {
    ECSIM_ASSIGN_OR_RETURN(device->digitalOutputs, DigitalOutputTerminal::create(std::move(outputs)));
  }
  return device;
}

Result<std::unique_ptr<IoDevice>> makeAnalogIo(coe::ObjectDictionary& od,
                                               const AnalogInputOptions& options) {
  auto inputs = analogInputChannelsOf(od);
  auto outputs = analogOutputChannelsOf(od);
  if (inputs.empty() && outputs.empty()) {
    return makeError(ErrorCode::kNotFound,
                     "profile analog: the device's assigned PDOs map no 16-bit INT/UINT entries "
                     "named like 'Value' (inputs) or 'Value'/'Output' (outputs)");
  }
  auto device = std::make_unique<IoDevice>();
  if (!inputs.empty()) {
    ECSIM_ASSIGN_OR_RETURN(device->analogInputs,
                           AnalogInputTerminal::create(std::move(inputs), od, options));
  }
  if (!outputs.empty()) {
    device->analogOutputs =
        std::make_unique<AnalogOutputTerminal>(std::move(outputs), options.fullScaleVolts);
  }
  return device;
}

IoProfileChoice ioProfileOf(coe::ObjectDictionary& od) {
  IoProfileChoice c;
  c.analog = !analogInputChannelsOf(od).empty() || !analogOutputChannelsOf(od).empty();
  const std::size_t outputs = digitalChannelsOf(od, true).size();
  c.digital = (!digitalChannelsOf(od, false).empty() || outputs > 0) &&
              outputs <= kMaxDigitalOutputChannels;
  return c;
}

namespace {

class OutputChannelSource final : public SignalSource {
 public:
  OutputChannelSource(ProcessDataDevice& device, unsigned channel)
      : device_(&device), channel_(channel) {}
  double value(SimTime /*t*/) const override {
    const DigitalOutputTerminal* outputs = digitalOutputsIn(device_->application());
    return outputs != nullptr && outputs->output(channel_) ? 1.0 : 0.0;
  }

 private:
  ProcessDataDevice* device_;
  unsigned channel_;
};

}  // namespace

Result<std::shared_ptr<const SignalSource>> outputChannelSource(ProcessDataDevice& device,
                                                                unsigned channel) {
  const DigitalOutputTerminal* outputs = digitalOutputsIn(device.application());
  if (outputs == nullptr) {
    return makeError(ErrorCode::kInvalidArgument, "has no digital outputs");
  }
  if (channel < 1 || channel > outputs->channels()) {
    return makeError(ErrorCode::kInvalidArgument,
                     "has output channels 1.." + std::to_string(outputs->channels()) +
                         ", not " + std::to_string(channel));
  }
  return std::shared_ptr<const SignalSource>(std::make_shared<OutputChannelSource>(device, channel));
}

DigitalInputTerminal* digitalInputsIn(Application* model) {
  if (auto* io = dynamic_cast<IoDevice*>(model)) return io->digitalInputs.get();
  return dynamic_cast<DigitalInputTerminal*>(model);
}

DigitalOutputTerminal* digitalOutputsIn(Application* model) {
  if (auto* io = dynamic_cast<IoDevice*>(model)) return io->digitalOutputs.get();
  return dynamic_cast<DigitalOutputTerminal*>(model);
}

AnalogInputTerminal* analogInputsIn(Application* model) {
  if (auto* io = dynamic_cast<IoDevice*>(model)) return io->analogInputs.get();
  return dynamic_cast<AnalogInputTerminal*>(model);
}

AnalogOutputTerminal* analogOutputsIn(Application* model) {
  if (auto* io = dynamic_cast<IoDevice*>(model)) return io->analogOutputs.get();
  return dynamic_cast<AnalogOutputTerminal*>(model);
}

}  // namespace ecsim::slavesim::devices
