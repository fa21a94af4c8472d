// The ESC's two repeated configuration blocks as value types: a SyncManager channel (8 bytes
// at 0x0800 + 8n) and an FMMU channel (16 bytes at 0x0600 + 16n), ESC datasheet section II
// ("SyncManager" and "FMMU" register descriptions) and ETG.1000.4 (FMMU / SyncManager
// attributes). The master encodes with emit(), the simulated ESC decodes with parse(); no other
// code takes these bytes apart.
//
// Every bit survives a round trip: bits the datasheet reserves are kept in `reserved` fields,
// so parse(b).emit() gives b back for any bytes (tests/protocol/esc_blocks_test.cpp, fuzzed by
// tests/fuzz/fuzz_esc_blocks.cpp).
#pragma once

#include <array>
#include <cstdint>

#include "protocol/bytes.hpp"
#include "protocol/registers.hpp"
#include "protocol/result.hpp"

namespace ecsim {

// SyncManager control register 0x0804, bits 1:0.
enum class SmMode : std::uint8_t { kBuffered = 0, kReserved1 = 1, kMailbox = 2, kReserved3 = 3 };
// Bits 3:2: the direction seen from the EtherCAT side.
enum class SmDirection : std::uint8_t {
  kEcatRead = 0,  // inputs / mailbox slave->master
  kEcatWrite = 1, // outputs / mailbox master->slave
  kReserved2 = 2,
  kReserved3 = 3,
};

struct SmControl {  // 0x0804
  SmMode mode{SmMode::kBuffered};
  SmDirection direction{SmDirection::kEcatRead};
  bool ecatEvent{false};        // bit 4: interrupt in ECAT event request register
  bool pdiEvent{false};         // bit 5: interrupt in AL event request register
  bool watchdogTrigger{false};  // bit 6
  std::uint8_t reserved{0};     // bit 7, as read

  static SmControl decode(std::uint8_t byte);
  std::uint8_t encode() const;
  bool isMailbox() const { return mode == SmMode::kMailbox; }
  bool isEcatWrite() const { return direction == SmDirection::kEcatWrite; }
  bool operator==(const SmControl&) const = default;
};

struct SmStatus {  // 0x0805 (maintained by the ESC; read-only for ECAT and PDI)
  bool interruptWrite{false};
  bool interruptRead{false};
  bool mailboxFull{false};       // 1-buffer mode
  std::uint8_t lastBuffer{0};    // 3-buffer mode, bits 5:4: 0-2 buffer, 3 none written yet
  bool readBufferOpen{false};
  bool writeBufferOpen{false};
  std::uint8_t reserved{0};      // bit 2, as read

  static SmStatus decode(std::uint8_t byte);
  std::uint8_t encode() const;
  bool operator==(const SmStatus&) const = default;
};

struct SmActivate {  // 0x0806 (ECAT writes it)
  bool enable{false};
  bool repeatRequest{false};
  bool latchEcat{false};  // bit 6: latch event on ECAT change
  bool latchPdi{false};   // bit 7: latch event on PDI change
  std::uint8_t reserved{0};  // bits 5:2, as read

  static SmActivate decode(std::uint8_t byte);
  std::uint8_t encode() const;
  bool operator==(const SmActivate&) const = default;
};

struct SmPdiControl {  // 0x0807 (the PDI writes it)
  bool deactivate{false};
  bool repeatAck{false};
  std::uint8_t reserved{0};  // bits 7:2, as read

  static SmPdiControl decode(std::uint8_t byte);
  std::uint8_t encode() const;
  bool operator==(const SmPdiControl&) const = default;
};

struct SyncManagerBlock {
  std::uint16_t start{0};   // physical start address
  std::uint16_t length{0};  // bytes
  SmControl control{};
  SmStatus status{};
  SmActivate activate{};
  SmPdiControl pdiControl{};

  // Fails only when fewer than reg::kSmSize bytes are given (extra bytes are ignored).
  static Result<SyncManagerBlock> parse(ConstBytes bytes);
  // Writes the reg::kSmSize bytes of the channel to the start of `out` (which must hold them).
  void emit(Bytes out) const;
  std::array<std::uint8_t, reg::kSmSize> bytes() const;
  bool operator==(const SyncManagerBlock&) const = default;
};

struct FmmuBlock {
  std::uint32_t logicalStart{0};
  std::uint16_t length{0};          // bytes spanned in the logical address space
  std::uint8_t logicalStartBit{0};  // bits 2:0 used (reg::fmmu::kBitMask), the rest kept
  std::uint8_t logicalStopBit{7};
  std::uint16_t physicalStart{0};
  std::uint8_t physicalStartBit{0};
  bool read{false};   // type bit 0: mapping used for read access (inputs)
  bool write{false};  // type bit 1: mapping used for write access (outputs)
  std::uint8_t typeReserved{0};      // type bits 7:2, as read
  bool enable{false};                // activate bit 0
  std::uint8_t activateReserved{0};  // activate bits 7:1, as read
  std::array<std::uint8_t, 3> reserved{};  // 0x0D-0x0F

  // Fails only when fewer than reg::kFmmuSize bytes are given (extra bytes are ignored).
  static Result<FmmuBlock> parse(ConstBytes bytes);
  void emit(Bytes out) const;
  std::array<std::uint8_t, reg::kFmmuSize> bytes() const;
  bool operator==(const FmmuBlock&) const = default;
};

}  // namespace ecsim
