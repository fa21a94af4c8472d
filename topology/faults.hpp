// Fault injection on a simulated network: the network-side actions of scenarios
// (docs/scenarios.md) and of `ecsim ctl`. An action is a verb with key=value arguments, the same
// in a scenario file (<Action do="link-down" cable="drives"/>) and on a control line
// ("link-down cable=drives"). FaultInjector applies them to a Network:
//
//   loss rate=R [cable=C]           frames lost (bad FCS) with probability R where cable C
//                                   (default: the master's) enters its downstream slave
//   corrupt cable=C [count=N]       the next N frames (default 1) arrive corrupted there
//   delay cable=C ns=N durationMs=T the cable takes N ns longer, each way, for T ms
//   link-down|link-up cable=C | slave=S port=P
//   power-off|power-on slave=S      off: a broken link at the neighbours' ports; on: power-on
//                                   reset (registers, AL state, dictionary values, device
//                                   model; EEPROM and encoder position kept)
//   detach|attach group=G           a hot-connect group (topology <Group>): its slaves off,
//                                   the junction's port without link / on again
//   al-error slave=S code=X [state=SAFEOP]   the firmware raises a local error
//   eeprom-checksum slave=S         corrupts the SII checksum (word 7) and power-cycles
//   mailbox-silent slave=S [on=0|1] the mailbox server stops (or resumes) answering
//   sdo-abort slave=S index=X [sub=N] code=X  SDO requests for that object are aborted
//   sdo-ok slave=S                  removes the SDO aborts
//   drive-fault slave=S [code=X]    CiA 402 drive fault (default 0x2310 overcurrent)
//   encoder-fault slave=S [kind=data|frame|power] [on=0|1] [channel=N]
//                                   an encoder terminal's fault (status bits, position
//                                   frozen; on=0 clears it); on a drive: fault 0x7305
//   input slave=S channel=N signal=TEXT    scripted input (slavesim/devices/signal.hpp); on an
//                                   encoder terminal the shaft position in turns
//   latch slave=S unit=0|1 level=0|1      the ESC's DC latch input LATCH0/1 goes to the level
//                                   now (an edge is time-stamped, slavesim/esc_latch.cpp)
//
//   pause-master durationMs=T       scenarios only: the runner's master sends nothing for T ms
//
// A delay's and pause-master's duration is durationMs=T or, in a scenario of our master (whose
// cycle time is known), durationCycles=N; exactly one of them.
//
// Every action is parsed into a typed Fault (parseFault) before it runs: when a scenario is
// loaded, when a control line arrives. Every argument has a range and a value outside it is
// refused with the range in the message ("loss: rate=nan is not a number in [0, 1]"); NaN,
// infinities and integers that do not fit are refused, never truncated. rate in [0, 1]; ns in
// [0, kMaxDelaySpikeNs] (1 s); durationMs in [0, kMaxFaultDurationMs] (one day),
// durationCycles as long at most; count in [0, kMaxCorruptCount]; codes and indexes within
// their wire width (al-error/drive-fault code and sdo-abort index 16 bits, sdo-abort code 32
// bits, sub 8 bits); port 0..3; on 0..1; channel 1..kMaxFaultChannel (when applied: 1..the
// device's channels); unit and level 0..1; state and kind by name. Slaves and cables are
// looked up when the fault is applied (a scenario's names are checked against its topology at
// load: scenario/scenario.hpp, checkTopologyNames).
// Clearing: a fault's zero removes it. "loss rate=0" ends the loss, "corrupt count=0" drops
// the corruptions still pending at that cable, "delay ns=0" removes the cable's delay spikes;
// the others have their opposite verb or on=0 (link-up, power-on, mailbox-ok, sdo-ok,
// encoder-fault on=0). At most kMaxDelaySpikes spikes are active at once.
//
// Random decisions come from a SplitMix64 generator seeded by the caller: the same seed and the
// same frames give the same faults.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "protocol/al_status.hpp"
#include "protocol/result.hpp"
#include "protocol/time.hpp"
#include "slavesim/devices/signal.hpp"
#include "topology/network_builder.hpp"
#include "topology/segment.hpp"

namespace ecsim::topology {

// Steele, Lea, Flood: "Fast splittable pseudorandom number generators" (SplitMix64).
class SplitMix64 {
 public:
  explicit SplitMix64(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  // Uniform in [0, 1) from the top 53 bits.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

 private:
  std::uint64_t state_;
};

constexpr std::uint64_t kMaxDelaySpikeNs = 1'000'000'000;  // 1 s per spike, each way
constexpr std::uint64_t kMaxFaultDurationMs = 86'400'000;  // one day
constexpr std::uint64_t kMaxCorruptCount = 1'000'000;      // pending, per cable end
constexpr std::size_t kMaxDelaySpikes = 64;                // active at once
constexpr std::uint64_t kMaxFaultChannel = 255;            // before the device is known

struct FaultAction {
  std::string verb;
  std::map<std::string, std::string, std::less<>> args;
  std::string where;  // "file.xml, line 12" or "control": prefixes error messages

  std::optional<std::string_view> get(std::string_view key) const;
  Result<std::string_view> require(std::string_view key) const;
  // An integer argument (decimal or 0x hex) in [lo, hi]; the error names the range (in hex
  // when the value was written in hex).
  Result<std::uint64_t> number(std::string_view key, std::uint64_t lo, std::uint64_t hi) const;
  // The same, `fallback` when the argument is absent.
  Result<std::uint64_t> number(std::string_view key, std::uint64_t lo, std::uint64_t hi,
                               std::uint64_t fallback) const;
  // A finite real argument in [lo, hi].
  Result<double> real(std::string_view key, double lo, double hi) const;
  // A duration in milliseconds (real, [0, kMaxFaultDurationMs]) as nanoseconds.
  Result<SimTime> millis(std::string_view key) const;
  Error error(std::string_view message) const;
  // "link-down cable=drives" (arguments in key order).
  std::string text() const;
};

// Where an action is written: a scenario takes pause-master and durationCycles (the runner's
// master and cycle), a control line (ecsim serve) does not.
enum class FaultScope : std::uint8_t { kControl, kScenario };

// "verb key=value key="quoted value" ..." (a control line; a final CR is ignored). Refused,
// naming the column: a byte that is not printable, an unterminated quote, an empty or repeated
// argument name; and what checkFaultArguments refuses.
Result<FaultAction> parseFaultAction(std::string_view line);
// An unknown verb, or an argument the verb does not take, is an error naming the closest valid
// name (or listing the valid ones).
Status checkFaultArguments(const FaultAction& action, FaultScope scope = FaultScope::kControl);
// The verbs of `scope`; the arguments a verb takes there (empty for an unknown verb). One table
// (topology/fault_parse.cpp) answers both, for scenarios, control lines and `ecsim ctl help`.
std::vector<std::string_view> faultVerbs(FaultScope scope = FaultScope::kControl);
std::vector<std::string_view> faultArguments(std::string_view verb,
                                             FaultScope scope = FaultScope::kControl);
// Decimal or 0x-prefixed hexadecimal.
std::optional<std::uint64_t> parseNumber(std::string_view text);

// ---- Typed faults ---------------------------------------------------------------------------
// Where a wire fault acts: a named cable (its downstream end), or a slave's port.
struct FaultPlace {
  std::string cable;  // empty: slave and port
  std::string slave;
  unsigned port{0};
};
struct LinkDown {
  FaultPlace at;
};
struct LinkUp {
  FaultPlace at;
};
struct Loss {
  std::string cable;  // empty: the master's
  double rate{0};
};
struct Corrupt {
  FaultPlace at;
  std::uint64_t count{1};
};
struct Delay {
  FaultPlace at;
  SimTime extra{0};  // each way
  SimTime duration{0};
};
struct PowerOff {
  std::string slave;
};
struct PowerOn {
  std::string slave;
};
struct PowerCycle {
  std::string slave;
};
// A hot-connect group (topology <Group>) detached (its slaves lose power, the junction's port
// its link) or attached again (power on: INIT, station address 0, EEPROM reloaded).
struct HotConnect {
  std::string group;
  bool attach{true};
};
struct AlError {
  std::string slave;
  std::uint16_t code{0};
  std::optional<AlState> state;  // none: the slave's state, at most SAFEOP
};
struct EepromChecksum {
  std::string slave;
};
struct MailboxSilent {
  std::string slave;
  bool silent{true};  // false: answering again (mailbox-ok)
};
struct SdoAbortFault {
  std::string slave;
  std::uint16_t index{0};
  std::optional<std::uint8_t> subindex;  // none: every subindex
  std::uint32_t code{0x06020000};        // object does not exist
};
struct SdoOk {
  std::string slave;
};
struct DriveFault {
  std::string slave;
  std::uint16_t code{0x2310};  // overcurrent
};
struct EncoderFault {
  enum class Kind : std::uint8_t { kData, kFrame, kPower };
  std::string slave;
  Kind kind{Kind::kData};
  bool on{true};
  unsigned channel{1};
};
struct Input {
  std::string slave;
  unsigned channel{1};
  std::string text;  // as written
  slavesim::devices::Signal signal;
};
struct Latch {
  std::string slave;
  unsigned unit{0};
  bool level{false};
};
struct PauseMaster {  // scenarios: carried out by the runner, not by FaultInjector
  SimTime duration{0};
};
using Fault = std::variant<LinkDown, LinkUp, Loss, Corrupt, Delay, PowerOff, PowerOn, PowerCycle,
                           HotConnect, AlError, EepromChecksum, MailboxSilent, SdoAbortFault, SdoOk,
                           DriveFault, EncoderFault, Input, Latch, PauseMaster>;

// What parseFault needs besides the action: where it is written and, for durationCycles, the
// cycle time of the master that counts the cycles (0: none known, durationCycles refused).
struct FaultContext {
  FaultScope scope{FaultScope::kControl};
  SimTime cycleTime{0};
  // Where a relative file of an argument (`signal="csv file=trace.csv"`) is: a scenario's
  // folder; empty (the working directory) for a control line.
  std::filesystem::path baseDir{};
};
// Checks and converts every argument (checkFaultArguments, the ranges above, names of states
// and kinds with the closest valid one, the input signal's text); errors begin with the
// action's `where` and verb.
Result<Fault> parseFault(const FaultAction& action, const FaultContext& context = {});
// A control line: parseFaultAction, then parseFault.
Result<Fault> parseFaultLine(std::string_view line);
// The verb of a fault, and the fault as an action line ("delay cable=drives ns=5000
// durationMs=20"): what was parsed, for logs; parseFaultLine reads it back to the same fault
// (a duration given in cycles is written in ms).
std::string_view verbOf(const Fault& fault);
std::string describe(const Fault& fault);
std::string_view toString(EncoderFault::Kind kind);

class FaultInjector final : public WireFaults {
 public:
  // Installs itself as the segment's wire faults; removes itself when destroyed.
  FaultInjector(Network& network, std::uint64_t seed);
  ~FaultInjector() override;
  FaultInjector(const FaultInjector&) = delete;
  FaultInjector& operator=(const FaultInjector&) = delete;

  static bool handles(std::string_view verb);
  // Applies a network-side fault at simulation time `now`; returns what was done in words. A
  // slave or cable the network does not have, or a channel or unit the slave's device does
  // not have, is an error (naming the closest name); pause-master is not the network's.
  // Errors begin with `where` ("s.xml, line 7" or "control") and the verb.
  Result<std::string> apply(const Fault& fault, SimTime now, std::string_view where = {});

  bool corrupts(std::size_t slave, unsigned port, SimTime time) override;
  SimTime extraDelay(std::size_t slave, unsigned port, SimTime time) override;

  Result<std::size_t> slaveIndex(std::string_view name) const;
  std::uint64_t framesCorrupted() const { return framesCorrupted_; }

 private:
  struct End {
    std::size_t slave{0};
    unsigned port{0};
    auto operator<=>(const End&) const = default;
  };
  struct Spike {
    End end;
    SimTime extra{0};
    SimTime until{0};
  };
  Result<End> cableEnd(const FaultPlace& at) const;
  Result<std::size_t> slaveNamed(std::string_view name) const;  // errors "no slave named ..."
  // One overload per fault (faults.cpp).
  Result<std::string> on(const LinkDown& f, SimTime now);
  Result<std::string> on(const LinkUp& f, SimTime now);
  Result<std::string> on(const Loss& f, SimTime now);
  Result<std::string> on(const Corrupt& f, SimTime now);
  Result<std::string> on(const Delay& f, SimTime now);
  Result<std::string> on(const PowerOff& f, SimTime now);
  Result<std::string> on(const PowerOn& f, SimTime now);
  Result<std::string> on(const PowerCycle& f, SimTime now);
  Result<std::string> on(const HotConnect& f, SimTime now);
  Result<std::string> on(const AlError& f, SimTime now);
  Result<std::string> on(const EepromChecksum& f, SimTime now);
  Result<std::string> on(const MailboxSilent& f, SimTime now);
  Result<std::string> on(const SdoAbortFault& f, SimTime now);
  Result<std::string> on(const SdoOk& f, SimTime now);
  Result<std::string> on(const DriveFault& f, SimTime now);
  Result<std::string> on(const EncoderFault& f, SimTime now);
  Result<std::string> on(const Input& f, SimTime now);
  Result<std::string> on(const Latch& f, SimTime now);
  Result<std::string> on(const PauseMaster& f, SimTime now);
  Result<std::string> setLink(const FaultPlace& at, bool up);
  // The other end of the cable at `end`, if there is one (the master cable has none).
  std::optional<End> peer(End end) const;
  void setCable(End end, bool up);
  Result<std::string> powerOff(std::size_t s);
  Result<std::string> powerOn(std::size_t s, SimTime now);

  Network& network_;
  Segment& segment_;
  SplitMix64 random_;
  std::map<End, double> lossRate_;
  std::map<End, std::uint64_t> corruptCount_;
  std::vector<Spike> spikes_;
  std::set<End> cablesDown_;  // by link-down, kept down through power cycles
  std::set<std::size_t> poweredOff_;
  std::uint64_t framesCorrupted_{0};
  bool anyWireFault_{false};
  void refreshAny() {
    anyWireFault_ = !lossRate_.empty() || !corruptCount_.empty() || !spikes_.empty();
  }
};

}  // namespace ecsim::topology
