// The ESC's register behaviour as data: one row per register (or register block) of the
// 0x0000-0x0FFF space with its ECAT and PDI write masks, reset value, how a write of its bytes
// is stored, and the hooks that run when it is written or read (ESC datasheet section II, the
// "ECAT"/"PDI" access columns and the register descriptions). Every access of the ECAT side
// goes through it (esc_registers.cpp); a new register behaviour is a row and, where it has side
// effects, a hook: not a new branch in the datagram path.
//
// Rows are expanded once into per-byte arrays (RegisterBytes) shared by every ESC: the tables
// stay hot in the cache when a frame passes a thousand ESCs. Registers of FMMU/SM channels a
// given ESC type does not have, and of a DC unit it lacks, are left to Esc::implemented().
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string_view>

#include "protocol/registers.hpp"

namespace ecsim::slavesim {

// How an ECAT write stores a register byte (bits outside the ECAT write mask never change).
enum class ByteRule : std::uint8_t {
  kStore,          // masked merge of the written value
  kClearOnWrite,   // a write of any value clears the byte (section II 0x030C-0x030F, 0x0442)
  kClearRxErrors,  // a write to any byte of 0x0300-0x030B clears all twelve (section II 0x0300)
  kClearLostLink,  // a write to any byte of 0x0310-0x0313 clears all four
  kNoStore,        // the write has an effect (hook), the content does not change (0x0900)
  kSmLocked,       // SM channel bytes 0-4: writable only while the SM is disabled (section II)
  kAlControlMailbox,  // 0x0120: without device emulation refused (no WKC) until the PDI read
                      // the last value (section II 0x0120 note; Esc::ecatAlControlWritable)
  kSiiLocked,      // 0x0502-0x050F: not while the EEPROM interface is busy (esc_sii.cpp)
  kMiiLocked,      // 0x0510-0x0515: not while MII management is busy or the PDI's (esc_mii.cpp)
  kLatchOwned,     // 0x09A8/0x09A9: read-only for ECAT while 0x0980 gives the unit to the PDI
};

// Side effects of an ECAT write, run once per access after all bytes are stored, in this order.
enum class WriteHook : std::uint8_t {
  kNone,
  kReceiveTimeLatch,   // 0x0900: latch the port receive times of this frame (section I §9.1.2)
  kDlControl,          // 0x0100-0x0103: port loop settings may change
  kAlControl,          // 0x0120: AL control event 0x0220 bit 0; device emulation copies it
                       // into AL status (esc_events.cpp)
  kEcatEventMask,      // 0x0200: which ECAT events go into the datagrams' IRQ field
  kSiiCommand,         // 0x0503: execute the EEPROM command (section II 0x0502)
  kMiiCommand,         // 0x0511: start an MII management command (section II 0x0510)
  kSystemTime,         // 0x0910-0x0917: one step of the drift control loop, 0x092C
  kSpeedCounterStart,  // 0x0930: reset of the drift control loop
  kCyclicUnitControl,  // 0x0980: latch units' owner (esc_latch.cpp)
  kDcActivation,       // 0x0981: cyclic unit activation
  kLatchControl,       // 0x09A8/0x09A9: single or continuous latch mode (esc_latch.cpp)
  kFmmu,               // 0x0600-0x06FF: rebuild the active FMMU cache
  kSm,                 // 0x0800-0x087F: SM activation, repeat request, SM cache
  kCount
};

// Refresh of volatile registers before an ECAT read of them.
enum class ReadHook : std::uint8_t {
  kNone,
  kSystemTime,  // 0x0910: the local copy of the system time at this instant
  kSyncUnit,    // 0x0980-0x09A7: cyclic unit status and next pulse times (esc_time_units.cpp)
  kEcatEventRequest,  // 0x0210: SyncManager and latch bits follow their status (esc_events.cpp)
  // Clear-on-read, after the read (Esc::afterRegisterRead): the ECAT event bit of the register.
  kDlStatusEvent,  // 0x0110: clears 0x0210 bit 2
  kAlStatusEvent,  // 0x0130: clears 0x0210 bit 3
  kSii,         // 0x0502-0x050F: a command whose busy time is over completes (esc_sii.cpp)
  kMii,         // 0x0510-0x0515: likewise for MII management (esc_mii.cpp)
  kLatchTime,   // 0x09B0-0x09CF: the owner's read clears the latch event (esc_latch.cpp)
  kCount
};

struct RegisterRow {
  std::uint16_t address;
  std::uint16_t width;
  std::uint8_t ecatWriteMask;  // per byte; 0 = read-only for the master
  std::uint8_t pdiWriteMask;   // per byte; 0 = read-only for the firmware
  std::uint64_t reset;         // little-endian, first min(width, 8) bytes; rest 0
  ByteRule rule;
  WriteHook write;
  ReadHook read;
  std::string_view name;
};

// The rows, in address order (non-overlapping; bytes not covered read as 0 and are read-only).
std::span<const RegisterRow> escRegisterRows();

// The rows expanded to one entry per register byte.
struct RegisterBytes {
  std::array<std::uint8_t, reg::kRegisterSpaceEnd> ecatWriteMask{};
  std::array<std::uint8_t, reg::kRegisterSpaceEnd> pdiWriteMask{};
  std::array<std::uint8_t, reg::kRegisterSpaceEnd> reset{};
  std::array<ByteRule, reg::kRegisterSpaceEnd> rule{};
  std::array<WriteHook, reg::kRegisterSpaceEnd> write{};
  // Read hooks as a bit set per byte (bit h - 1 = ReadHook h), so the hooks of a range are the
  // OR of its bytes, taken 8 at a time (Esc::readHooks; every ECAT register read asks).
  std::array<std::uint8_t, reg::kRegisterSpaceEnd> readHookBits{};
};
static_assert(static_cast<unsigned>(ReadHook::kCount) <= 9, "read hooks must fit readHookBits");
const RegisterBytes& escRegisterBytes();

}  // namespace ecsim::slavesim
