#include "slavesim/esc_register_table.hpp"

#include <vector>

namespace ecsim::slavesim {
namespace {

// Row builders: `rw` = writable by the master (ECAT column "RW" in section II), `r` = read-only
// for the master. The PDI column likewise. Masks are per byte.
constexpr std::uint8_t kAll = 0xFF;
constexpr std::uint8_t kNone = 0x00;

template <typename T>
RegisterRow row(reg::Reg<T> r, std::uint8_t ecat, std::uint8_t pdi, std::uint64_t reset = 0,
                WriteHook write = WriteHook::kNone, ByteRule rule = ByteRule::kStore,
                ReadHook read = ReadHook::kNone) {
  return {r.address, r.width, ecat, pdi, reset, rule, write, read, r.name};
}
RegisterRow block(std::uint16_t address, std::uint16_t width, std::uint8_t ecat, std::uint8_t pdi,
                  std::string_view name, WriteHook write = WriteHook::kNone,
                  ByteRule rule = ByteRule::kStore, ReadHook read = ReadHook::kNone) {
  return {address, width, ecat, pdi, 0, rule, write, read, name};
}

std::vector<RegisterRow> buildRows() {
  using namespace reg;
  std::vector<RegisterRow> rows = {
      // ESC information (0x0000-0x000F): from the ESC type, read-only on both sides; reset()
      // fills them from EscType.
      block(kType.address, 0x0A, kNone, kNone, "ESC Information"),
      row(kConfiguredStationAddress, kAll, kNone),
      row(kConfiguredStationAlias, kNone, kAll),  // loaded from SII word 4; PDI may change it
      row(kRegisterWriteEnable, 0x01, kNone),
      row(kRegisterWriteProtection, 0x01, kNone),
      row(kEscWriteEnable, 0x01, kNone),
      row(kEscWriteProtection, 0x01, kNone),
      row(kEscResetEcat, kAll, kNone),
      row(kEscResetPdi, kNone, kAll),
      // Data link layer
      row(kDlControl, kAll, kNone, dl_control::kResetValue, WriteHook::kDlControl),
      row(kPhysicalRwOffset, kAll, kNone),
      row(kDlStatus, kNone, kNone, 0, WriteHook::kNone, ByteRule::kStore,
          ReadHook::kDlStatusEvent),
      // Application layer: AL control is the master's, AL status the firmware's.
      row(kAlControl, kAll, kNone, 0x0001, WriteHook::kAlControl, ByteRule::kAlControlMailbox),
      row(kAlStatus, kNone, kAll, 0x0001, WriteHook::kNone, ByteRule::kStore,
          ReadHook::kAlStatusEvent),
      row(kAlStatusCode, kNone, kAll),
      row(kRunLedOverride, kAll, kNone),
      row(kErrLedOverride, kAll, kNone),
      // PDI: loaded from the SII at power-on (esc_sii.cpp)
      row(kPdiControl, kNone, kNone),
      row(kEscConfiguration, kNone, kNone),
      row(kPdiInformation, kNone, kNone),
      block(kPdiConfiguration.address, 4, kNone, kNone, "PDI Configuration"),
      // Interrupts
      row(kEcatEventMask, kAll, kNone, 0, WriteHook::kEcatEventMask),
      row(kPdiAlEventMask, kNone, kAll),
      row(kEcatEventRequest, kNone, kNone, ecat_event::kResetValue, WriteHook::kNone,
          ByteRule::kStore, ReadHook::kEcatEventRequest),
      row(kAlEventRequest, kNone, kNone),
      // Error counters (section II 0x0300-0x0313): cleared by a write of any value.
      block(kErrorCountersBegin, 0x0C, kAll, kNone, "RX Error Counters", WriteHook::kNone,
            ByteRule::kClearRxErrors),
      block(kEcatProcessingUnitErrorCounter.address, 4, kAll, kNone, "Error Counters",
            WriteHook::kNone, ByteRule::kClearOnWrite),
      block(lostLinkCounter(0), 4, kAll, kNone, "Lost Link Counters", WriteHook::kNone,
            ByteRule::kClearLostLink),
      // Watchdogs (reset values from section II: 2498 -> 100 us units, 1000 -> 100 ms)
      row(kWatchdogDivider, kAll, kNone, 0x09C2),
      row(kWatchdogTimePdi, kAll, kNone, 0x03E8),
      row(kWatchdogTimeProcessData, kAll, kNone, 0x03E8),
      row(kWatchdogStatusProcessData, kNone, kNone),
      row(kWatchdogCounterProcessData, kAll, kNone, 0, WriteHook::kNone, ByteRule::kClearOnWrite),
      row(kWatchdogCounterPdi, kAll, kNone, 0, WriteHook::kNone, ByteRule::kClearOnWrite),
      // SII EEPROM interface (the PDI columns apply while the PDI owns the EEPROM, 0x0500)
      row(kSiiConfiguration, 0x03, kNone),
      row(kSiiPdiAccessState, kNone, 0x01),
      // While a command runs (busy, 0x0502 bit 15) the master cannot change control, address
      // or data (kSiiLocked); reads complete a command whose time is over (esc_sii.cpp).
      block(kSiiControlStatus.address, 1, 0x01, 0x01, "EEPROM Control/Status (write enable)",
            WriteHook::kNone, ByteRule::kSiiLocked, ReadHook::kSii),
      block(kSiiControlStatus.address + 1, 1, 0x07, 0x07, "EEPROM Control/Status (command)",
            WriteHook::kSiiCommand, ByteRule::kSiiLocked, ReadHook::kSii),
      row(kSiiAddress, kAll, kAll, 0, WriteHook::kNone, ByteRule::kSiiLocked, ReadHook::kSii),
      block(kSiiData.address, kSiiData.width, kAll, kAll, kSiiData.name, WriteHook::kNone,
            ByteRule::kSiiLocked, ReadHook::kSii),
      // MII management interface (esc_mii.cpp): write enable (bit 0) and command (bits 8-9)
      // for the master, the rest of 0x0510 is the ESC's; PHY and register address 5 bits each.
      // Refused while busy or while the PDI has the interface (kMiiLocked).
      block(kMiiControlStatus.address, 1, 0x01, kAll, "MII Control/Status (write enable)",
            WriteHook::kNone, ByteRule::kMiiLocked, ReadHook::kMii),
      block(kMiiControlStatus.address + 1, 1, 0x03, kAll, "MII Control/Status (command)",
            WriteHook::kMiiCommand, ByteRule::kMiiLocked, ReadHook::kMii),
      row(kPhyAddress, 0x1F, kAll, 0, WriteHook::kNone, ByteRule::kMiiLocked),
      row(kPhyRegisterAddress, 0x1F, kAll, 0, WriteHook::kNone, ByteRule::kMiiLocked),
      row(kPhyData, kAll, kAll, 0, WriteHook::kNone, ByteRule::kMiiLocked, ReadHook::kMii),
      row(kMiiEcatAccessState, 0x01, kNone),
      row(kMiiPdiAccessState, kNone, 0x01),
  };
  // FMMU channels: master-owned configuration
  rows.push_back(block(kFmmuBase, static_cast<std::uint16_t>(kFmmuSize * kMaxFmmus), kAll, kNone,
                       "FMMU channels", WriteHook::kFmmu));
  // SyncManager channels: start, length, control writable only while disabled; the status is
  // the ESC's; activate (enable, repeat request, latch bits); PDI control is the firmware's.
  for (unsigned n = 0; n < kMaxSyncManagers; ++n) {
    const std::uint16_t base = smChannel(n);
    rows.push_back(block(base, 5, kAll, kNone, "SyncManager configuration", WriteHook::kSm,
                         ByteRule::kSmLocked));
    rows.push_back(block(static_cast<std::uint16_t>(base + sm::kStatus.address), 1, kNone, kNone,
                         "SyncManager status"));
    rows.push_back(block(static_cast<std::uint16_t>(base + sm::kActivate.address), 1, 0xC3, kNone,
                         "SyncManager activate", WriteHook::kSm));
    rows.push_back(block(static_cast<std::uint16_t>(base + sm::kPdiControl.address), 1, kNone,
                         sm::kPdiDeactivate | sm::kPdiRepeatAck, "SyncManager PDI control"));
  }
  const std::vector<RegisterRow> dc = {
      // Distributed clocks (section II 0x0900-0x09FF)
      // A write to 0x0900 latches; the whole register accepts the write, none stores it.
      block(kReceiveTimePort0.address, 1, kAll, kNone, kReceiveTimePort0.name,
            WriteHook::kReceiveTimeLatch, ByteRule::kNoStore),
      block(kReceiveTimePort0.address + 1, 3, kAll, kNone, kReceiveTimePort0.name, WriteHook::kNone,
            ByteRule::kNoStore),
      block(kReceiveTimePort1.address, 12, kNone, kNone, "Receive Times Ports 1-3"),
      row(kSystemTime, kAll, kAll, 0, WriteHook::kSystemTime, ByteRule::kStore,
          ReadHook::kSystemTime),
      row(kReceiveTimeEcatProcessingUnit, kNone, kNone),
      row(kSystemTimeOffset, kAll, kAll),
      row(kSystemTimeDelay, kAll, kAll),
      row(kSystemTimeDifference, kNone, kNone),
      row(kSpeedCounterStart, kAll, kAll, 0x1000, WriteHook::kSpeedCounterStart),
      row(kSpeedCounterDiff, kNone, kNone),
      row(kSystemTimeDifferenceFilterDepth, kAll, kAll, 0x04),
      row(kSpeedCounterFilterDepth, kAll, kAll, 0x0C),
      row(kReceiveTimeLatchMode, kAll, kNone),
      row(kCyclicUnitControl, kAll, kNone, 0, WriteHook::kCyclicUnitControl, ByteRule::kStore,
          ReadHook::kSyncUnit),
      row(kDcActivation, kAll, kAll, 0, WriteHook::kDcActivation, ByteRule::kStore,
          ReadHook::kSyncUnit),
      block(kSyncPulseLength.address, 0x0990 - 0x0982, kNone, kNone, "SYNC status",
            WriteHook::kNone, ByteRule::kStore, ReadHook::kSyncUnit),
      row(kStartTimeCyclicOperation, kAll, kAll, 0, WriteHook::kNone, ByteRule::kStore,
          ReadHook::kSyncUnit),
      row(kNextSync1Pulse, kNone, kNone, 0, WriteHook::kNone, ByteRule::kStore,
          ReadHook::kSyncUnit),
      block(kSync0CycleTime.address, 8, kAll, kAll, "SYNC0/SYNC1 Cycle Time", WriteHook::kNone,
            ByteRule::kStore, ReadHook::kSyncUnit),
      // DC latch unit (esc_latch.cpp): control written by the unit's owner (0x0980 bits 4/5;
      // bits 2-7 reserved), status and times the ESC's; the owner's read of a time clears.
      block(kLatch0Control.address, 2, latch::kControlMask, latch::kControlMask, "Latch Control",
            WriteHook::kLatchControl, ByteRule::kLatchOwned),
      block(kLatch0Status.address, 2, kNone, kNone, "Latch Status"),
      block(kLatch0TimePositiveEdge.address, 32, kNone, kNone, "Latch Times", WriteHook::kNone,
            ByteRule::kStore, ReadHook::kLatchTime),
      block(kEcatBufferChangeEventTime.address, 16, kNone, kNone, "Buffer Change Event Times"),
      // ESC specific
      row(kDigitalIoOutputData, kAll, kNone),
      row(kGeneralPurposeOutputs, kAll, kAll),
      row(kGeneralPurposeInputs, kNone, kNone),
      block(kUserRam.address, kUserRam.width, kAll, kAll, kUserRam.name),
  };
  rows.insert(rows.end(), dc.begin(), dc.end());
  return rows;
}

}  // namespace

std::span<const RegisterRow> escRegisterRows() {
  static const std::vector<RegisterRow> rows = buildRows();
  return rows;
}

const RegisterBytes& escRegisterBytes() {
  static const RegisterBytes bytes = [] {
    RegisterBytes b;
    for (const RegisterRow& r : escRegisterRows()) {
      for (std::uint32_t i = 0; i < r.width; ++i) {
        const std::uint32_t a = r.address + i;
        b.ecatWriteMask[a] = r.ecatWriteMask;
        b.pdiWriteMask[a] = r.pdiWriteMask;
        b.reset[a] = static_cast<std::uint8_t>(i < 8 ? r.reset >> (8 * i) : 0);
        b.rule[a] = r.rule;
        b.write[a] = r.write;
        if (r.read != ReadHook::kNone)
          b.readHookBits[a] = static_cast<std::uint8_t>(1u << (static_cast<unsigned>(r.read) - 1));
      }
    }
    return b;
  }();
  return bytes;
}

}  // namespace ecsim::slavesim
