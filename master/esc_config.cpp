#include "master/esc_config.hpp"

#include <array>

namespace ecsim::master {

SyncManagerBlock syncManagerChannel(std::uint16_t start, std::uint16_t length, std::uint8_t control,
                                    bool enable) {
  SyncManagerBlock sm;
  sm.start = start;
  sm.length = length;
  sm.control = SmControl::decode(control);
  sm.activate.enable = enable;
  return sm;
}

void addMailboxSetup(DatagramBatch& batch, const SlaveInfo& slave) {
  if (!slave.mailbox) return;
  const MailboxConfig& m = *slave.mailbox;
  // Both off first: an SM left enabled (the bootstrap layout after BOOT, another master's)
  // would keep its start, length and control and ignore the new ones.
  const std::array<std::uint8_t, 2 * reg::kSmSize> off{};
  batch.add().fpwr(slave.station, reg::smChannel(0), off);
  std::array<std::uint8_t, 2 * reg::kSmSize> both{};
  syncManagerChannel(m.outStart, m.outSize, m.outControl, true).emit(both);
  syncManagerChannel(m.inStart, m.inSize, m.inControl, true)
      .emit(Bytes(both).subspan(reg::kSmSize));
  batch.add().fpwr(slave.station, reg::smChannel(0), both);
}

}  // namespace ecsim::master
