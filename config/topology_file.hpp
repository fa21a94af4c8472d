// Topology files (documented in docs/topology.md): which slaves a simulated network has,
// which device each one is (a device from an ESI file, or a device of ours), how they are
// wired port to port with which cable lengths, which ESC and delays they use, their clocks
// and their initial input values. Read into plain structs; errors name the file and line.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/frame.hpp"  // kMaxSlaves
#include "protocol/result.hpp"

namespace ecsim {

// Ranges of a topology file's numbers (docs/topology.md); a value outside is an error naming the
// file, line and range.
constexpr double kMaxCableMetres = 100.0;           // a 100BASE-TX segment
constexpr std::int64_t kMaxEscDelayNs = 1'000'000;  // processing/forwarding delay, 1 ms
// Local time at simulation time 0: about 126 years either way of the DC epoch, leaving room
// for runs of centuries before SimTime's end.
constexpr std::int64_t kMaxClockOffsetNs = 4'000'000'000'000'000'000;
constexpr double kMaxDriftPpm = 1000.0;

struct TopologyInput {  // an initial input value: object entry and value
  std::uint16_t index{0};
  std::uint8_t subIndex{0};
  std::int64_t value{0};
  int line{0};
};

struct TopologyParam {  // a device model parameter (<Param name= value=>)
  std::string name;
  std::string value;
  int line{0};
};

// A module in a slot of a modular device (<Module type="UR20-4DI-P"/> or ident="#x00091F84"),
// in slot order.
struct TopologyModule {
  std::string type;                    // module <Type> text, or empty
  std::optional<std::uint32_t> ident;  // ModuleIdent, or nullopt
  int line{0};
};

struct TopologySlave {
  std::string name;
  // Device: from an ESI file (esiFile + productCode [+ revision]) or a built-in one.
  std::filesystem::path esiFile;  // resolved against the topology file's folder
  std::optional<std::uint32_t> productCode;
  std::optional<std::uint32_t> revision;  // absent: the highest revision in the file
  std::string builtin;                    // "generic" when no ESI device is named
  std::filesystem::path eepromFile;       // a device given by a raw SII dump instead
  std::string esc;         // ESC model; empty: the device's choice (generic devices: ET1100)
  std::string dc{"full"};  // DC unit: full, delay-only (receive times only), none
  std::optional<std::int64_t> processingDelayNs;
  std::optional<std::int64_t> forwardingDelayNs;
  std::int64_t clockOffsetNs{0};
  double driftPpm{0.0};
  std::vector<TopologyInput> inputs;
  std::filesystem::path stateFile;  // persistent device state (e.g. absolute encoder)
  // The device model (model="cia402|none"); empty: chosen from the ESI (docs/devices.md).
  std::string model;
  std::vector<TopologyParam> params;  // device model parameters, in the written order
  std::filesystem::path folder;       // the topology file's folder (for files params name)
  // Modular devices: the modules in the slots (none given: the slots' default modules), and
  // the ESI file holding them (empty: the device's file, then every ESI file in its folder).
  std::vector<TopologyModule> modules;
  std::filesystem::path moduleFile;
  // SoE devices: the EtherCATDict file holding the drive's IDNs (soeDictionary=, resolved
  // against the topology file's folder).
  std::filesystem::path soeDictionaryFile;
  // Identification (ETG.1020 §22 hot-connect; docs/topology.md): the configured station alias
  // in the SII (word 4, loaded into 0x0012), and the explicit device ID the device shows in AL
  // status code 0x0134 when a master requests it (AL control 0x0120 bit 5): an ID switch.
  std::optional<std::uint16_t> alias;
  std::optional<std::uint16_t> deviceId;
  int line{0};
};

struct TopologyLink {
  std::string name;  // cable name, for --pcap-link and fault injection ("" = auto)
  std::size_t fromSlave{0};
  unsigned fromPort{0};
  std::size_t toSlave{0};
  unsigned toPort{0};
  double cableMetres{1.0};
  int line{0};
};

// A hot-connect group (<Group name= slaves= attached=>): slaves attached to and detached from
// the running network together (a tool changer), through the one link that joins them to the
// rest (the junction's cable).
struct TopologyGroup {
  std::string name;
  std::vector<std::size_t> slaves;  // slave indices, as written
  bool attached{true};              // at power-up
  std::size_t junctionLink{0};      // index in TopologyConfig::links
  int line{0};
};

struct TopologyConfig {
  std::string name;
  std::filesystem::path file;
  double masterCableMetres{1.0};
  // Cable redundancy (<Master redundant="SLAVE:PORT">): the slave's port wired to the master's
  // second port, and that cable's length.
  std::optional<std::pair<std::size_t, unsigned>> redundantPort;
  double redundantCableMetres{1.0};
  int masterLine{0};
  std::vector<TopologySlave> slaves;  // in the order written; slave 0 is at the master
  std::vector<TopologyLink> links;    // empty in the file: a line in written order
  std::vector<TopologyGroup> groups;  // hot-connect groups
  bool explicitLinks{false};
  // Slave index by name, filled by parseTopology (findSlave falls back to a search when a
  // caller filled `slaves` itself).
  std::map<std::string, std::size_t, std::less<>> byName;
  // What reading found without refusing (an ENI's ignored values, for a topology on an ENI),
  // one line each naming file and line; buildNetwork passes them on as the network's warnings.
  std::vector<std::string> warnings;

  std::optional<std::size_t> findSlave(std::string_view name) const;
};

Result<TopologyConfig> parseTopology(std::string_view xml, const std::filesystem::path& file);
Result<TopologyConfig> loadTopologyFile(const std::filesystem::path& path);

}  // namespace ecsim
