// Parameters of the EtherCAT Slave Controller models the simulator offers. Values are those the
// ESC datasheets give for the register file (section II) and memory (section III).
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

namespace ecsim::slavesim {

enum class EscKind : std::uint8_t { kEt1100, kEt1200, kLan9252 };

struct EscType {
  EscKind kind;
  std::string_view name;
  std::uint8_t typeRegister;      // 0x0000
  std::uint8_t revisionRegister;  // 0x0001
  std::uint16_t build;            // 0x0002
  std::uint8_t fmmus;             // 0x0004
  std::uint8_t syncManagers;      // 0x0005
  std::uint8_t ramKb;             // 0x0006, process RAM in KB from 0x1000
  std::uint16_t features;         // 0x0008
  bool siiRead8Bytes;             // 0x0502 bit 6
  std::uint8_t maxPorts;
  // Forwarding delay through one ESC in ns, used by the timing model; see docs/timing.md.
  std::uint16_t processingDelayNs;
  std::uint16_t forwardingDelayNs;
};

// ET1100: 8 FMMUs, 8 SMs, 8 KB process RAM, 4 ports, 64-bit DC (section II "ESC Features"
// 0x01FC as SOEM sees it on real ET1100 terminals, notes/soem-interop.md §3.2). 8-byte SII
// reads: a real EK1100 reports 0x0502 bit 6 set (../shared/pcap/replay-dc.pcapng frame 102).
inline constexpr EscType kEt1100{EscKind::kEt1100, "ET1100", 0x11, 0x00, 0x0002, 8, 8, 8,
                                 0x01FC,           true,     4,    1000, 1000};
// ET1200: 3 FMMUs, 4 SMs, 1 KB process RAM, up to 3 ports (datasheet section III ET1200);
// real EL2828/EL2889 terminals answer only for FMMU0-2 and SM0-3 and report 8-byte SII reads
// (replay-dc.pcapng).
inline constexpr EscType kEt1200{EscKind::kEt1200, "ET1200", 0x12, 0x00, 0x0001, 3, 4, 1,
                                 0x01FC,           true,     3,    1000, 1000};
// LAN9252 (Microchip): 3 FMMUs, 4 SMs, 4 KB process RAM, 2 ports, 64-bit DC.
inline constexpr EscType kLan9252{
    EscKind::kLan9252, "LAN9252", 0xC0, 0x01, 0x0001, 3, 4, 4, 0x01FC, true, 2, 1000, 1000};

std::optional<EscType> escTypeByName(std::string_view name);

}  // namespace ecsim::slavesim
