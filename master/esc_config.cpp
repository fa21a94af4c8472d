#include "master/esc_config.hpp"

namespace ecsim::master {

std::array<std::uint8_t, reg::kSmSize> encodeSyncManager(const SyncManagerSetting& sm) {
  std::array<std::uint8_t, reg::kSmSize> b{};
  writeLe16(b, reg::sm::kPhysicalStart.address, sm.start);
  writeLe16(b, reg::sm::kLength.address, sm.length);
  b[reg::sm::kControl.address] = sm.control;
  b[reg::sm::kActivate.address] = sm.enable ? reg::sm::kActivateEnable : 0;
  return b;
}

std::array<std::uint8_t, reg::kFmmuSize> encodeFmmu(const FmmuSetting& f) {
  std::array<std::uint8_t, reg::kFmmuSize> b{};
  writeLe32(b, reg::fmmu::kLogicalStart.address, f.logicalStart);
  writeLe16(b, reg::fmmu::kLength.address, f.length);
  b[reg::fmmu::kLogicalStartBit.address] = f.logicalStartBit;
  b[reg::fmmu::kLogicalStopBit.address] = f.logicalStopBit;
  writeLe16(b, reg::fmmu::kPhysicalStart.address, f.physicalStart);
  b[reg::fmmu::kPhysicalStartBit.address] = f.physicalStartBit;
  b[reg::fmmu::kType.address] = f.type;
  b[reg::fmmu::kActivate.address] = f.enable ? 1 : 0;
  return b;
}

void addMailboxSetup(DatagramBatch& batch, const SlaveInfo& slave) {
  if (!slave.mailbox) return;
  const MailboxConfig& m = *slave.mailbox;
  std::array<std::uint8_t, 2 * reg::kSmSize> both{};
  const auto sm0 = encodeSyncManager({m.outStart, m.outSize, m.outControl, true});
  const auto sm1 = encodeSyncManager({m.inStart, m.inSize, m.inControl, true});
  std::copy(sm0.begin(), sm0.end(), both.begin());
  std::copy(sm1.begin(), sm1.end(), both.begin() + reg::kSmSize);
  batch.add().fpwr(slave.station, reg::smChannel(0), both);
}

}  // namespace ecsim::master
