// The register file as the ECAT side sees it: every write is stored and every side effect is
// run as the register table says (esc_register_table.cpp, datasheet section II); this file
// holds the hooks the table names.
#include "slavesim/esc.hpp"

#include <algorithm>
#include <cstring>

#include "slavesim/esc_internal.hpp"

namespace ecsim::slavesim {
using namespace esc_detail;

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
    // reference once per frame): one row, plain stores, one hook.
    bool accepted = false;
    if (data.size() == 8) {
      // All of it: one masked merge of 8 bytes at once (bitwise, so byte order is irrelevant).
      std::uint64_t mask = 0;
      std::uint64_t old = 0;
      std::uint64_t value = 0;
      std::memcpy(&mask, regs_.ecatWriteMask.data() + begin, 8);
      std::memcpy(&old, memory_.data() + begin, 8);
      std::memcpy(&value, data.data(), 8);
      const std::uint64_t merged = (old & ~mask) | (value & mask);
      std::memcpy(memory_.data() + begin, &merged, 8);
      accepted = mask != 0;
    }
    for (std::uint32_t i = 0; data.size() != 8 && i < data.size(); ++i) {
      const std::uint32_t a = begin + i;
      const std::uint8_t mask = regs_.ecatWriteMask[a];
      accepted |= mask != 0;
      memory_[a] = static_cast<std::uint8_t>((memory_[a] & ~mask) | (data[i] & mask));
    }
    systemTimeWritten(begin, end, data);
    return accepted;
  }
  // The SM hook compares each channel's enable bit before and after the write.
  std::array<bool, reg::kMaxSyncManagers> smWasEnabled{};
  if (overlaps(begin, end, reg::kSmBase, reg::kSmSize * reg::kMaxSyncManagers)) {
    for (unsigned s = 0; s < type_.syncManagers; ++s) smWasEnabled[s] = smEnabledBit(s);
  }
  bool accepted = false;
  bool clearRxErrors = false;
  bool clearLostLink = false;
  std::uint32_t hooks = 0;
  for (std::uint32_t i = 0; i < data.size(); ++i) {
    const std::uint32_t a = begin + i;
    const std::uint8_t mask = regs_.ecatWriteMask[a];
    if (mask == 0) continue;
    // AL control still unread by the firmware: refused, no working counter for it (as a full
    // SyncManager mailbox; section II 0x0120 note does not say).
    if (regs_.rule[a] == ByteRule::kAlControlMailbox && !ecatAlControlWritable()) continue;
    // A latch unit the PDI owns: its control register is read-only for the master (section
    // II 0x09A8: write access for ECAT only with 0x0980 bit 4/5 = 0), so no working counter.
    if (regs_.rule[a] == ByteRule::kLatchOwned &&
        latchOwnedByPdi(a - reg::kLatch0Control.address)) {
      continue;
    }
    accepted = true;
    hooks |= 1u << static_cast<unsigned>(regs_.write[a]);
    switch (regs_.rule[a]) {
      case ByteRule::kStore:
      case ByteRule::kAlControlMailbox:
      case ByteRule::kLatchOwned:
        memory_[a] = static_cast<std::uint8_t>((memory_[a] & ~mask) | (data[i] & mask));
        break;
      case ByteRule::kClearOnWrite:
        memory_[a] = 0;
        break;
      case ByteRule::kClearRxErrors:
        clearRxErrors = true;
        break;
      case ByteRule::kClearLostLink:
        clearLostLink = true;
        break;
      case ByteRule::kNoStore:
        break;
      case ByteRule::kSiiLocked:
        if (!siiAcceptsWrite()) break;
        memory_[a] = static_cast<std::uint8_t>((memory_[a] & ~mask) | (data[i] & mask));
        break;
      case ByteRule::kMiiLocked:
        if (!miiAcceptsEcatWrite()) break;
        memory_[a] = static_cast<std::uint8_t>((memory_[a] & ~mask) | (data[i] & mask));
        break;
      case ByteRule::kSmLocked: {
        // Bytes 0-4 of a channel precede its activate byte, so the enable bit read here is
        // still the one before this write.
        const unsigned s = (a - reg::kSmBase) / reg::kSmSize;
        if (s < type_.syncManagers && smEnabledBit(s)) break;
        memory_[a] = static_cast<std::uint8_t>((memory_[a] & ~mask) | (data[i] & mask));
        break;
      }
    }
  }
  if (clearRxErrors) std::fill_n(memory_.begin() + reg::kErrorCountersBegin, 0x0C, 0);
  if (clearLostLink) std::fill_n(memory_.begin() + reg::lostLinkCounter(0), 4, 0);
  if (overlaps(begin, end, reg::kConfiguredStationAddress.address,
               reg::kDlControl.address + 4 - reg::kConfiguredStationAddress.address)) {
    refreshAddressing();
  }
  hooks &= ~1u;  // WriteHook::kNone
  for (unsigned h = 1; hooks != 0 && h < static_cast<unsigned>(WriteHook::kCount); ++h) {
    if ((hooks & (1u << h)) == 0) continue;
    hooks &= ~(1u << h);
    runWriteHook(static_cast<WriteHook>(h), begin, end, data, smWasEnabled);
  }
  return accepted;
}

void Esc::runWriteHook(WriteHook hook, std::uint32_t begin, std::uint32_t end, ConstBytes data,
                       const std::array<bool, reg::kMaxSyncManagers>& smWasEnabled) {
  switch (hook) {
    case WriteHook::kNone:
    case WriteHook::kCount:
      break;
    case WriteHook::kReceiveTimeLatch:
      latchReceiveTimes();
      break;
    case WriteHook::kDlControl:
      events_.dlControlWritten = true;
      noteEvent();
      break;
    case WriteHook::kAlControl:
      ecatAlControlWritten();  // esc_events.cpp
      break;
    case WriteHook::kEcatEventMask:
      ecatEventMaskWritten();  // esc_events.cpp
      break;
    case WriteHook::kSiiCommand:
      // The command byte was written: execute it (write needs the enable bit in the same access).
      siiCommand(read(reg::kSiiControlStatus));
      break;
    case WriteHook::kMiiCommand:
      miiCommand();
      break;
    case WriteHook::kSystemTime:
      systemTimeWritten(begin, end, data);
      break;
    case WriteHook::kSpeedCounterStart:
      dc_.resetControl();
      break;
    case WriteHook::kCyclicUnitControl:
      latchEventsChanged();  // esc_latch.cpp
      break;
    case WriteHook::kDcActivation:
      onSyncActivationWrite();
      break;
    case WriteHook::kLatchControl:
      latchControlWritten();  // esc_latch.cpp
      break;
    case WriteHook::kFmmu:
      rebuildFmmuCache();
      break;
    case WriteHook::kSm:
      for (unsigned s = 0; s < type_.syncManagers; ++s) {
        const std::uint16_t base = reg::smChannel(s);
        if (smEnabledBit(s) != smWasEnabled[s]) smActivationChanged(s);
        if (overlaps(begin, end, base + reg::sm::kActivate.address, 1) &&
            (memory_[base + reg::sm::kActivate.address] & reg::sm::kActivateRepeatRequest) !=
                (memory_[base + reg::sm::kPdiControl.address] & reg::sm::kPdiRepeatAck)) {
          events_.mailboxRead = true;  // firmware sees the repeat request toggle
          noteEvent();
        }
      }
      rebuildSmCache();
      events_.smConfigChanged = true;
      noteEvent();
      break;
  }
}

std::uint32_t Esc::readHooks(std::uint32_t begin, std::uint32_t end) const {
  end = std::min<std::uint32_t>(end, kRamStart);
  std::uint64_t bits = 0;
  std::uint32_t a = begin;
  for (; a + 8 <= end; a += 8) {
    std::uint64_t eight = 0;
    std::memcpy(&eight, regs_.readHookBits.data() + a, 8);
    bits |= eight;
  }
  for (; a < end; ++a) bits |= regs_.readHookBits[a];
  bits |= bits >> 32;
  bits |= bits >> 16;
  bits |= bits >> 8;
  return static_cast<std::uint32_t>(bits & 0xFF) << 1;  // bit n = ReadHook n, as the callers test
}

void Esc::refreshVolatile(std::uint16_t begin, std::uint16_t end) {
  const std::uint32_t hooks = readHooks(begin, end);
  if (hooks == 0) return;
  if ((hooks & (1u << static_cast<unsigned>(ReadHook::kSyncUnit))) != 0) {
    refreshSyncRegisters(begin, end);
  }
  if ((hooks & (1u << static_cast<unsigned>(ReadHook::kEcatEventRequest))) != 0) {
    refreshEcatEvents();
  }
  if ((hooks & (1u << static_cast<unsigned>(ReadHook::kSii))) != 0) siiRefresh();
  if ((hooks & (1u << static_cast<unsigned>(ReadHook::kMii))) != 0) miiRefresh();
  if ((hooks & (1u << static_cast<unsigned>(ReadHook::kSystemTime))) != 0) {
    writeLe64(memory_, reg::kSystemTime.address,
              static_cast<std::uint64_t>(wrapAdd(localNow_, read(reg::kSystemTimeOffset))));
  }
}

void Esc::afterRegisterRead(std::uint32_t begin, std::uint32_t end) {
  const std::uint32_t hooks = readHooks(begin, end);
  std::uint16_t clear = 0;
  if ((hooks & (1u << static_cast<unsigned>(ReadHook::kDlStatusEvent))) != 0) {
    clear |= reg::ecat_event::kDlStatus;
  }
  if ((hooks & (1u << static_cast<unsigned>(ReadHook::kAlStatusEvent))) != 0) {
    clear |= reg::ecat_event::kAlStatus;
  }
  if (clear != 0) clearEcatEvents(clear);  // esc_events.cpp
  if ((hooks & (1u << static_cast<unsigned>(ReadHook::kLatchTime))) != 0) {
    latchTimesRead(begin, end);  // esc_latch.cpp
  }
}

bool Esc::pdiWriteRegisters(std::uint16_t address, ConstBytes data) {
  bool accepted = false;
  for (std::uint32_t i = 0; i < data.size() && address + i < kRamStart; ++i) {
    const std::uint32_t a = address + i;
    const std::uint8_t mask = regs_.pdiWriteMask[a];
    accepted |= mask != 0;
    memory_[a] = static_cast<std::uint8_t>((memory_[a] & ~mask) | (data[i] & mask));
  }
  refreshAddressing();
  return accepted;
}

void Esc::smActivationChanged(unsigned s) {
  SmState& st = sm_[s];
  st = {};
  std::uint16_t base = reg::smChannel(s);
  memory_[base + reg::sm::kStatus.address] = 0;
}

void Esc::completeReceiveTimeLatch(const std::array<SimTime, 4>& times, std::uint8_t portMask) {
  if (!latchArmed_) return;
  latchArmed_ = false;
  for (unsigned p = 0; p < 4; ++p) {
    if ((portMask & (1u << p)) != 0) {
      writeLe32(memory_, reg::receiveTime(p), static_cast<std::uint32_t>(dc_.localTime(times[p])));
    }
  }
  // 0x0918 latches when the frame's first bit reaches the processing unit, which a frame
  // enters from port 0: the same instant as port 0's receive time, wherever in the frame the
  // latching write was. Real EK1100 and EL2889 show both equal (../shared/pcap/replay-dc.pcapng
  // frames 504/506 and 512/514; soem-sdinfo-ek1100-el1004.pcapng frames 453/455).
  if ((portMask & 0x01) != 0) {
    writeLe64(memory_, reg::kReceiveTimeEcatProcessingUnit.address,
              static_cast<std::uint64_t>(dc_.localTime(times[0])));
  }
}

void Esc::latchReceiveTimes() {
  latchArmed_ = true;  // 0x0900-0x090F and 0x0918 are written once the frame has passed
  events_.dcLatched = true;
  noteEvent();
}

}  // namespace ecsim::slavesim
