// Behaviour profiles for third-party IO devices served from their vendor's ESI (issue #17):
// the IO terminal models of io_terminals.hpp bound to the device's own PDO entries, found in
// the PDOs its default assignment (0x1C1n) maps, SM by SM and entry by entry in mapping order.
//
//   io        digital inputs  = the 1-bit entries of the TxPDOs (channel 1, 2, ... in that order),
//             digital outputs = the 1-bit entries of the RxPDOs; only application objects
//             (0x2000-0x9FFF: the old Beckhoff layouts 0x3101/0x3001 and the MDP 0x6000/0x7000
//             alike). A device with no 1-bit entries in a direction uses its byte-wide unsigned
//             entries there (SMC EX250-SEN1-X156: UINT8 Byte0..3 at 0x6000/0x7000), 8 channels
//             per byte, bit 0 first, leaving out entries named like "Status".
//   analog    analog inputs   = the 16-bit INT/UINT TxPDO entries named like "Value"; status
//             from a "Status" entry of 8 or 16 bits mapped in the same PDO (the old Beckhoff
//             layout: bits as the ECS3102's, io_terminals.hpp), or the 1-bit entries of the
//             value's own object named Underrange, Overrange, Error and TxPDO Toggle (MDP 5001:
//             0x60n0:01, :02, :07, :10 beside the value at :11);
//             analog outputs  = the 16-bit INT/UINT RxPDO entries named like "Value" or
//             "Output" (EL4xxx, EL47xx), visible as raw values and volts.
//             Scripts give volts; +/-analog.fullScaleVolts (default 10) is +/-32767 for INT
//             values and 0..32767 for UINT values: the ESI says nothing ecsim reads about a
//             channel's range (the 2006 files' DScale="+/-10" is not read), so a 0-20 mA input
//             is scripted in mA with analog.fullScaleVolts=20.
//   loopback  io whose input channel n follows output channel n of another slave
//             (loopback.from, bound by the topology builder).
// The models are IoDevice: one Application holding the terminals a device has; outputs are
// applied before inputs are latched at each step.
#pragma once

#include <memory>
#include <vector>

#include "protocol/result.hpp"
#include "slavesim/devices/io_terminals.hpp"
#include "slavesim/process_data.hpp"

namespace ecsim::slavesim::devices {

// The device's digital channels in one direction, as described above.
std::vector<DigitalChannel> digitalChannelsOf(coe::ObjectDictionary& od, bool outputs);
std::vector<AnalogChannelObjects> analogInputChannelsOf(coe::ObjectDictionary& od);

struct AnalogOutputChannel {
  ObjectRef value;
  bool unsignedValue{false};
};
std::vector<AnalogOutputChannel> analogOutputChannelsOf(coe::ObjectDictionary& od);

// Analog outputs: the value the device drives, as the dictionary holds it in OP; 0 (the safe
// state) in every other AL state.
class AnalogOutputTerminal final : public Application {
 public:
  AnalogOutputTerminal(std::vector<AnalogOutputChannel> channels, double fullScaleVolts);

  unsigned channels() const { return static_cast<unsigned>(channels_.size()); }
  std::int64_t raw(unsigned channel) const;
  double volts(unsigned channel) const;

  void step(coe::ObjectDictionary& od, AlState state, SimTime now) override;
  void sync(coe::ObjectDictionary& od, unsigned signal, AlState state, SimTime now) override;

 private:
  void apply(AlState state);
  std::vector<AnalogOutputChannel> channels_;
  std::vector<std::int64_t> values_;
  double fullScaleVolts_;
};

// The terminals of one device (any of them may be absent).
class IoDevice final : public Application {
 public:
  std::unique_ptr<DigitalInputTerminal> digitalInputs;
  std::unique_ptr<DigitalOutputTerminal> digitalOutputs;
  std::unique_ptr<AnalogInputTerminal> analogInputs;
  std::unique_ptr<AnalogOutputTerminal> analogOutputs;

  void step(coe::ObjectDictionary& od, AlState state, SimTime now) override;
  void sync(coe::ObjectDictionary& od, unsigned signal, AlState state, SimTime now) override;

 private:
  template <typename F>
  void each(F&& f);
};

// The digital (io) or analog profile over the device's entries; kNotFound naming what the
// device lacks when it has none of the profile's entries.
Result<std::unique_ptr<IoDevice>> makeDigitalIo(coe::ObjectDictionary& od);
Result<std::unique_ptr<IoDevice>> makeAnalogIo(coe::ObjectDictionary& od,
                                               const AnalogInputOptions& options);

// Which of the two a device without another model gets: analog when it has analog values,
// io when it has digital entries; false/false: neither (a coupler).
struct IoProfileChoice {
  bool analog{false};
  bool digital{false};
};
IoProfileChoice ioProfileOf(coe::ObjectDictionary& od);

// Output channel `channel` of the digital outputs of `device` (looked up at each read, so a
// power cycle re-creating the model is followed); kInvalidArgument when the device has no
// digital outputs or not that channel.
Result<std::shared_ptr<const SignalSource>> outputChannelSource(ProcessDataDevice& device,
                                                                unsigned channel);

// The terminals of a model, whether it is the terminal itself or an IoDevice holding it.
DigitalInputTerminal* digitalInputsIn(Application* model);
DigitalOutputTerminal* digitalOutputsIn(Application* model);
AnalogInputTerminal* analogInputsIn(Application* model);
AnalogOutputTerminal* analogOutputsIn(Application* model);

}  // namespace ecsim::slavesim::devices
