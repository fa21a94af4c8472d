// An SSI absolute encoder interface terminal: ecsim's ECS5001 (examples/esi/ecsim_encoders.xml)
// and the real Beckhoff EJ5002, whose ESI (revision 0x00110000, TxPDOs 0x1A00/0x1A01 "SSI
// Inputs Channel n") gives the layout both follow. Channel n (1-based) lives at
// 0x6000 + 0x10 * (n - 1):
//
//   :01 Data error     no valid data from the encoder: a broken data line, an encoder that
//                      does not answer the clock, or one without supply
//   :02 Frame error    the SSI frame did not have the expected form
//   :03 Power failure  the encoder's supply failed
//   :0F TxPDO State    the inputs are invalid (any error above)
//   :10 TxPDO Toggle   toggles with each new valid reading: it stands still while faulted
//   :11 Counter value  the encoder's position (Encoder::read, reported value in 32 bits);
//                      frozen at the last valid reading while an error is present
// (:04 Data mismatch and :0E Sync error are laid out but never set.) Entries a dictionary
// lacks (EJ5002 revision 0x00100000 keeps TxPDO state and toggle in 0x1800) are skipped.
//
// The shaft: each channel's encoder (encoder.hpp: resolution, single/multi-turn, noise) reads a
// shaft angle that is either held (setShaftAngle, the topology's drive.initialShaftAngle) or
// scripted in turns over time (signal.N, signal.hpp). An absolute multi-turn position survives
// a power cycle: the restart keeps the shaft angle, and a state file keeps channel 1's angle
// across restarts of the simulator (device_state.hpp), as for a drive.
//
// Faults (setFault, the scenario action `encoder-fault`) are conditions outside the terminal
// (wiring, encoder supply): they stay until cleared, through a power cycle of the terminal;
// when cleared, the next reading is valid again and the toggle resumes. A dictionary with the
// CiA 301 error register 0x1001 (error_register.hpp) shows them there too, at each reading:
// generic while any channel has a fault, voltage as well while an encoder supply has failed;
// 0 again at the first reading after the last fault is cleared. (The ECS5001 has no mailbox
// and so no 0x1001; the EJ5002's dictionary has none either. The terminal sends no
// emergencies.)
//
// The inputs are latched at each firmware step, or at SYNC0 while the ESC generates it: one new
// reading (and one toggle) per point in simulation time.
//
// The `encoder` profile for third-party counter terminals (issue #17: Beckhoff EL5101/EL5151 of
// the 2006 Beckhoff_EtherCAT_Terminals.xml, EJ5101 of Beckhoff_EJ5xxx.xml, ...) is the same
// terminal bound by createForCounters to the counter values its TxPDOs carry
// (counterValueChannels): channel n drives the n-th entry named "Counter value" (MDP 5001,
// 0x6000 + 0x10 * k : 0x11) and the n-th entry named "Value" of an unsigned type (the compact
// "Status, Value" PDOs: 0x3101:02 of the 2006 files, the EJ5101's 0x6000:02; the analog
// terminals' "Value" is INT and does not count). Of the status bits it sets only the channel
// object's "TxPDO State" (:0F) and "TxPDO Toggle" (:10), where entries of those names exist: the
// SSI bits :01-:03 mean other things in a counter terminal (latch valid, set counter done).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "protocol/result.hpp"
#include "slavesim/devices/device_state.hpp"
#include "slavesim/devices/encoder.hpp"
#include "slavesim/devices/object_ref.hpp"
#include "slavesim/devices/signal.hpp"
#include "slavesim/process_data.hpp"

namespace ecsim::slavesim::devices {

// Bit mask of what is wrong on a channel.
namespace encoder_fault {
inline constexpr std::uint8_t kNone = 0;
inline constexpr std::uint8_t kData = 1u << 0;   // no valid data (wire break)
inline constexpr std::uint8_t kFrame = 1u << 1;  // malformed SSI frame
inline constexpr std::uint8_t kPower = 1u << 2;  // encoder supply failed (no data either)
}  // namespace encoder_fault

struct EncoderTerminalOptions {
  EncoderParams encoder;
  double initialShaftAngle{0.0};    // rad, every channel, when there is no state file yet
  std::filesystem::path stateFile;  // channel 1's shaft angle, kept across restarts
  SimTime stateSaveInterval{100 * kNsPerMs};  // periodic saves while it turns; 0: none
};

class SsiEncoderTerminal final : public Application {
 public:
  static constexpr std::uint16_t kInputBase = 0x6000;
  static constexpr std::uint16_t kChannelStride = 0x10;
  static constexpr unsigned kMaxChannels = 8;

  // One channel per 0x6000 + 0x10 * n object with a counter value (:11); kNotFound when there
  // is none, kParse when the state file is not one.
  static Result<std::unique_ptr<SsiEncoderTerminal>> create(
      coe::ObjectDictionary& od, const EncoderTerminalOptions& options = {});
  // The encoder profile: one channel per counter value (counterValueChannels); kNotFound when
  // the TxPDOs carry none.
  static Result<std::unique_ptr<SsiEncoderTerminal>> createForCounters(
      coe::ObjectDictionary& od, const EncoderTerminalOptions& options = {});
  ~SsiEncoderTerminal() override;
  SsiEncoderTerminal(const SsiEncoderTerminal&) = delete;
  SsiEncoderTerminal& operator=(const SsiEncoderTerminal&) = delete;

  unsigned channels() const { return static_cast<unsigned>(channels_.size()); }
  const EncoderTerminalOptions& options() const { return options_; }

  // Channels are 1-based; calls for a channel the terminal does not have do nothing.
  void setShaftAngle(unsigned channel, double rad);
  double shaftAngle(unsigned channel) const;
  void setScript(unsigned channel, Signal turns);
  void clearScript(unsigned channel);
  const std::optional<Signal>& script(unsigned channel) const {
    return channels_.at(channel - 1).script;
  }
  void setFault(unsigned channel, std::uint8_t faults);
  std::uint8_t fault(unsigned channel) const;
  const Encoder& encoder(unsigned channel) const { return channels_.at(channel - 1).encoder; }
  // The 0x1001 value of the present faults (error_register.hpp), whether or not the dictionary
  // has the object; updated at each reading.
  std::uint8_t errorRegister() const { return errorRegisterValue_; }

  void step(coe::ObjectDictionary& od, AlState state, SimTime now) override;
  void sync(coe::ObjectDictionary& od, unsigned signal, AlState state, SimTime now) override;

  // Writes the state file now (no-op without one).
  Status saveState() const;

 private:
  struct Channel {
    explicit Channel(const EncoderParams& p) : encoder(p) {}
    Encoder encoder;
    ObjectRef dataError, frameError, powerFailure, txPdoState, txPdoToggle, counter;
    ObjectRef compactCounter;  // the same count in a compact "Value" entry (EJ5101 0x6000:02)
    std::optional<Signal> script;
    double angle{0.0};
    std::uint32_t reported{0};  // the counter value of the last reading
    std::uint8_t faults{encoder_fault::kNone};
    bool toggle{false};
  };
  explicit SsiEncoderTerminal(const EncoderTerminalOptions& options) : options_(options) {}
  // The shaft angle at power-up (state file, else the options'); opens the state file.
  Result<double> powerUpAngle();
  Channel& addChannel(double angle);
  void latch(SimTime now);

  EncoderTerminalOptions options_;
  std::vector<Channel> channels_;
  ObjectRef errorRegister_;  // 0x1001, when present
  std::uint8_t errorRegisterValue_{0};
  SimTime lastLatch_{0};
  std::optional<PeriodicStateSaver> stateSaver_;
  bool latched_{false};
};

// A counter value a TxPDO mapping object (0x1A00-0x1BFF) of `od` maps.
struct CounterEntry {
  std::uint16_t index{0};
  std::uint8_t subindex{0};
};
// The counter channels of a dictionary (the encoder profile's rule above): per channel, its
// "Counter value" entry and its compact "Value" entry, either absent (index 0). Empty when the
// TxPDOs map no counter value.
struct CounterChannel {
  CounterEntry counter, compact;
};
std::vector<CounterChannel> counterValueChannels(const coe::ObjectDictionary& od);

}  // namespace ecsim::slavesim::devices
