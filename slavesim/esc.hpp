// A simulated EtherCAT Slave Controller: the register file and process RAM, datagram
// processing with the working-counter rules, FMMUs, SyncManagers (mailbox and 3-buffer), the
// SII EEPROM interface, error counters and the DC registers the ECAT side sees.
//
// The ESC is driven from two sides, as the hardware is:
//  - the ECAT side: processDatagram() for each datagram of a frame passing through (called by
//    topology/Segment, which knows the addressing position and timing);
//  - the PDI side: the slave's firmware (ESM, mailbox server, device model) reads outputs,
//    writes inputs, serves the mailbox and sets AL status through the pdi*() functions.
// It never allocates after construction and never reads a clock: times are passed in.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "protocol/bytes.hpp"
#include "protocol/esc_blocks.hpp"
#include "protocol/frame.hpp"
#include "protocol/registers.hpp"
#include "protocol/sii.hpp"
#include "protocol/time.hpp"
#include "slavesim/dc_clock.hpp"
#include "slavesim/esc_register_table.hpp"
#include "slavesim/esc_type.hpp"

namespace ecsim::slavesim {

struct EscCounters {
  // framesSeen: first, on a cache line every frame touches. A network letting frames pass
  // without a visit adds them later (topology::Segment::framesSeen counts them all).
  std::uint64_t framesSeen{0};
  std::uint64_t datagramsAddressed{0};
  std::uint64_t mailboxWrites{0};
  std::uint64_t mailboxWritesRejected{0};
  std::uint64_t outOfRangeAccesses{0};
};

// What the ECAT side did that the firmware must react to, collected while a frame passes and
// handed over with takeEvents() after it (the firmware runs "between frames", as on hardware).
struct EscEvents {
  bool alControlWritten{false};
  bool mailboxReceived{false};  // SM0-type mailbox became full
  bool mailboxRead{false};      // SM1-type mailbox was emptied by the master
  bool smConfigChanged{false};
  bool outputsWritten{false};  // a buffered write SM completed a buffer
  bool eepromReloaded{false};
  bool dcLatched{false};
  bool dlControlWritten{false};  // port loop settings may have changed
};

// Told by an ESC when something changes that a network keeps an index of, so that a frame
// passes and the firmware runs only where there is something to do (topology::Segment). Each
// call carries the id the ESC was given with setObserver().
class EscObserver {
 public:
  // The ESC holds events for its firmware again (none were pending since the last
  // takeEvents()).
  virtual void escEventsRaised(std::uint32_t id) = 0;
  // Its station address, alias or alias enable changed (refreshAddressing()).
  virtual void escAddressingChanged(std::uint32_t id) = 0;
  // What it ORs into the IRQ field of a datagram header passing it changed: `irq` now (kept
  // current between frames), or, with `followsSm`, whatever its SyncManagers' status gives
  // when the header passes (headerIrq() asks them; SM events in the ECAT event mask).
  virtual void escIrqChanged(std::uint32_t id, std::uint16_t irq, bool followsSm) = 0;

 protected:
  ~EscObserver() = default;
};

class Esc {
 public:
  Esc(const EscType& type, std::vector<std::uint8_t> siiImage);

  const EscType& type() const { return type_; }

  // ---- ECAT side ------------------------------------------------------------------------
  // Processes one datagram at this ESC. `time` is the simulation (global) time at which the
  // datagram's first byte passes the processing unit; the ESC reads its own local clock from
  // it. Modifies data, ADP and WKC in place.
  void processDatagram(DatagramView datagram, SimTime time);
  // What the header of a datagram passing now gets ORed into its IRQ field (the masked ECAT
  // event request), as processDatagram() does for every datagram, addressed or not.
  std::uint16_t headerIrq() {
    if (smEventMask_ != 0) refreshEcatEvents();
    return ecatIrq_;
  }
  // The observer told of events, addressing and IRQ changes (nullptr: none). It is told at
  // once of what holds now.
  void setObserver(EscObserver* observer, std::uint32_t id);
  // A configured-address datagram (FPRD/FPWR/FPRW) with this ADP is addressed to this ESC: its
  // station address, or its alias while DL control enables it (0x0103 bit 0). Anything else
  // such a datagram meets here is only its header passing (headerIrq()).
  // Asks the cache for the per-frame state (the hot group below, up to the memory's address).
  // A network calls it for the ESCs some way down the route, then prefetchMemory() for those
  // nearer, so that a long line's ESCs, evicted between frames, are fetched together and not
  // one miss after the other.
  void prefetchFrameState() const {
    const auto* hot = reinterpret_cast<const char*>(&dc_);
    for (std::size_t at = 0; at < kHotBytes; at += 64) __builtin_prefetch(hot + at);
  }
  // The register or RAM line at `address` (a physical datagram's ADO). Reads the memory's
  // address, in the hot group: call it once prefetchFrameState() had time to bring that in.
  void prefetchMemory(std::uint32_t address) const {
    if (address < memory_.size()) __builtin_prefetch(memory_.data() + address);
  }
  // While no frame is there (a server waiting): asks for what a frame's pass reads first, the
  // hot group, the memory line at `address` (the last frame's first physical ADO), the active
  // FMMUs and the process RAM and buffers they lead to (esc_fmmu.cpp).
  void prefetchForNextFrame(std::uint32_t address) const;
  // Read from copies kept beside the per-frame state (refreshAddressing()), so that a frame
  // passing ESCs it does not address touches none of their memory.
  std::uint16_t stationAddress() const { return station_; }
  bool aliasEnabled() const { return aliasOn_; }
  std::uint16_t stationAlias() const { return alias_; }
  // Working counter increment this ESC gave the last processed datagram (for tests/tracing).
  std::uint16_t lastWkcIncrement() const { return lastWkcIncrement_; }
  // A new frame starts passing (resets per-frame state: the SyncManagers' end-address rule).
  // `invalid`: the frame reached this ESC corrupted (bad FCS). The processing unit then runs
  // in "invalid frame" mode (ESC datasheet section I §14.1): RAM writes outside SyncManagers
  // take effect as the frame passes, register writes, SyncManager buffer changes and events
  // are discarded, and the frame counts in 0x030C.
  void beginFrame(bool invalid = false) {
    ++counters_.framesSeen;
    beginFrameUncounted(invalid);
  }
  // As beginFrame, but the frame is counted in framesSeen by addFramesSeen() later (a
  // network that lets frames pass ESCs they do not concern without visiting them).
  void beginFrameUncounted(bool invalid = false) {
    smEndAccessed_ = 0;
    invalidFrame_ = invalid;
    if (invalid) countProcessingUnitError();
  }
  // True while the frame being processed is invalid (see beginFrame); units that raise
  // events or change register state on an access must do nothing then.
  bool processingInvalidFrame() const { return invalidFrame_; }

  // DC: a write to 0x0900 arms the receive-time latch; when the frame has passed, the topology
  // hands over the simulation times its first bit arrived at each port (mask: ports it
  // arrived at) and their local-clock values are stored in 0x0900-0x090F.
  bool receiveTimeLatchArmed() const { return latchArmed_; }
  void completeReceiveTimeLatch(const std::array<SimTime, 4>& times, std::uint8_t portMask);

  // Which distributed-clock unit this ESC has (ESC datasheet section I §9.1: full DC,
  // propagation-delay measurement only — the port receive times, as in an EK1100 — or none).
  // Registers of a missing unit answer without a working-counter increment.
  enum class DcUnit : std::uint8_t { kFull, kDelayOnly, kNone };
  void setDcUnit(DcUnit unit) { dcUnit_ = unit; }
  DcUnit dcUnit() const { return dcUnit_; }

  // The ESC's local clock (oscillator offset and drift, and the DC control loop).
  DcClock& dcClock() { return dc_; }
  const DcClock& dcClock() const { return dc_; }
  // System time (0x0910 as a read would give it) at simulation time `time`.
  SimTime systemTime(SimTime time) const;
  // True while the sync unit generates SYNC0 (signal 0) or SYNC1 (signal 1) pulses: cyclic
  // unit assigned to ECAT or PDI, activation 0x0981 bit 0 and the signal's enable bit set.
  bool syncActive(unsigned signal) const {
    const std::uint8_t act = reg8(reg::kDcActivation.address);
    return dcUnit_ == DcUnit::kFull && (act & 0x01) != 0 &&
           (act & (signal == 0 ? 0x02 : 0x04)) != 0;
  }

  // ---- PDI side (firmware) --------------------------------------------------------------
  std::uint16_t alControl() const { return reg16(reg::kAlControl.address); }
  std::uint16_t alStatus() const { return reg16(reg::kAlStatus.address); }
  void pdiSetAlStatus(std::uint16_t status, std::uint16_t code);

  // Mailbox: the SM in mailbox mode with ECAT write direction (normally SM0) and with ECAT read
  // direction (normally SM1). Returns false when there is none or it is not enabled.
  bool pdiMailboxAvailable() const;
  // Copies a received mailbox into out (size = SM length) and frees SM0. Returns bytes copied
  // or 0 when SM0 holds nothing.
  std::size_t pdiMailboxReceive(Bytes out);
  // Puts a response into SM1 if it is empty; returns false when SM1 is still full.
  bool pdiMailboxSend(ConstBytes data);
  bool pdiMailboxResponsePending() const;
  // Repeat request handling: re-present the last mailbox response.
  void pdiMailboxRepeat();

  // Process data: the newest complete buffer of an ECAT-write SM, and write a complete buffer
  // into an ECAT-read SM. Returns an empty span / false when the SM is not a buffered SM.
  // pdiOutputs() only looks (tests, inspection); the firmware reads with pdiReadOutputs(),
  // which is a PDI read of the whole buffer: for a 3-buffer SM it clears "interrupt write" and
  // sets "interrupt read" in the SM status 0x0805+8n, the SM's ECAT event (section II 0x0805).
  ConstBytes pdiOutputs(unsigned sm) const;
  ConstBytes pdiReadOutputs(unsigned sm);
  // 1-buffer (mailbox-mode) process-data output SM: the firmware has taken the buffer, so the
  // master may write the next one (a completed PDI read: "interrupt read", as for a mailbox).
  void pdiReleaseBuffer(unsigned sm);
  // True once the master completed at least one buffer of this output SM since it was enabled.
  bool pdiOutputsReceived(unsigned sm) const { return sm < sm_.size() && sm_[sm].hasLatest; }
  bool hasEvents() const {
    return events_.alControlWritten || events_.mailboxReceived || events_.mailboxRead ||
           events_.smConfigChanged || events_.outputsWritten || events_.eepromReloaded ||
           events_.dcLatched || events_.dlControlWritten;
  }
  bool pdiWriteInputs(unsigned sm, ConstBytes data);

  // SM configuration as the master programmed it: the channel as protocol/esc_blocks.hpp
  // decodes it, plus whether it works (enabled, not deactivated by the PDI, inside memory).
  struct SmConfig : SyncManagerBlock {
    bool enabled{false};
  };
  SmConfig smConfig(unsigned sm) const;
  using FmmuConfig = FmmuBlock;
  FmmuConfig fmmuConfig(unsigned n) const;

  const EscEvents& peekEvents() const { return events_; }
  EscEvents takeEvents() {
    EscEvents e = events_;
    events_ = {};
    eventsNoted_ = false;
    return e;
  }
  void addFramesSeen(std::uint64_t n) { counters_.framesSeen += n; }

  // Typed register access through the register map (protocol/registers.hpp): the width comes
  // from the register, never from the caller. Little-endian as on the wire.
  template <typename T>
  T read(reg::Reg<T> r) const {
    std::uint64_t v = 0;
    for (unsigned i = 0; i < sizeof(T); ++i)
      v |= static_cast<std::uint64_t>(memory_[r.address + i]) << (8 * i);
    return static_cast<T>(v);
  }
  // PDI-side write of a whole register (no ECAT write masks; FMMU/SM caches follow).
  template <typename T>
  void pdiWrite(reg::Reg<T> r, T value) {
    const auto v = static_cast<std::uint64_t>(value);
    for (unsigned i = 0; i < sizeof(T); ++i)
      memory_[r.address + i] = static_cast<std::uint8_t>(v >> (8 * i));
    afterPdiWrite(r.address);
  }

  // Raw register access for tests, the status view and fault injection.
  std::uint8_t reg8(std::uint16_t address) const { return memory_[address]; }
  std::uint16_t reg16(std::uint16_t address) const { return readLe16(memory_, address); }
  std::uint32_t reg32(std::uint16_t address) const { return readLe32(memory_, address); }
  std::uint64_t reg64(std::uint16_t address) const { return readLe64(memory_, address); }
  // PDI-side register/RAM writes (no ECAT write masks; FMMU/SM caches follow).
  void pdiWrite8(std::uint16_t address, std::uint8_t v) {
    memory_[address] = v;
    afterPdiWrite(address);
  }
  void pdiWrite16(std::uint16_t address, std::uint16_t v) {
    writeLe16(memory_, address, v);
    afterPdiWrite(address);
  }
  void pdiWrite32(std::uint16_t address, std::uint32_t v) {
    writeLe32(memory_, address, v);
    afterPdiWrite(address);
  }
  void pdiWrite64(std::uint16_t address, std::uint64_t v) {
    writeLe64(memory_, address, v);
    afterPdiWrite(address);
  }
  std::size_t memorySize() const { return memory_.size(); }

  // Error counters (0x0300-0x0313), saturating at 0xFF as the datasheet specifies.
  void countRxError(unsigned port, bool invalidFrame);
  void countLostLink(unsigned port);
  // A frame already marked bad by an earlier ESC arrived at `port` (0x0308 + port).
  void countForwardedRxError(unsigned port);
  // An invalid frame passed the processing unit (0x030C; section I §14, Table 50).
  void countProcessingUnitError();

  // The SII EEPROM content (words), e.g. for persisting writes or inspecting.
  const std::vector<std::uint8_t>& sii() const { return sii_; }
  // Changes one byte of the EEPROM from outside (fault injection); takes effect at the next
  // reload or power-on reset, as on hardware.
  void writeSiiByte(std::size_t offset, std::uint8_t value) {
    if (offset < sii_.size()) sii_[offset] = value;
  }
  // Gives the EEPROM another configured station alias (word 4, checksum renewed: a topology's
  // alias=); 0x0012 takes it at the next reload or power-on reset.
  void setSiiStationAlias(std::uint16_t alias) { ecsim::setSiiStationAlias(sii_, alias); }

  // Power cycle: registers back to reset values, EEPROM content kept, reloaded.
  void powerOnReset();

  // ---- time-driven units (esc_time_units.cpp) ---------------------------------------------
  // Process-data watchdog (0x0400, 0x0420, 0x0440, 0x0442): every ECAT write to the buffer of
  // an SM whose control byte has the watchdog trigger bit (0x40) re-arms it; it expires when
  // no such write came for 0x0420 x (0x0400 + 2) x 40 ns (0x0420 = 0: disabled). Returns true
  // once per expiry, when `now` is past it (status bit cleared, counter incremented then).
  bool pdWatchdogExpired(SimTime now);
  // ESC configuration 0x0141 bit 0: the ESC itself copies AL control to AL status (no
  // firmware state machine, as in simple IO terminals without a microcontroller).
  bool deviceEmulation() const { return (memory_[reg::kEscConfiguration.address] & 0x01) != 0; }
  // SYNC0/SYNC1 pulses of the cyclic unit that are due at or before `now`, one per call, in
  // time order; false when none is due. `time` is the simulation time of the pulse.
  struct SyncPulse {
    unsigned signal{0};
    SimTime time{0};
  };
  bool nextSyncPulse(SimTime now, SyncPulse& pulse);
  // The cyclic unit was activated with a start time already in the past: as on the ET1100,
  // the first pulse waits for the 64-bit system time to reach it again (never, in practice).
  bool syncStartMissed() const { return sync_.running && sync_.startMissed; }

  // ---- AL control, device emulation, ECAT events (esc_events.cpp; issue #15 items 2, 5) ----
  // The firmware reads AL control through the PDI: clears AL event request 0x0220 bit 0 and
  // lets the master write AL control again (section II 0x0120 note: without device emulation
  // AL control behaves like a mailbox).
  std::uint16_t pdiReadAlControl();
  // False while an ECAT write of AL control would be refused: device emulation off and the
  // firmware has not read the last value yet (section II 0x0120 note).
  bool ecatAlControlWritable() const { return deviceEmulation() || !alControlUnread_; }
  // The ECAT side wrote AL control (called after the write): AL event request, and with device
  // emulation the copy into AL status as written, error-acknowledge bit included.
  void ecatAlControlWritten();
  // The DL status (0x0110) got a new value from the ports (topology): DL status event.
  void dlStatusChanged();
  // ECAT event request 0x0210 masked by the ECAT event mask 0x0200: what this ESC ORs into
  // the IRQ field of every datagram passing it (section II 0x0200/0x0210).
  std::uint16_t ecatIrq() const { return ecatIrq_; }
  // Recomputes 0x0210 (SyncManager and latch bits follow their status registers) and ecatIrq.
  void refreshEcatEvents();

  // ---- DC latch unit (esc_latch.cpp; section I "Distributed Clocks: LatchSignals", section II
  // 0x0980, 0x09A8-0x09CF) ------------------------------------------------------------------
  // The LATCH0/LATCH1 input pin (`unit` 0/1) goes to `level` at simulation time `time` (not
  // before the last time the ESC saw). An edge stores the system time at `time` in the unit's
  // positive- or negative-edge time register: in continuous mode every edge, in single-event
  // mode (0x09A8+unit bit 0/1) only the first one until that register is read by the unit's
  // owner (0x0980 bit 4+unit: 0 ECAT, 1 PDI), with the event in the latch status and 0x0210
  // bit 0 (ECAT) or 0x0220 bit 1 (PDI). Nothing happens without a full DC unit.
  void setLatchInput(unsigned unit, bool level, SimTime time);
  bool latchInput(unsigned unit) const { return unit < latchPin_.size() && latchPin_[unit]; }
  // PDI read of a latch time register (the firmware's timestamp): clears the single event when
  // the PDI owns the unit, as an ECAT read does when the master owns it.
  std::uint64_t pdiReadLatchTime(unsigned unit, bool negativeEdge);

  const EscCounters& counters() const { return counters_; }

 private:
  // ---- What every passing frame touches, first and together (docs/timing.md, "Simulator
  // speed"): a frame passing a thousand ESCs finds them outside the L1 cache, so each ESC costs
  // the cache lines it touches. Line 0: the local clock and the per-datagram flags; line 1: the
  // datagram's times, per-frame SM state, cache counts, frame counter; line 2: the other
  // counters and where the memory is; then the FMMU cache. A datagram no FMMU of this ESC maps
  // (most of them, in a long line) touches lines 0-2 and the memory it addresses (a register
  // read below every SyncManager: one line). Keep new per-frame state here, cold state further
  // down, and kHotBytes covering it.
  alignas(64) DcClock dc_;
  std::uint16_t lastWkcIncrement_{0};
  std::uint16_t ecatIrq_{0};      // 0x0210 & 0x0200
  std::uint16_t smEventMask_{0};  // SM bits of 0x0200 (nonzero: SM events are followed)
  // 0x0010, 0x0012 and 0x0103 bit 0 as in memory_, copied by refreshAddressing() after every
  // ECAT access, PDI register write, reset and SII load (the only ways they change).
  std::uint16_t station_{0};
  std::uint16_t alias_{0};
  bool aliasOn_{false};
  // No enabled SyncManager range starts below this (0xFFFF: none): a register access below
  // it needs no SM lookup (smRanges_ lies outside the hot group).
  std::uint16_t smLowestStart_{0xFFFF};
  void refreshAddressing() {
    const std::uint16_t station = reg16(reg::kConfiguredStationAddress.address);
    const std::uint16_t alias = reg16(reg::kConfiguredStationAlias.address);
    const bool aliasOn = (memory_[reg::kDlControl.address + 3] & 0x01) != 0;
    if (station == station_ && alias == alias_ && aliasOn == aliasOn_) return;
    station_ = station;
    alias_ = alias;
    aliasOn_ = aliasOn;
    if (observer_ != nullptr) observer_->escAddressingChanged(observerId_);
  }
  // Marks an event for the firmware: events_.x = true, then noteEvent().
  void noteEvent() {
    if (eventsNoted_ || observer_ == nullptr) return;
    eventsNoted_ = true;
    observer_->escEventsRaised(observerId_);
  }
  void noteIrq() {
    if (observer_ == nullptr) return;
    const bool followsSm = smEventMask_ != 0;
    if (ecatIrq_ == irqNoted_ && followsSm == smNoted_) return;
    irqNoted_ = ecatIrq_;
    smNoted_ = followsSm;
    observer_->escIrqChanged(observerId_, ecatIrq_, followsSm);
  }
  EscObserver* observer_{nullptr};
  std::uint32_t observerId_{0};
  bool eventsNoted_{false};
  std::uint16_t irqNoted_{0};
  bool smNoted_{false};
  // Per-frame state of the SM rules and invalid frames (esc_sm.cpp).
  bool invalidFrame_{false};
  bool latchArmed_{false};
  SimTime now_{0};                  // simulation time of the datagram being processed
  SimTime localNow_{0};             // local time of the datagram being processed
  std::uint32_t smEndAccessed_{0};  // bit per SM: its end address was accessed in this frame
  std::uint8_t activeFmmuCount_{0};
  std::uint8_t smRangeCount_{0};
  std::uint8_t smTriggerOnlyCount_{0};
  DcUnit dcUnit_{DcUnit::kFull};
  EscCounters counters_{};            // framesSeen first: on line 1
  std::vector<std::uint8_t> memory_;  // registers 0x0000-0x0FFF + process RAM
  const RegisterBytes& regs_;  // the register table, per byte (shared by all ESCs)
  // Bytes of the hot group, from dc_ to regs_ (prefetchFrameState()).
  static constexpr std::size_t kHotBytes = 192;
  struct ActiveFmmu {
    std::uint64_t logicalStartBit;  // absolute logical bit address
    std::uint64_t logicalEndBit;    // inclusive
    std::uint32_t physicalStartBit;
    std::uint8_t type;
    bool byteAligned;
  };
  alignas(64) std::array<ActiveFmmu, reg::kMaxFmmus> activeFmmus_{};

  struct SmState {
    // 3-buffer mode: three buffers of `length` bytes in buffers_. `latest` holds the newest
    // complete one (for the reader), `writing` is the one the writer fills.
    std::uint16_t bufferOffset{0};  // into buffers_
    std::uint8_t latest{0};
    std::uint8_t writing{1};
    bool hasLatest{false};
    bool mailboxFull{false};
    // Section I §8: accessed at its start address, end address not yet accessed (the buffer
    // may be accessed anywhere until then).
    bool open{false};
  };

  void reset();
  void loadFromSii();
  // ECAT access to [address, address + size): registers with write masks and side effects,
  // process RAM through the SyncManagers. Return false when no byte could be accessed (an SM
  // blocked it), which means no working-counter increment.
  bool readMemory(std::uint32_t address, Bytes out, bool orInto);
  bool writeMemory(std::uint32_t address, ConstBytes data);
  // Process RAM access for one contiguous piece inside one SM (sm >= 0) or outside any (-1).
  bool readRam(std::uint16_t address, Bytes out, bool orInto, int sm);
  bool writeRam(std::uint16_t address, ConstBytes data, int sm);
  // ---- register file (esc_registers.cpp, rows in esc_register_table.cpp) ----
  // Stores an ECAT write as the table's masks and byte rules say, then runs the write hooks of
  // the rows it touched. Returns false when no byte of the range is writable for ECAT (no WKC).
  bool writeRegisters(std::uint16_t address, ConstBytes data);
  void runWriteHook(WriteHook hook, std::uint32_t begin, std::uint32_t end, ConstBytes data,
                    const std::array<bool, reg::kMaxSyncManagers>& smWasEnabled);
  // The read hooks of the rows in [begin, end), as a bit set (bit n = ReadHook n).
  std::uint32_t readHooks(std::uint32_t begin, std::uint32_t end) const;
  // Firmware write of registers with the table's PDI write masks.
  bool pdiWriteRegisters(std::uint16_t address, ConstBytes data);
  bool smEnabledBit(unsigned s) const {
    return (memory_[reg::smChannel(s) + reg::sm::kActivate.address] & reg::sm::kActivateEnable) !=
           0;
  }
  // [begin, end) overlapping 0x0910-0x0917 was written with `data` (starting at begin): one
  // step of the drift control loop, 0x092C updated.
  void systemTimeWritten(std::uint32_t begin, std::uint32_t end, ConstBytes data);
  void refreshVolatile(std::uint16_t begin, std::uint16_t end);
  // ---- SII EEPROM interface timing (esc_sii.cpp, issue #15 item 7) ----------------------
  // A command written to 0x0503 starts it (busy, command bits held); it takes effect when
  // the device's busy time (EscType::siiBusyNs) has passed. siiRefresh() completes it once
  // the ESC's time (now_) is past that: the table's read hook and byte rule for 0x0502-0x050F
  // call it, so a read sees the result and a write is refused only while still busy.
  void siiCommand(std::uint16_t control);
  void siiRefresh();
  bool siiAcceptsWrite() {
    siiRefresh();
    return !siiPending_;
  }
  void siiExecute(std::uint16_t command, std::uint32_t word, std::uint16_t data);
  void smActivationChanged(unsigned sm);
  // The enabled SM covering `at` (or -1); lowers `limit` to where that SM, or the next SM
  // above `at`, ends or starts, so callers split accesses at SM boundaries.
  int smLookup(std::uint32_t at, std::uint32_t& limit) const;
  // False when [at, at + n) lies entirely in registers this ESC type does not have.
  bool implemented(std::uint32_t at, std::uint32_t n) const;
  void rebuildSmCache();
  void afterPdiWrite(std::uint16_t address) {
    refreshAddressing();
    if (address >= reg::kFmmuBase && address < reg::kFmmuBase + reg::kFmmuSize * reg::kMaxFmmus) {
      rebuildFmmuCache();
    } else if (address >= reg::kSmBase &&
               address < reg::kSmBase + reg::kSmSize * reg::kMaxSyncManagers) {
      rebuildSmCache();
    } else if (address == reg::kCyclicUnitControl.address ||
               address == reg::kDcActivation.address) {
      onSyncActivationWrite();
      latchEventsChanged();  // 0x0980 says who owns the latch units
    } else if (address == reg::kLatch0Control.address || address == reg::kLatch1Control.address) {
      latchControlWritten();
    }
  }
  // Logical addressing through FMMUs. Returns {readHit, writeHit}.
  std::pair<bool, bool> processLogical(DatagramView d, bool doRead, bool doWrite);
  void latchReceiveTimes();
  // Time-driven units (esc_time_units.cpp).
  void triggerPdWatchdog() {
    pdWatchdog_.armed = true;
    pdWatchdog_.expired = false;
    pdWatchdog_.lastTrigger = now_;
    memory_[reg::kWatchdogStatusProcessData.address] |= 0x01;
  }
  void onSyncActivationWrite();
  void refreshSyncRegisters(std::uint16_t begin, std::uint16_t end);
  std::uint64_t systemTimeNow() const;
  std::uint64_t lastSync0(std::uint64_t sysNow, bool& any) const;
  std::uint64_t sync1Time(std::uint64_t k) const;
  std::uint64_t sync1IndexAfter(std::uint64_t sysNow) const;

  struct PdWatchdog {
    bool armed{false};
    bool expired{false};
    SimTime lastTrigger{0};
  };
  PdWatchdog pdWatchdog_{};
  // Cyclic unit state, latched at activation (system times).
  struct SyncState {
    bool running{false};
    bool startMissed{false};
    bool sync0{false};
    bool sync1{false};
    std::uint64_t start{0};
    std::uint64_t cycle0{0};
    std::uint64_t cycle1{0};
    std::uint64_t pulseLength{0};  // ns; 0 = acknowledge mode
    std::uint64_t next0Index{0};   // next SYNC0 pulse: start + index * cycle0
    std::uint64_t next1Index{0};
    bool done0{false};  // single shot delivered
    bool done1{false};
    std::uint64_t ack0{0};  // system time of the last status read (acknowledge mode)
    std::uint64_t ack1{0};
  };
  SyncState sync_{};

  const EscType type_;
  std::vector<std::uint8_t> buffers_;  // 3-buffer storage, 3 * length per buffered SM
  std::vector<std::uint8_t> sii_;
  std::array<SmState, reg::kMaxSyncManagers> sm_{};
  std::vector<std::uint8_t> lastMailboxResponse_;
  std::size_t lastMailboxResponseSize_{0};
  // SII EEPROM command in progress (esc_sii.cpp): what runs and when it is done.
  bool siiPending_{false};
  std::uint16_t siiPendingCommand_{0};
  std::uint16_t siiPendingData_{0};
  std::uint32_t siiPendingWord_{0};
  SimTime siiDoneAt_{0};

  // ---- MII management interface and PHY model (esc_mii.cpp, issue #15 item 8) -----------
  // One IEEE 802.3 clause 22 PHY per MII port, at PHY address (0x0510[7:3] + port).
  struct PhyState {
    std::uint16_t control{0};
    std::uint16_t advertisement{0};
  };
  void miiReset();
  // Command byte 0x0511 written (table write hook): start a read or write of a PHY register.
  void miiCommand();
  // Byte rule of 0x0510-0x0515: ECAT writes are refused while a command runs or while the PDI
  // has the interface (0x0517 bit 0).
  bool miiAcceptsEcatWrite();
  // Completes a running MII command once the ESC's time is past its end.
  void miiRefresh();
  bool phyPresent(std::uint8_t phyAddress, unsigned& port) const;
  std::uint16_t phyRead(unsigned port, std::uint8_t index) const;
  void phyWrite(unsigned port, std::uint8_t index, std::uint16_t value);
  std::array<PhyState, 4> phys_{};
  bool miiPending_{false};
  std::uint16_t miiPendingCommand_{0};
  std::uint8_t miiPendingPhy_{0};
  std::uint8_t miiPendingRegister_{0};
  std::uint16_t miiPendingData_{0};
  SimTime miiDoneAt_{0};
  EscEvents events_{};
  void rebuildFmmuCache();

  struct SmRange {
    std::uint16_t start;
    std::uint32_t end;  // exclusive
    std::uint8_t index;
  };
  std::array<SmRange, reg::kMaxSyncManagers> smRanges_{};
  // smConfig() of every SM this ESC has, as of the last rebuildSmCache(): start, length,
  // control and enabled are current (every write of an SM channel's bytes 0-4, 6 and 7 goes
  // through the ECAT SM hook or afterPdiWrite, both of which rebuild); status, repeat request
  // and repeat acknowledge are not (read them from memory_). The datagram path and the PDI
  // functions read this instead of decoding the channel on every access.
  std::array<SmConfig, reg::kMaxSyncManagers> smCache_{};
  // Bit s: SM s's control byte asks for ECAT events (0x0804 bit 4; refreshEcatEvents).
  std::uint16_t smEventControl_{0};
  // The enabled SM with more than one byte in mailbox mode whose ECAT direction is `ecatWrite`
  // (the lowest such index), or -1.
  int mailboxSm(bool ecatWrite) const;
  std::vector<std::uint8_t> scratch_;  // read-write and bit-FMMU staging, one datagram

  // ---- AL control, device emulation, ECAT events (esc_events.cpp) ----
  void resetEventState();
  // Register hooks (esc_registers.cpp calls them from the table's rows).
  void ecatEventMaskWritten();
  void clearEcatEvents(std::uint16_t bits);
  // After a physical ECAT read of registers [begin, end): clear-on-read effects (ReadHook).
  void afterRegisterRead(std::uint32_t begin, std::uint32_t end);
  // The header of a datagram passes: the masked event request goes into its IRQ field.
  void orEventsIntoIrq(DatagramView d) {
    if (smEventMask_ != 0) refreshEcatEvents();  // SM events follow SM status between frames
    if (ecatIrq_ != 0) d.setIrq(static_cast<std::uint16_t>(d.irq() | ecatIrq_));
  }
  // The PDI completed a read of a write-direction mailbox-mode buffer / a write of a
  // read-direction one: status 0x0805+8n as section II says (esc_sm.cpp).
  void pdiReadCompleted(unsigned sm);
  void pdiWriteCompleted(unsigned sm);
  // After a PDI-side change of an SM status: the SM's ECAT event follows it.
  void pdiSmStatusChanged() {
    if (smEventMask_ != 0) refreshEcatEvents();
  }
  bool alControlUnread_{false};  // written by ECAT, not yet read by the PDI

  // ---- SyncManager access rules and invalid frames (esc_sm.cpp; section I §8, §14.1) ----
  enum class SmAccess : std::uint8_t {
    kDenied,  // not begun at the start address, or the end address again in this frame
    kInside,  // allowed, the buffer state does not change
    kEnd,     // allowed and it accesses the end address: the buffer completes
  };
  SmAccess smAccess(unsigned sm, std::uint16_t address, std::size_t size);
  // Invalid frame: writes only the RAM (>= 0x0F80) that no SyncManager covers.
  bool writeUnshadowed(std::uint32_t address, ConstBytes data);
  // An SM of length 1 is no buffer (section II Table 90): plain memory whose ECAT write only
  // triggers the process-data watchdog (if its control byte asks for it).
  struct SmTriggerOnly {
    std::uint16_t address;
    std::uint8_t index;
    SmControl control;
  };
  void smTriggerOnlyWrite(std::uint32_t address, std::uint32_t size);
  std::array<SmTriggerOnly, reg::kMaxSyncManagers> smTriggerOnly_{};

  // ---- DC latch unit (esc_latch.cpp) ----
  // Reset: no events, the status shows the pins' levels (the pins are outside the ESC).
  void latchReset();
  // An ECAT read of [begin, end) in 0x09B0-0x09CF: the owner's read clears the single event.
  void latchTimesRead(std::uint32_t begin, std::uint32_t end);
  // A latch status or 0x0980 changed: 0x0210 bit 0 and 0x0220 bit 1 follow.
  void latchEventsChanged();
  // 0x09A8/0x09A9 written by their owner: edges now in continuous mode show no event.
  void latchControlWritten();
  bool latchOwnedByPdi(unsigned unit) const {
    return (memory_[reg::kCyclicUnitControl.address] & (reg::latch::kPdiControlledUnit0 << unit)) !=
           0;
  }
  std::array<bool, reg::latch::kUnits> latchPin_{};
  bool latchEcatEvent_{false};  // an ECAT-owned unit shows an event: 0x0210 bit 0
};

}  // namespace ecsim::slavesim
