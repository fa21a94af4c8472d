// IO terminal models (the ECS1008, ECS2008 and ECS3102 of examples/esi/ecsim_devices.xml).
// Each is an Application of the slave's ProcessDataDevice: it works on the dictionary entries
// the PDO binding copies to and from the SyncManager buffers, never on the ESC itself.
//
//   DigitalInputTerminal   channels = BOOL entries index:01..index:N (ECS1008: 0x6000:01-08), or
//                          any list of bits of entries (a vendor device's PDO entries, io_profile.hpp).
//                          A channel with a script is driven by it (on when the value is >=
//                          0.5); a channel without one keeps whatever value the dictionary holds
//                          (set by a topology <Input>, a test or SDO), so scripts are optional.
//   DigitalOutputTerminal  channels = BOOL entries index:01..index:N (ECS2008: 0x7000:01-08), or
//                          any list of bits of entries, at most 32.
//                          The physical outputs follow the dictionary in OP and are off (safe
//                          state) in every other AL state. Read them with output()/outputs(),
//                          be called on each change, or keep a log of changes.
//   AnalogInputTerminal    2 channels of the ECS3102 layout: per channel c (0-based) status
//                          UINT 0x6000+0x10c:01, value INT 0x6000+0x10c:11, settings
//                          0x8000+0x10c (:01 filter on, :02/:03 limit 1/2 on, :11/:12 limits,
//                          :13 filter time constant in ms). Scripts give volts; the ADC converts
//                          every conversion period: +/-full scale -> +/-32767, clamped to
//                          -32768..32767; status bit 0 underrange, 1 overrange, 2-3 and 4-5
//                          limit 1 and 2 (1 above, 2 below, 3 equal, 0 off), 6 error (under- or
//                          overrange), 15 toggles with each new value. A channel without a script
//                          is left as the dictionary holds it. The CiA 301 error register 0x1001
//                          (when present; error_register.hpp) is generic + voltage (0x05) while
//                          any channel's status shows the error bit, 0 otherwise; updated with
//                          each conversion. No emergencies.
// With SYNC0 running (Application::syncActive()) inputs are latched, conversions published and
// outputs applied at each SYNC0 pulse (sync()) instead of at every firmware step; outputs still
// go to their safe state at once when the slave leaves OP.
// Channels are numbered from 1, as their subindexes are.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "protocol/result.hpp"
#include "slavesim/devices/object_ref.hpp"
#include "slavesim/devices/signal.hpp"
#include "slavesim/process_data.hpp"

namespace ecsim::slavesim::devices {

// One digital channel: bit `bit` of a dictionary entry (0 for a BOOL entry, 0-7 for the bits
// of a byte-wide entry).
struct DigitalChannel {
  ObjectRef entry;
  std::uint8_t bit{0};

  bool get() const { return ((entry.getUnsigned() >> bit) & 1u) != 0; }
  void set(bool on) {
    const std::uint64_t mask = std::uint64_t{1} << bit;
    const std::uint64_t v = entry.getUnsigned();
    entry.set(static_cast<std::int64_t>(on ? v | mask : v & ~mask));
  }
};

class DigitalInputTerminal final : public Application {
 public:
  // kNotFound when index:01..index:channels are not all in the dictionary.
  static Result<std::unique_ptr<DigitalInputTerminal>> create(coe::ObjectDictionary& od,
                                                              std::uint16_t index = 0x6000,
                                                              unsigned channels = 8);
  // Over the given channels (channel n = channels[n - 1]).
  static std::unique_ptr<DigitalInputTerminal> create(std::vector<DigitalChannel> channels);

  unsigned channels() const { return static_cast<unsigned>(channels_.size()); }
  void setScript(unsigned channel, Signal signal);
  void setInput(unsigned channel, bool on) { setScript(channel, Signal::constant(on ? 1 : 0)); }
  void clearScript(unsigned channel);
  // The script of a channel (1-based), if it has one.
  const std::optional<Signal>& script(unsigned channel) const {
    return channels_.at(channel - 1).script;
  }
  // The input as the dictionary (and so the next process-data image) holds it.
  bool input(unsigned channel) const;

  void step(coe::ObjectDictionary& od, AlState state, SimTime now) override;
  void sync(coe::ObjectDictionary& od, unsigned signal, AlState state, SimTime now) override;

 private:
  void latch(SimTime now);
  struct Channel {
    DigitalChannel value;
    std::optional<Signal> script;
  };
  std::vector<Channel> channels_;
};

struct OutputChange {
  SimTime time{0};
  std::uint32_t outputs{0};  // bit n-1 = channel n
};

class DigitalOutputTerminal final : public Application {
 public:
  static Result<std::unique_ptr<DigitalOutputTerminal>> create(coe::ObjectDictionary& od,
                                                               std::uint16_t index = 0x7000,
                                                               unsigned channels = 8);
  // Over the given channels (at most 32).
  static Result<std::unique_ptr<DigitalOutputTerminal>> create(std::vector<DigitalChannel> channels);

  unsigned channels() const { return static_cast<unsigned>(channels_.size()); }
  bool output(unsigned channel) const;
  std::uint32_t outputs() const { return outputs_; }
  // Called with the time and the new outputs whenever they change.
  void setObserver(std::function<void(SimTime, std::uint32_t)> observer) {
    observer_ = std::move(observer);
  }
  // Keeps the first `capacity` changes (memory reserved now, none allocated while stepping).
  void enableLog(std::size_t capacity);
  const std::vector<OutputChange>& log() const { return log_; }
  // The log as CSV: "time_ns,outputs,out1,...,outN".
  Status writeLogCsv(const std::filesystem::path& path) const;

  void step(coe::ObjectDictionary& od, AlState state, SimTime now) override;
  void sync(coe::ObjectDictionary& od, unsigned signal, AlState state, SimTime now) override;

 private:
  void apply(AlState state, SimTime now);
  std::vector<DigitalChannel> channels_;
  std::uint32_t outputs_{0};
  std::function<void(SimTime, std::uint32_t)> observer_;
  std::vector<OutputChange> log_;
  std::size_t logCapacity_{0};
};

// Raw value of +full scale (analog inputs and outputs; -full scale is its negative).
inline constexpr std::int64_t kAnalogRawFullScale = 32767;

// The objects of one analog input channel of any layout; all but `value` optional.
struct AnalogChannelObjects {
  ObjectRef value;   // raw value, INT (-32768..32767) or UINT (0..32767 used)
  bool unsignedValue{false};
  ObjectRef status;  // status word or byte with the bits of the ECS3102 layout above
  // Single status bits (MDP 5001 layout: 0x60n0:01 Underrange, :02 Overrange, :07 Error,
  // :10 TxPDO Toggle).
  ObjectRef underrange, overrange, error, toggle;
  ObjectRef filterOn, limit1On, limit2On, limit1, limit2, filterMs;  // ECS3102 settings
};

struct AnalogInputOptions {
  double fullScaleVolts{10.0};
  SimTime conversionPeriod{kNsPerMs};
};

class AnalogInputTerminal final : public Application {
 public:
  static Result<std::unique_ptr<AnalogInputTerminal>> create(coe::ObjectDictionary& od,
                                                             unsigned channels = 2,
                                                             AnalogInputOptions options = {});
  // Over the given channels (a vendor device's entries, io_profile.hpp).
  static Result<std::unique_ptr<AnalogInputTerminal>> create(
      std::vector<AnalogChannelObjects> channels, coe::ObjectDictionary& od,
      AnalogInputOptions options = {});

  unsigned channels() const { return static_cast<unsigned>(channels_.size()); }
  // Volts as a function of time.
  void setScript(unsigned channel, Signal volts);
  void clearScript(unsigned channel);
  const std::optional<Signal>& script(unsigned channel) const {
    return channels_.at(channel - 1).script;
  }
  // The last converted (filtered) voltage of a scripted channel.
  double volts(unsigned channel) const;
  // Raw value for a voltage, as the ADC reports it (no filter).
  std::int16_t rawValue(double volts) const;

  void step(coe::ObjectDictionary& od, AlState state, SimTime now) override;
  void sync(coe::ObjectDictionary& od, unsigned signal, AlState state, SimTime now) override;

 private:
  void update(SimTime now);
  struct Channel {
    AnalogChannelObjects objects;
    std::optional<Signal> script;
    double filtered{0.0};
    bool primed{false};  // filter state initialised
    bool toggle{false};
    bool error{false};  // under- or overrange at the last conversion
  };
  void convert(Channel& c, SimTime t);

  AnalogInputOptions options_;
  std::vector<Channel> channels_;
  ObjectRef errorRegister_;  // 0x1001, when present
  SimTime nextConversion_{0};
  bool started_{false};
};

}  // namespace ecsim::slavesim::devices
