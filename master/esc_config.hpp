// Register images the master writes to configure an ESC (ESC datasheet section II, 0x0600
// FMMU and 0x0800 SyncManager channels; field offsets from protocol/registers.hpp), and the
// batches that write them.
#pragma once

#include <array>
#include <cstdint>

#include "master/batch.hpp"
#include "master/slave_info.hpp"
#include "protocol/registers.hpp"

namespace ecsim::master {

struct SyncManagerSetting {
  std::uint16_t start{0};
  std::uint16_t length{0};
  std::uint8_t control{0};
  bool enable{false};
  bool operator==(const SyncManagerSetting&) const = default;
};

struct FmmuSetting {
  std::uint32_t logicalStart{0};
  std::uint16_t length{0};
  std::uint8_t logicalStartBit{0};
  std::uint8_t logicalStopBit{7};
  std::uint16_t physicalStart{0};
  std::uint8_t physicalStartBit{0};
  std::uint8_t type{0};  // reg::fmmu::kTypeRead (inputs) / kTypeWrite (outputs)
  bool enable{true};
  bool operator==(const FmmuSetting&) const = default;
};

std::array<std::uint8_t, reg::kSmSize> encodeSyncManager(const SyncManagerSetting& sm);
std::array<std::uint8_t, reg::kFmmuSize> encodeFmmu(const FmmuSetting& fmmu);

// SM0 and SM1 of a mailbox slave, from its SII (one 16-byte FPWR, as SOEM writes them).
// Does nothing for a slave without mailbox.
void addMailboxSetup(DatagramBatch& batch, const SlaveInfo& slave);

}  // namespace ecsim::master
