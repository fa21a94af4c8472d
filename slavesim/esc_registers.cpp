// The register file as the ECAT side sees it: write masks and the side effects of register
// writes and reads (datasheet section II).
#include "slavesim/esc.hpp"

#include <algorithm>
#include <cstring>

#include "slavesim/esc_internal.hpp"

namespace ecsim::slavesim {
using namespace esc_detail;

// ECAT write masks of the register space, one byte per register byte: the same for every ESC
// type this simulator models, so one immutable table is shared by all ESCs (it stays hot in
// the cache when a frame passes a thousand of them).
const std::array<std::uint8_t, kRamStart>& esc_detail::ecatWriteMasks() {
  static const std::array<std::uint8_t, kRamStart> table = [] {
    std::array<std::uint8_t, kRamStart> masks{};
    // ECAT write masks (datasheet section II register tables, column "ECAT"). Everything not
    // listed is read-only for the master.
    auto allow = [&](std::uint16_t address, std::uint16_t width, std::uint8_t mask = 0xFF) {
      for (std::uint16_t i = 0; i < width; ++i) masks[address + i] = mask;
    };
    allow(reg::kConfiguredStationAddress.address, 2);
    allow(reg::kRegisterWriteEnable.address, 1, 0x01);
    allow(reg::kRegisterWriteProtection.address, 1, 0x01);
    allow(reg::kEscWriteEnable.address, 1, 0x01);
    allow(reg::kEscWriteProtection.address, 1, 0x01);
    allow(reg::kEscResetEcat.address, 1);
    allow(reg::kDlControl.address, 4);
    allow(reg::kPhysicalRwOffset.address, 2);
    allow(reg::kAlControl.address, 2);
    allow(reg::kRunLedOverride.address, 2);
    allow(reg::kEcatEventMask.address, 2);
    allow(reg::kErrorCountersBegin, reg::kErrorCountersEnd - reg::kErrorCountersBegin);
    allow(reg::kWatchdogDivider.address, 2);
    allow(reg::kWatchdogTimePdi.address, 2);
    allow(reg::kWatchdogTimeProcessData.address, 2);
    allow(reg::kWatchdogCounterProcessData.address, 2);
    allow(reg::kSiiConfiguration.address, 1, 0x03);
    allow(reg::kSiiControlStatus.address, 1, 0x01);      // write enable
    allow(reg::kSiiControlStatus.address + 1, 1, 0x07);  // command bits 8-10
    allow(reg::kSiiAddress.address, 4);
    allow(reg::kSiiData.address, 8);
    allow(reg::kMiiControlStatus.address, 6);
    allow(reg::kMiiEcatAccessState.address, 1, 0x01);
    allow(reg::kFmmuBase, reg::kFmmuSize * reg::kMaxFmmus);
    for (unsigned n = 0; n < reg::kMaxSyncManagers; ++n) {
      std::uint16_t base = reg::smChannel(n);
      allow(base, 5);                                     // start, length, control
      allow(base + reg::sm::kActivate.address, 1, 0xC3);  // enable, repeat, latch bits
    }
    allow(reg::kReceiveTimePort0.address, 4);  // a write latches, content not changed
    allow(reg::kSystemTime.address, 8);
    allow(reg::kSystemTimeOffset.address, 8);
    allow(reg::kSystemTimeDelay.address, 4);
    allow(reg::kSpeedCounterStart.address, 2);
    allow(reg::kSystemTimeDifferenceFilterDepth.address, 3);
    allow(reg::kCyclicUnitControl.address, 2);
    allow(reg::kStartTimeCyclicOperation.address, 8);
    allow(reg::kSync0CycleTime.address, 8);
    allow(reg::kLatch0Control.address, 2);
    allow(reg::kDigitalIoOutputData.address, 4);
    allow(reg::kGeneralPurposeOutputs.address, 8);
    allow(reg::kUserRam.address, reg::kUserRam.width);
    return masks;
  }();
  return table;
}

void Esc::systemTimeWritten(std::uint32_t begin, std::uint32_t end, ConstBytes data) {
  // Written system time is compared with the local copy; the difference feeds the drift
  // control loop (datasheet section I §9.1.3). A 32-bit write compares the low 32 bits.
  // 0x092C: bit 31 set = local copy smaller than the received time.
  const SimTime local = wrapAdd(localNow_, reg64(reg::kSystemTimeOffset.address));
  std::uint64_t written = static_cast<std::uint64_t>(local);
  if (begin == reg::kSystemTime.address && end == reg::kSystemTime.end()) {
    written = readLe64(data, 0);  // the usual 64-bit distribution (ARMW/FRMW)
  } else {
    for (std::uint32_t i = 0; i < 8; ++i) {
      std::uint32_t a = reg::kSystemTime.address + i;
      if (a >= begin && a < end) {
        written = (written & ~(0xFFull << (8 * i))) |
                  (static_cast<std::uint64_t>(data[a - begin]) << (8 * i));
      }
    }
  }
  const SimTime received =
      wrapAdd(static_cast<SimTime>(written), reg32(reg::kSystemTimeDelay.address));
  const std::int64_t diff = dc_.onSystemTimeWrite(
      now_, local, received, memory_[reg::kSystemTimeDifferenceFilterDepth.address] & 0x0F);
  writeLe32(memory_, reg::kSystemTimeDifference.address, systemTimeDifferenceRegister(diff));
}

bool Esc::writeRegisters(std::uint16_t address, ConstBytes data) {
  const std::uint32_t begin = address;
  const std::uint32_t end = address + static_cast<std::uint32_t>(data.size());
  if (begin >= reg::kSystemTime.address && end <= reg::kSystemTime.end()) {
    // Fast path for the cyclic DC distribution (ARMW/FRMW of 0x0910 reaches every ESC but the
    // reference once per frame): no other register with side effects lies in this range.
    bool accepted = false;
    if (data.size() == 8) {
      // All of it: one masked merge of 8 bytes at once (bitwise, so byte order is irrelevant).
      std::uint64_t mask = 0;
      std::uint64_t old = 0;
      std::uint64_t value = 0;
      std::memcpy(&mask, writable_.data() + begin, 8);
      std::memcpy(&old, memory_.data() + begin, 8);
      std::memcpy(&value, data.data(), 8);
      const std::uint64_t merged = (old & ~mask) | (value & mask);
      std::memcpy(memory_.data() + begin, &merged, 8);
      accepted = mask != 0;
    }
    for (std::uint32_t i = 0; data.size() != 8 && i < data.size(); ++i) {
      const std::uint32_t a = begin + i;
      const std::uint8_t mask = writable_[a];
      accepted |= mask != 0;
      memory_[a] = static_cast<std::uint8_t>((memory_[a] & ~mask) | (data[i] & mask));
    }
    systemTimeWritten(begin, end, data);
    return accepted;
  }
  // SM channel registers 0x0800-0x0804 are writable only while the SM is disabled
  // (datasheet section II, SyncManager register description).
  std::array<bool, reg::kMaxSyncManagers> smWasEnabled{};
  const bool smTouched = overlaps(begin, end, reg::kSmBase, reg::kSmSize * reg::kMaxSyncManagers);
  for (unsigned s = 0; smTouched && s < type_.syncManagers; ++s) {
    smWasEnabled[s] =
        (memory_[reg::smChannel(s) + reg::sm::kActivate.address] & reg::sm::kActivateEnable) != 0;
  }
  bool accepted = false;
  for (std::uint32_t a = begin; a < end && !accepted; ++a) accepted = writable_[a] != 0;
  bool errorCounterWrite = false;
  bool lostLinkWrite = false;
  // Fast path (cyclic DC writes, AL control, ...): no register with per-byte special rules.
  const bool special =
      smTouched ||
      overlaps(begin, end, reg::kErrorCountersBegin,
               reg::kErrorCountersEnd - reg::kErrorCountersBegin) ||
      overlaps(begin, end, reg::kWatchdogCounterProcessData.address, 2) ||
      overlaps(begin, end, reg::kReceiveTimePort0.address, reg::kReceiveTimePort0.width);
  for (std::uint32_t i = 0; !special && i < data.size(); ++i) {
    const std::uint32_t a = begin + i;
    const std::uint8_t mask = writable_[a];
    memory_[a] = static_cast<std::uint8_t>((memory_[a] & ~mask) | (data[i] & mask));
  }
  for (std::uint32_t i = 0; special && i < data.size(); ++i) {
    const std::uint32_t a = begin + i;
    std::uint8_t mask = writable_[a];
    if (mask == 0) continue;
    if (a >= reg::kSmBase &&
        a < reg::kSmBase + reg::kSmSize * static_cast<std::uint32_t>(type_.syncManagers)) {
      unsigned s = (a - reg::kSmBase) / reg::kSmSize;
      unsigned off = (a - reg::kSmBase) % reg::kSmSize;
      if (off < reg::sm::kStatus.address && smWasEnabled[s]) continue;
    }
    if (a >= reg::kErrorCountersBegin && a < reg::kErrorCountersEnd) {
      // Error counters are cleared by a write of any value (datasheet section II §2.9).
      if (a < 0x030C)
        errorCounterWrite = true;
      else if (a >= 0x0310)
        lostLinkWrite = true;
      else
        memory_[a] = 0;
      continue;
    }
    if (a == reg::kWatchdogCounterProcessData.address || a == reg::kWatchdogCounterPdi.address) {
      memory_[a] = 0;
      continue;
    }
    if (a >= reg::kReceiveTimePort0.address && a < reg::kReceiveTimePort0.end()) continue;
    memory_[a] = static_cast<std::uint8_t>((memory_[a] & ~mask) | (data[i] & mask));
  }
  if (errorCounterWrite) std::fill_n(memory_.begin() + reg::kErrorCountersBegin, 0x0C, 0);
  if (lostLinkWrite) std::fill_n(memory_.begin() + 0x0310, 4, 0);

  if (overlaps(begin, end, reg::kDlControl.address, reg::kDlControl.width)) {
    events_.dlControlWritten = true;
  }
  if (overlaps(begin, end, reg::kAlControl.address, reg::kAlControl.width)) {
    events_.alControlWritten = true;
    memory_[reg::kAlEventRequest.address] |= 0x01;
  }
  if (overlaps(begin, end, reg::kSiiControlStatus.address + 1, 1)) {
    // The command byte was written: execute it (write needs the enable bit in the same access).
    siiCommand(reg16(reg::kSiiControlStatus.address));
  }
  if (overlaps(begin, end, reg::kSystemTime.address, reg::kSystemTime.width)) {
    systemTimeWritten(begin, end, data);
  }
  if (overlaps(begin, end, reg::kSpeedCounterStart.address, reg::kSpeedCounterStart.width)) {
    dc_.resetControl();
  }
  if (overlaps(begin, end, reg::kDcActivation.address, 1)) onSyncActivationWrite();
  if (overlaps(begin, end, reg::kFmmuBase, reg::kFmmuSize * reg::kMaxFmmus)) rebuildFmmuCache();
  if (overlaps(begin, end, reg::kSmBase, reg::kSmSize * reg::kMaxSyncManagers)) {
    for (unsigned s = 0; s < type_.syncManagers; ++s) {
      bool nowEnabled =
          (memory_[reg::smChannel(s) + reg::sm::kActivate.address] & reg::sm::kActivateEnable) != 0;
      if (nowEnabled != smWasEnabled[s]) smActivationChanged(s);
      if (overlaps(begin, end, reg::smChannel(s) + reg::sm::kActivate.address, 1) &&
          (memory_[reg::smChannel(s) + reg::sm::kActivate.address] &
           reg::sm::kActivateRepeatRequest) !=
              (memory_[reg::smChannel(s) + reg::sm::kPdiControl.address] &
               reg::sm::kPdiRepeatAck)) {
        events_.mailboxRead = true;  // firmware sees the repeat request toggle
      }
    }
    rebuildSmCache();
    events_.smConfigChanged = true;
  }
  return accepted;
}

void Esc::smActivationChanged(unsigned s) {
  SmState& st = sm_[s];
  st = {};
  std::uint16_t base = reg::smChannel(s);
  memory_[base + reg::sm::kStatus.address] = 0;
}

void Esc::refreshVolatile(std::uint16_t begin, std::uint16_t end) {
  if (overlaps(begin, end, reg::kCyclicUnitControl.address, 0x28)) refreshSyncRegisters(begin, end);
  if (overlaps(begin, end, reg::kSystemTime.address, reg::kSystemTime.width)) {
    writeLe64(
        memory_, reg::kSystemTime.address,
        static_cast<std::uint64_t>(wrapAdd(localNow_, reg64(reg::kSystemTimeOffset.address))));
  }
}

void Esc::completeReceiveTimeLatch(const std::array<SimTime, 4>& times, std::uint8_t portMask) {
  if (!latchArmed_) return;
  latchArmed_ = false;
  for (unsigned p = 0; p < 4; ++p) {
    if ((portMask & (1u << p)) != 0) {
      writeLe32(memory_, reg::receiveTime(p), static_cast<std::uint32_t>(dc_.localTime(times[p])));
    }
  }
}

void Esc::latchReceiveTimes() {
  latchArmed_ = true;
  writeLe64(memory_, reg::kReceiveTimeEcatProcessingUnit.address,
            static_cast<std::uint64_t>(localNow_));
  events_.dcLatched = true;
}

}  // namespace ecsim::slavesim
