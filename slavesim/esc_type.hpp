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
  // Delay of one passage through the ESC in ns, used by the timing model (docs/timing.md):
  // through the processing unit (entered at port 0) and alongside it (any other port). The
  // default is that of the port kind the ESC's devices typically have (see below).
  std::uint16_t processingDelayNs;
  std::uint16_t forwardingDelayNs;
  // How long the SII EEPROM interface stays busy after a read, write or reload command
  // (0x0502 bit 15 and the command bits held; section I §11.2): the I2C transfer time of the
  // device's EEPROM, so a property of the device more than of the ESC chip.
  std::uint32_t siiBusyNs;
};

// Passage delays by port kind (docs/timing.md, "ESC delays", for the derivations).
// 100BASE-TX (MII port + PHY on both sides): "approx. 1 us per slave" (ESC datasheet section I
// §9.3), taken as 1000 ns per passage, the value the SOEM interop tests check against.
inline constexpr std::uint16_t kPassage100BaseTxNs = 1000;
// EBUS (LVDS, no PHY), measured on real EK1100 + EL2828 + EL2889 (ET1200) hardware: the
// EL2828's port 1 receive time is 310 ns after its port 0 one (two passages: its own and the
// end terminal's loop), the EK1100's 600 ns (+ one EK1100 and one EL2828 passage);
// ../shared/pcap/replay-dc.pcapng frames 506, 510. 150 ns per passage matches both to 10 ns.
inline constexpr std::uint16_t kPassageEbusNs = 150;
// 100BASE-TX PHY latencies, for devices with one PHY port and one EBUS side (couplers): a
// DP83848 receives in 24 bit times (240 ns, datasheet T2.9.2) and transmits in 17 (170 ns,
// T2.26.4, RMII).
inline constexpr std::uint16_t kPhyReceiveNs = 240;
inline constexpr std::uint16_t kPhyTransmitNs = 170;

// SII EEPROM busy time per command, measured on real hardware in ../shared/pcap/replay-dc.pcapng
// (EtherCrab polls 0x0502 every ~265 us after each FPWR read command; status 0x8140 = busy +
// read command held, then 0x0040). EK1100 (ET1100, station 0x1000): still busy 595 us after
// the command (frames 1884/1888), ready 721 us after it (frames 158/162); one command spans
// 530-796 us (frames 104/108/110). EL2889 (ET1200, station 0x1002): busy at 622 us (frames
// 1752/1756), ready at 774 us (frames 1556/1560); EL2828 (ET1200, 0x1001) busy at 720 us
// (frames 1514/1518). The midpoints of those windows:
inline constexpr std::uint32_t kSiiBusyEt1100Ns = 660'000;
inline constexpr std::uint32_t kSiiBusyEt1200Ns = 700'000;

// ET1100: 8 FMMUs, 8 SMs, 8 KB process RAM, 4 ports, 64-bit DC (section II "ESC Features"
// 0x01FC as SOEM sees it on real ET1100 terminals, notes/soem-interop.md §3.2). 8-byte SII
// reads: a real EK1100 reports 0x0502 bit 6 set (../shared/pcap/replay-dc.pcapng frame 102).
// Default delays: 100BASE-TX (couplers, drives and boxes with RJ45/M8 ports).
inline constexpr EscType kEt1100{
    EscKind::kEt1100,    "ET1100",           0x11, 0x00, 0x0002, 8, 8, 8, 0x01FC, true, 4,
    kPassage100BaseTxNs, kPassage100BaseTxNs, kSiiBusyEt1100Ns};
// ET1200: 3 FMMUs, 4 SMs, 1 KB process RAM, up to 3 ports (datasheet section III ET1200);
// real EL2828/EL2889 terminals answer only for FMMU0-2 and SM0-3 and report 8-byte SII reads
// (replay-dc.pcapng). Default delays: EBUS (EtherCAT terminals).
inline constexpr EscType kEt1200{
    EscKind::kEt1200, "ET1200", 0x12, 0x00,           0x0001,        3, 4, 1,
    0x01FC,           true,     3,    kPassageEbusNs, kPassageEbusNs, kSiiBusyEt1200Ns};
// LAN9252 (Microchip): 3 FMMUs, 4 SMs, 4 KB process RAM, 2 ports, 64-bit DC, two integrated
// 100BASE-TX PHYs. No capture of its EEPROM timing here: the ET1100's, as for anything the
// sources leave open.
inline constexpr EscType kLan9252{
    EscKind::kLan9252,   "LAN9252",          0xC0, 0x01, 0x0001, 3, 4, 4, 0x01FC, true, 2,
    kPassage100BaseTxNs, kPassage100BaseTxNs, kSiiBusyEt1100Ns};

std::optional<EscType> escTypeByName(std::string_view name);

}  // namespace ecsim::slavesim
