// Every DI/DO/AI/AO device of Beckhoff_EL1xxx_2011.xml, Beckhoff_EtherCAT_Terminals.xml
// (EL1xxx-EL4xxx), Beckhoff_EM2xxx.xml, SMC_EX250-SEN1-X156.xml and Beckhoff_EL47xx.xml
// (../shared/esi), with the channel counts read off each ESI's PDOs with Sm= (the default
// assignment): 1-bit entries of 0x2000-0x9FFF (old layout 0x3101/0x3001, MDP 0x60n0/0x70n0),
// the SMC's UINT8 Byte0..3 (8 channels each), 16-bit "Value" inputs and "Value"/"Output"
// outputs. The in-process IO tests (tests/embed/vendor_io_test.cpp) and the SOEM interop test
// (tests/interop/soem_io_test.cpp) both go through it.
#pragma once

#include <cstdint>
#include <ostream>

namespace ecsim::testing {

struct VendorIoDevice {
  const char* file;
  const char* type;
  std::uint32_t product;
  std::uint32_t revision;
  bool analog;  // the analog profile; else io
  unsigned digitalInputs, digitalOutputs, analogInputs, analogOutputs;
};
inline void PrintTo(const VendorIoDevice& c, std::ostream* os) {
  *os << c.file << " " << c.type << " rev 0x" << std::hex << c.revision;
}

inline constexpr VendorIoDevice kVendorIoDevices[] = {
    {"Beckhoff_EL1xxx_2011.xml", "EL1002", 0x03EA3052, 0x00000000, false, 2, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1002", 0x03EA3052, 0x00100000, false, 2, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1004", 0x03EC3052, 0x00000000, false, 4, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1004", 0x03EC3052, 0x00100000, false, 4, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1004-0010", 0x03EC3052, 0x0000000A, false, 4, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1004-0010", 0x03EC3052, 0x0010000A, false, 4, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1008", 0x03F03052, 0x00100000, false, 8, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1012", 0x03F43052, 0x00000000, false, 2, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1012", 0x03F43052, 0x00100000, false, 2, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1014", 0x03F63052, 0x00000000, false, 4, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1014", 0x03F63052, 0x00100000, false, 4, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1014-0010", 0x03F63052, 0x0000000A, false, 4, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1014-0010", 0x03F63052, 0x0010000A, false, 4, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1018", 0x03FA3052, 0x00100000, false, 8, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1024", 0x04003052, 0x00100000, false, 4, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1034", 0x040A3052, 0x00100000, false, 4, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1084", 0x043C3052, 0x00100000, false, 4, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1088", 0x04403052, 0x00100000, false, 8, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1094", 0x04463052, 0x00100000, false, 4, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1098", 0x044A3052, 0x00100000, false, 8, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1104", 0x04503052, 0x00100000, false, 4, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1114", 0x045A3052, 0x00100000, false, 4, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1124", 0x04643052, 0x00100000, false, 4, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1134", 0x046E3052, 0x00100000, false, 4, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1144", 0x04783052, 0x00100000, false, 4, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1202", 0x04B23052, 0x00100000, false, 2, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1202-0100", 0x04B23052, 0x00100064, false, 2, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1252", 0x04E43052, 0x00110000, false, 2, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1252", 0x04E43052, 0x00120000, false, 2, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1252", 0x04E43052, 0x00130000, false, 2, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1262", 0x04EE3052, 0x00020000, false, 2, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1702", 0x06A63052, 0x00100000, false, 2, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1712", 0x06B03052, 0x00100000, false, 2, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1722", 0x06BA3052, 0x00100000, false, 2, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1804", 0x070C3052, 0x00100000, false, 4, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1808", 0x07103052, 0x00100000, false, 8, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1809", 0x07113052, 0x00100000, false, 16, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1814", 0x07163052, 0x00100000, false, 4, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1819", 0x071B3052, 0x00100000, false, 16, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1859", 0x07433052, 0x00100000, false, 8, 8, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1862", 0x07463052, 0x00100000, false, 16, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1862-0010", 0x07463052, 0x0010000A, false, 16, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1872", 0x07503052, 0x00100000, false, 16, 0, 0, 0},
    {"Beckhoff_EL1xxx_2011.xml", "EL1889", 0x07613052, 0x00100000, false, 16, 0, 0, 0},
    {"Beckhoff_EtherCAT_Terminals.xml", "EL1002", 0x03EA3052, 0x270B0000, false, 2, 0, 0, 0},
    {"Beckhoff_EtherCAT_Terminals.xml", "EL1004", 0x03EC3052, 0x270B0000, false, 4, 0, 0, 0},
    {"Beckhoff_EtherCAT_Terminals.xml", "EL1012", 0x03F43052, 0x270B0000, false, 2, 0, 0, 0},
    {"Beckhoff_EtherCAT_Terminals.xml", "EL1014", 0x03F63052, 0x270B0000, false, 4, 0, 0, 0},
    {"Beckhoff_EtherCAT_Terminals.xml", "EL2002", 0x07D23052, 0x270B0000, false, 0, 2, 0, 0},
    {"Beckhoff_EtherCAT_Terminals.xml", "EL2004", 0x07D43052, 0x270B0000, false, 0, 4, 0, 0},
    {"Beckhoff_EtherCAT_Terminals.xml", "EL2032", 0x07F03052, 0x270B0000, false, 2, 2, 0, 0},
    {"Beckhoff_EtherCAT_Terminals.xml", "EL3102", 0x0C1E3052, 0x270B0000, true, 0, 0, 2, 0},
    {"Beckhoff_EtherCAT_Terminals.xml", "EL3112", 0x0C283052, 0x270B0000, true, 0, 0, 2, 0},
    {"Beckhoff_EtherCAT_Terminals.xml", "EL3122", 0x0C323052, 0x270B0000, true, 0, 0, 2, 0},
    {"Beckhoff_EtherCAT_Terminals.xml", "EL3142", 0x0C463052, 0x270B0000, true, 0, 0, 2, 0},
    {"Beckhoff_EtherCAT_Terminals.xml", "EL3142", 0x0C463052, 0x270C0000, true, 0, 0, 2, 0},
    {"Beckhoff_EtherCAT_Terminals.xml", "EL3152", 0x0C503052, 0x270B0000, true, 0, 0, 2, 0},
    {"Beckhoff_EtherCAT_Terminals.xml", "EL3162", 0x0C5A3052, 0x270B0000, true, 0, 0, 2, 0},
    {"Beckhoff_EtherCAT_Terminals.xml", "EL4102", 0x10063052, 0x270B0000, true, 0, 0, 0, 2},
    {"Beckhoff_EtherCAT_Terminals.xml", "EL4112", 0x10103052, 0x270B0000, true, 0, 0, 0, 2},
    {"Beckhoff_EtherCAT_Terminals.xml", "EL4132", 0x10243052, 0x270B0000, true, 0, 0, 0, 2},
    {"Beckhoff_EM2xxx.xml", "EM2042", 0x07FA3452, 0x00100000, false, 0, 16, 0, 0},
    {"SMC_EX250-SEN1-X156.xml", "EX250-SEN1-X156", 0x00FA6053, 0x00000000, false, 32, 32, 0, 0},
    {"Beckhoff_EL47xx.xml", "EL4712", 0x12683052, 0x00000000, true, 0, 0, 0, 2},
    {"Beckhoff_EL47xx.xml", "EL4712", 0x12683052, 0x00010000, true, 0, 0, 0, 2},
    {"Beckhoff_EL47xx.xml", "EL4732", 0x127C3052, 0x00000001, true, 0, 0, 0, 2},
    {"Beckhoff_EL47xx.xml", "EL4732", 0x127C3052, 0x00020000, true, 0, 0, 0, 2},
    {"Beckhoff_EL47xx.xml", "EL4732", 0x127C3052, 0x00030000, true, 0, 0, 0, 2},
    {"Beckhoff_EL47xx.xml", "EL4732", 0x127C3052, 0x00040000, true, 0, 0, 0, 2},
};

}  // namespace ecsim::testing
