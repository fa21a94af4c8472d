#include "protocol/registers.hpp"

namespace ecsim::reg {
namespace {

template <typename T>
constexpr RegisterInfo info(const Reg<T>& r) {
  return {r.address, Reg<T>::width, r.name};
}
constexpr RegisterInfo info(const Block& b) {
  return {b.address, b.width, b.name};
}

constexpr auto kTable = std::to_array<RegisterInfo>({
    info(kType),
    info(kRevision),
    info(kBuild),
    info(kFmmusSupported),
    info(kSyncManagersSupported),
    info(kRamSize),
    info(kPortDescriptor),
    info(kEscFeatures),
    info(kConfiguredStationAddress),
    info(kConfiguredStationAlias),
    info(kRegisterWriteEnable),
    info(kRegisterWriteProtection),
    info(kEscWriteEnable),
    info(kEscWriteProtection),
    info(kEscResetEcat),
    info(kEscResetPdi),
    info(kDlControl),
    info(kPhysicalRwOffset),
    info(kDlStatus),
    info(kAlControl),
    info(kAlStatus),
    info(kAlStatusCode),
    info(kRunLedOverride),
    info(kErrLedOverride),
    info(kPdiControl),
    info(kEscConfiguration),
    info(kPdiInformation),
    info(kPdiConfiguration),
    info(kSyncLatchPdiConfiguration),
    info(kExtendedPdiConfiguration),
    info(kEcatEventMask),
    info(kPdiAlEventMask),
    info(kEcatEventRequest),
    info(kAlEventRequest),
    RegisterInfo{0x0300, 1, "Invalid Frame Counter of Port 0"},
    RegisterInfo{0x0301, 1, "RX Error Counter of Port 0"},
    RegisterInfo{0x0302, 1, "Invalid Frame Counter of Port 1"},
    RegisterInfo{0x0303, 1, "RX Error Counter of Port 1"},
    RegisterInfo{0x0304, 1, "Invalid Frame Counter of Port 2"},
    RegisterInfo{0x0305, 1, "RX Error Counter of Port 2"},
    RegisterInfo{0x0306, 1, "Invalid Frame Counter of Port 3"},
    RegisterInfo{0x0307, 1, "RX Error Counter of Port 3"},
    RegisterInfo{0x0308, 1, "Forwarded RX Error Counter Port 0"},
    RegisterInfo{0x0309, 1, "Forwarded RX Error Counter Port 1"},
    RegisterInfo{0x030A, 1, "Forwarded RX Error Counter Port 2"},
    RegisterInfo{0x030B, 1, "Forwarded RX Error Counter Port 3"},
    info(kEcatProcessingUnitErrorCounter),
    info(kPdiErrorCounter),
    info(kPdiErrorCode),
    RegisterInfo{0x0310, 1, "Lost Link Counter Port 0"},
    RegisterInfo{0x0311, 1, "Lost Link Counter Port 1"},
    RegisterInfo{0x0312, 1, "Lost Link Counter Port 2"},
    RegisterInfo{0x0313, 1, "Lost Link Counter Port 3"},
    info(kWatchdogDivider),
    info(kWatchdogTimePdi),
    info(kWatchdogTimeProcessData),
    info(kWatchdogStatusProcessData),
    info(kWatchdogCounterProcessData),
    info(kWatchdogCounterPdi),
    info(kSiiConfiguration),
    info(kSiiPdiAccessState),
    info(kSiiControlStatus),
    info(kSiiAddress),
    info(kSiiData),
    info(kMiiControlStatus),
    info(kPhyAddress),
    info(kPhyRegisterAddress),
    info(kPhyData),
    info(kMiiEcatAccessState),
    info(kMiiPdiAccessState),
    info(kReceiveTimePort0),
    info(kReceiveTimePort1),
    info(kReceiveTimePort2),
    info(kReceiveTimePort3),
    info(kSystemTime),
    info(kReceiveTimeEcatProcessingUnit),
    info(kSystemTimeOffset),
    info(kSystemTimeDelay),
    info(kSystemTimeDifference),
    info(kSpeedCounterStart),
    info(kSpeedCounterDiff),
    info(kSystemTimeDifferenceFilterDepth),
    info(kSpeedCounterFilterDepth),
    info(kReceiveTimeLatchMode),
    info(kCyclicUnitControl),
    info(kDcActivation),
    info(kSyncPulseLength),
    info(kDcActivationStatus),
    info(kSync0Status),
    info(kSync1Status),
    info(kStartTimeCyclicOperation),
    info(kNextSync1Pulse),
    info(kSync0CycleTime),
    info(kSync1CycleTime),
    info(kLatch0Control),
    info(kLatch1Control),
    info(kLatch0Status),
    info(kLatch1Status),
    info(kLatch0TimePositiveEdge),
    info(kLatch0TimeNegativeEdge),
    info(kLatch1TimePositiveEdge),
    info(kLatch1TimeNegativeEdge),
    info(kEcatBufferChangeEventTime),
    info(kPdiBufferStartEventTime),
    info(kPdiBufferChangeEventTime),
    info(kDigitalIoOutputData),
    info(kGeneralPurposeOutputs),
    info(kGeneralPurposeInputs),
    info(kUserRam),
});

constexpr bool sortedAndDisjoint() {
  for (std::size_t i = 1; i < kTable.size(); ++i) {
    if (kTable[i - 1].address + kTable[i - 1].width > kTable[i].address) return false;
  }
  return true;
}
static_assert(sortedAndDisjoint(), "register table must be sorted and non-overlapping");

constexpr std::array<RegisterInfo, 9> kFmmuFields{{
    info(fmmu::kLogicalStart),
    info(fmmu::kLength),
    info(fmmu::kLogicalStartBit),
    info(fmmu::kLogicalStopBit),
    info(fmmu::kPhysicalStart),
    info(fmmu::kPhysicalStartBit),
    info(fmmu::kType),
    info(fmmu::kActivate),
    RegisterInfo{0xD, 3, "Reserved"},
}};
constexpr std::array<RegisterInfo, 6> kSmFields{{
    info(sm::kPhysicalStart),
    info(sm::kLength),
    info(sm::kControl),
    info(sm::kStatus),
    info(sm::kActivate),
    info(sm::kPdiControl),
}};

}  // namespace

std::span<const RegisterInfo> registerTable() {
  return kTable;
}

std::optional<RegisterInfo> findRegister(std::uint16_t address) {
  auto inBlock = [&](std::uint16_t base, std::uint16_t size, unsigned count,
                     std::span<const RegisterInfo> fields) -> std::optional<RegisterInfo> {
    if (address < base || address >= base + size * count) return std::nullopt;
    auto channelBase = static_cast<std::uint16_t>(base + (address - base) / size * size);
    auto offset = static_cast<std::uint16_t>(address - channelBase);
    for (const auto& f : fields) {
      if (offset >= f.address && offset < f.address + f.width) {
        return RegisterInfo{static_cast<std::uint16_t>(channelBase + f.address), f.width, f.name};
      }
    }
    return std::nullopt;
  };
  if (auto r = inBlock(kFmmuBase, kFmmuSize, kMaxFmmus, kFmmuFields)) return r;
  if (auto r = inBlock(kSmBase, kSmSize, kMaxSyncManagers, kSmFields)) return r;
  for (const auto& r : kTable) {
    if (address >= r.address && address < r.address + r.width) return r;
  }
  return std::nullopt;
}

}  // namespace ecsim::reg
