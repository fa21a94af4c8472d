// The ESC's time-driven units: the process-data watchdog and the DC cyclic unit that
// generates SYNC0/SYNC1 (ESC datasheet section I, "Watchdog" and "Distributed Clocks: SyncSignal
// generation"; registers in section II 0x0400-0x0443 and 0x0980-0x09A7).
//
// Both are evaluated lazily from simulation time: when the firmware polls (Slave::poll) and
// when the master reads their registers. Nothing here allocates.
//
// Cyclic unit, as the ET1100 does it:
//  - activation (0x0981 bit 0 with bit 1 SYNC0 and/or bit 2 SYNC1) latches the start time
//    0x0990, the cycle times 0x09A0/0x09A4 and the pulse length 0x0982 (10 ns units);
//  - the first SYNC0 pulse comes when the system time reaches the start time, then one every
//    SYNC0 cycle time (0 = a single pulse); a start time already in the past is reached only
//    after the 64-bit system time wraps, i.e. never: the classic master mistake, kept visible
//    through the activation status 0x0984 bit 0 (first pulse pending) that never clears;
//  - SYNC1 depends on SYNC0: with a SYNC1 cycle time shorter than the SYNC0 cycle time (or a
//    single-shot SYNC0) it follows each SYNC0 pulse by that time; with a longer one, SYNC1
//    comes with every m-th SYNC0 pulse (m = SYNC1 / SYNC0 cycle, integer part) delayed by the
//    remainder;
//  - 0x0990 reads as the next SYNC0 pulse time and 0x0998 as the next SYNC1 pulse time while
//    the unit runs; 0x098E/0x098F (SYNC0/1 status): with pulse length 0 (acknowledge mode) set
//    by a pulse and cleared by reading, otherwise set for the pulse's duration.
#include <algorithm>

#include "slavesim/esc.hpp"

namespace ecsim::slavesim {
namespace {

constexpr std::uint8_t kActivationCyclicUnit = 0x01;
constexpr std::uint8_t kActivationSync0 = 0x02;
constexpr std::uint8_t kActivationSync1 = 0x04;
constexpr std::uint8_t kActivationStatusSync0Pending = 0x01;
constexpr std::uint8_t kActivationStatusSync1Pending = 0x02;
constexpr std::uint16_t kSync0StatusAddress = reg::kSync0Status.address;
constexpr std::uint16_t kSync1StatusAddress = reg::kSync1Status.address;

// Wrap-aware "a is not after b" for 64-bit system times.
bool notAfter(std::uint64_t a, std::uint64_t b) {
  return static_cast<std::int64_t>(a - b) <= 0;
}

bool overlapsRange(std::uint16_t begin, std::uint16_t end, std::uint16_t address, unsigned width) {
  return begin < address + width && end > address;
}

}  // namespace

// ---- process-data watchdog --------------------------------------------------------------------

bool Esc::pdWatchdogExpired(SimTime now) {
  if (!pdWatchdog_.armed || pdWatchdog_.expired) return false;
  const std::uint64_t ticks = read(reg::kWatchdogTimeProcessData);
  if (ticks == 0) return false;  // disabled
  // One watchdog increment is (divider + 2) periods of the 25 MHz clock (40 ns).
  const std::uint64_t unitNs =
      (static_cast<std::uint64_t>(read(reg::kWatchdogDivider)) + 2) * 40;
  const auto timeout = static_cast<SimTime>(ticks * unitNs);
  if (now - pdWatchdog_.lastTrigger < timeout) return false;
  pdWatchdog_.expired = true;
  memory_[reg::kWatchdogStatusProcessData.address] &= static_cast<std::uint8_t>(~0x01u);
  std::uint8_t& counter = memory_[reg::kWatchdogCounterProcessData.address];
  if (counter != 0xFF) ++counter;  // saturates (datasheet)
  return true;
}

// ---- cyclic unit ------------------------------------------------------------------------------

std::uint64_t Esc::systemTimeNow() const {
  return static_cast<std::uint64_t>(localNow_) + read(reg::kSystemTimeOffset);
}

void Esc::onSyncActivationWrite() {
  const std::uint8_t act = memory_[reg::kDcActivation.address];
  const bool on = dcUnit_ == DcUnit::kFull && (act & kActivationCyclicUnit) != 0 &&
                  (act & (kActivationSync0 | kActivationSync1)) != 0;
  if (!on) {
    sync_ = {};
    memory_[reg::kDcActivationStatus.address] = 0;
    return;
  }
  if (sync_.running) {
    // Generation bits may be switched while running; timing stays as latched.
    sync_.sync0 = (act & kActivationSync0) != 0;
    sync_.sync1 = (act & kActivationSync1) != 0;
    return;
  }
  sync_ = {};
  sync_.running = true;
  sync_.sync0 = (act & kActivationSync0) != 0;
  sync_.sync1 = (act & kActivationSync1) != 0;
  sync_.start = read(reg::kStartTimeCyclicOperation);
  sync_.cycle0 = read(reg::kSync0CycleTime);
  sync_.cycle1 = read(reg::kSync1CycleTime);
  sync_.pulseLength = static_cast<std::uint64_t>(read(reg::kSyncPulseLength)) * 10;
  const std::uint64_t sysNow = systemTimeNow();
  sync_.startMissed = !notAfter(sysNow, sync_.start);
  sync_.ack0 = sync_.ack1 = sysNow;
  memory_[reg::kDcActivationStatus.address] =
      static_cast<std::uint8_t>((sync_.sync0 ? kActivationStatusSync0Pending : 0) |
                                (sync_.sync1 ? kActivationStatusSync1Pending : 0));
}

// System time of SYNC1 pulse number k.
std::uint64_t Esc::sync1Time(std::uint64_t k) const {
  if (sync_.cycle0 == 0 || sync_.cycle1 < sync_.cycle0) {
    return sync_.start + k * sync_.cycle0 + sync_.cycle1;
  }
  const std::uint64_t m = sync_.cycle1 / sync_.cycle0;
  const std::uint64_t rest = sync_.cycle1 % sync_.cycle0;
  return sync_.start + (k + 1) * m * sync_.cycle0 + rest;
}

std::uint64_t Esc::sync1IndexAfter(std::uint64_t sysNow) const {
  if (sync_.startMissed || !notAfter(sync_.start, sysNow)) return 0;
  // sync1Time is increasing and pulse k is at least k SYNC0 cycles after the start.
  std::uint64_t lo = 0;
  std::uint64_t hi = sync_.cycle0 == 0 ? 1 : (sysNow - sync_.start) / sync_.cycle0 + 2;
  while (lo < hi) {
    const std::uint64_t mid = lo + (hi - lo) / 2;
    if (notAfter(sync1Time(mid), sysNow)) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  return lo;
}

bool Esc::nextSyncPulse(SimTime now, SyncPulse& pulse) {
  if (!sync_.running || sync_.startMissed) return false;
  const std::uint64_t sysNow =
      static_cast<std::uint64_t>(dc_.localTime(now)) + read(reg::kSystemTimeOffset);
  bool have0 = sync_.sync0 && !sync_.done0;
  bool have1 = sync_.sync1 && !sync_.done1;
  const std::uint64_t t0 = sync_.start + sync_.next0Index * sync_.cycle0;
  const std::uint64_t t1 = sync1Time(sync_.next1Index);
  have0 = have0 && notAfter(t0, sysNow);
  have1 = have1 && notAfter(t1, sysNow);
  if (!have0 && !have1) return false;
  const bool take0 = have0 && (!have1 || notAfter(t0, t1));
  const std::uint64_t t = take0 ? t0 : t1;
  if (take0) {
    if (sync_.cycle0 == 0) sync_.done0 = true;
    ++sync_.next0Index;
  } else {
    if (sync_.cycle0 == 0) sync_.done1 = true;
    ++sync_.next1Index;
  }
  pulse.signal = take0 ? 0 : 1;
  // Local time of the pulse, then the simulation time at which the local clock shows it.
  const auto local = static_cast<SimTime>(t - read(reg::kSystemTimeOffset));
  pulse.time = dc_.globalTime(local);
  return true;
}

// Time of the last SYNC0 pulse at or before sysNow; any = false when none has come yet.
std::uint64_t Esc::lastSync0(std::uint64_t sysNow, bool& any) const {
  any = false;
  if (!sync_.running || sync_.startMissed || !notAfter(sync_.start, sysNow)) return 0;
  any = true;
  if (sync_.cycle0 == 0) return sync_.start;
  return sync_.start + ((sysNow - sync_.start) / sync_.cycle0) * sync_.cycle0;
}

void Esc::refreshSyncRegisters(std::uint16_t begin, std::uint16_t end) {
  if (!sync_.running) return;
  const std::uint64_t sysNow = systemTimeNow();
  bool any = false;
  const std::uint64_t last0 = lastSync0(sysNow, any);
  if (overlapsRange(begin, end, reg::kDcActivationStatus.address, 1)) {
    std::uint8_t status = memory_[reg::kDcActivationStatus.address];
    if (any) status = static_cast<std::uint8_t>(status & ~kActivationStatusSync0Pending);
    if (notAfter(sync1Time(0), sysNow) && !sync_.startMissed) {
      status = static_cast<std::uint8_t>(status & ~kActivationStatusSync1Pending);
    }
    memory_[reg::kDcActivationStatus.address] = status;
  }
  // SYNC1 pulses before and after sysNow (first index with a pulse time after sysNow).
  const std::uint64_t next1 = sync1IndexAfter(sysNow);
  if (overlapsRange(begin, end, kSync0StatusAddress, 2)) {
    const bool any1 = sync_.sync1 && next1 > 0;
    const std::uint64_t last1 = any1 ? sync1Time(next1 - 1) : 0;
    auto status = [&](bool pulsed, std::uint64_t last, std::uint64_t& ack) -> std::uint8_t {
      if (!pulsed) return 0;
      if (sync_.pulseLength == 0) {  // acknowledge mode: set by a pulse, cleared by a read
        const bool set = !notAfter(last, ack);
        ack = sysNow;
        return set ? 1 : 0;
      }
      return sysNow - last < sync_.pulseLength ? 1 : 0;
    };
    if (overlapsRange(begin, end, kSync0StatusAddress, 1)) {
      memory_[kSync0StatusAddress] = status(sync_.sync0 && any, last0, sync_.ack0);
    }
    if (overlapsRange(begin, end, kSync1StatusAddress, 1)) {
      memory_[kSync1StatusAddress] = status(any1, last1, sync_.ack1);
    }
  }
  if (overlapsRange(begin, end, reg::kStartTimeCyclicOperation.address, 8) && !sync_.startMissed) {
    std::uint64_t next = sync_.start;
    if (any) next = sync_.cycle0 == 0 ? last0 : last0 + sync_.cycle0;
    writeLe64(memory_, reg::kStartTimeCyclicOperation.address, next);
  }
  if (overlapsRange(begin, end, reg::kNextSync1Pulse.address, 8) && sync_.sync1 &&
      !sync_.startMissed) {
    writeLe64(memory_, reg::kNextSync1Pulse.address, sync1Time(next1));
  }
}

}  // namespace ecsim::slavesim
