// EtherCAT Network Information (ENI, root element <EtherCATConfig>, ETG.2100): the
// configuration a configuration tool exports for a master. Read into plain structs:
//
//   Config/Master              name, init commands of the master
//   Config/Slave               Info (name, station address, position, identity), Mailbox
//                              (SM areas, protocols, CoE init commands), register init
//                              commands, ProcessData (Send/Recv bit ranges, SMs, PDOs),
//                              PreviousPort (the wiring, when the tool wrote it)
//   Config/Cyclic/Frame/Cmd    the cyclic datagrams (state, command, address, length, WKC)
//   Config/ProcessImage        named input/output variables with bit offsets
//
// Numbers are decimal or in ESI syntax (#x..); Data is hex. Unknown elements are ignored (ENI
// files carry much tool-specific detail). Errors name the file and line.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/result.hpp"

namespace ecsim {

// A state transition of an init command: "IP", "PS", "SO", "OS", "SP", "PI", "SI", "OI", "OP",
// "IB", "BI", "II", "PP", "SS". from/to as AL state letters I, P, B, S, O.
struct EniTransition {
  char from{'I'};
  char to{'P'};
  std::string name() const { return std::string{from, to}; }
  bool operator==(const EniTransition&) const = default;
};

// Parses one transition name ("PS"); nullopt when it is not one.
std::optional<EniTransition> parseEniTransition(std::string_view text);

// An ESC register init command (datagram): Cmd is the EtherCAT command number (1 APRD, 2 APWR,
// 4 FPRD, 5 FPWR, 7 BRD, 8 BWR, ...).
struct EniRegisterCmd {
  std::vector<EniTransition> transitions;
  bool beforeSlave{false};
  std::string comment;
  std::uint8_t cmd{0};
  std::uint16_t adp{0};
  std::uint16_t ado{0};
  std::vector<std::uint8_t> data;           // written (write commands) or the length to read
  std::optional<std::uint16_t> dataLength;  // <DataLength> instead of <Data>
  std::optional<std::uint16_t> cnt;         // expected working counter
  std::uint32_t retries{0};
  int line{0};
  std::size_t length() const { return dataLength ? *dataLength : data.size(); }
};

// A CoE init command: an SDO download (Ccs 1) or upload (Ccs 2) at a transition.
struct EniCoeCmd {
  std::vector<EniTransition> transitions;
  std::string comment;
  std::uint8_t ccs{1};
  std::uint16_t index{0};
  std::uint8_t subIndex{0};
  bool completeAccess{false};
  bool fixed{false};
  std::vector<std::uint8_t> data;
  std::uint32_t timeoutMs{0};
  int line{0};
};

struct EniMailbox {
  std::uint16_t sendStart{0};  // master -> slave (SM0)
  std::uint16_t sendLength{0};
  std::uint16_t recvStart{0};  // slave -> master (SM1)
  std::uint16_t recvLength{0};
  std::vector<std::string> protocols;  // "CoE", "FoE", "EoE", ...
  std::vector<EniCoeCmd> coeInitCmds;
  int line{0};
  bool has(std::string_view protocol) const;
};

struct EniPdoEntry {
  std::uint16_t index{0};
  std::uint8_t subIndex{0};
  std::uint16_t bitLen{0};
  std::string name;
  std::string dataType;
};

struct EniPdo {
  std::uint16_t index{0};
  std::string name;
  std::optional<std::uint8_t> sm;  // the SM the PDO is assigned to (absent: not assigned)
  bool fixed{false};
  std::vector<EniPdoEntry> entries;
  std::uint32_t bitLength() const;
};

// Send = outputs (master -> slave), Recv = inputs, bit ranges in the logical process image.
struct EniBitRange {
  std::uint32_t bitStart{0};
  std::uint32_t bitLength{0};
};

struct EniSyncManager {
  std::uint8_t number{0};
  std::string type;  // "Outputs", "Inputs", "MBoxOut", "MBoxIn"
  std::uint16_t startAddress{0};
  std::uint16_t length{0};
  std::uint8_t control{0};
  bool enable{true};
  std::vector<std::uint16_t> pdos;
};

struct EniProcessData {
  std::vector<EniBitRange> send;
  std::vector<EniBitRange> recv;
  std::vector<EniSyncManager> syncManagers;
  std::vector<EniPdo> txPdos;  // inputs
  std::vector<EniPdo> rxPdos;  // outputs
};

// The port of an earlier slave this one is connected to (ports A..D = 0..3).
struct EniPreviousPort {
  std::uint16_t physAddr{0};
  unsigned port{0};
  bool selected{true};
};

struct EniSlave {
  std::string name;
  std::uint16_t physAddr{0};
  std::optional<std::int32_t> autoIncAddr;  // 0, -1, -2 ... (the position, negated)
  std::string physics;
  std::uint32_t vendorId{0};
  std::uint32_t productCode{0};
  std::optional<std::uint32_t> revisionNo;
  std::optional<std::uint32_t> serialNo;
  std::optional<EniMailbox> mailbox;
  std::vector<EniRegisterCmd> initCmds;
  EniProcessData processData;
  std::vector<EniPreviousPort> previousPorts;
  bool dcCapable{false};  // a <DC> element is present
  std::optional<std::uint32_t> dcCycleTimeNs;
  int line{0};
  const EniPreviousPort* previousPort() const;  // the selected one, if any
};

struct EniCyclicCmd {
  std::string state;  // states in which the datagram is sent, blank-separated ("SAFEOP OP")
  std::uint8_t cmd{0};
  std::optional<std::uint16_t> adp;
  std::optional<std::uint16_t> ado;
  std::optional<std::uint32_t> addr;  // logical address (LRD/LWR/LRW)
  std::uint16_t dataLength{0};
  std::optional<std::uint16_t> cnt;
  // Where the Cmd's data goes in the input / output process image, in bytes (ETG.2100; a
  // TwinCAT image mirrors the frames, so the first Cmd's is 26 = 14 + 2 + 10), which for
  // ecsim's own ENIs is the data's offset in the frame (master/eni_config.hpp reads both).
  std::optional<std::uint32_t> inputOffs;
  std::optional<std::uint32_t> outputOffs;
  int line{0};
};

struct EniFrame {
  std::vector<EniCyclicCmd> cmds;
};

struct EniCyclic {
  std::optional<std::uint32_t> cycleTimeUs;
  std::vector<EniFrame> frames;
};

struct EniVariable {
  std::string name;
  std::string dataType;
  std::uint32_t bitSize{0};
  std::uint32_t bitOffs{0};
  int line{0};
};

struct EniProcessImage {
  std::optional<std::uint32_t> inputByteSize;
  std::optional<std::uint32_t> outputByteSize;
  std::vector<EniVariable> inputs;
  std::vector<EniVariable> outputs;
};

struct EniMaster {
  std::string name;
  std::vector<EniRegisterCmd> initCmds;
};

// Cycle times beyond these are taken for absurd: a warning (file and line) and the value is
// ignored, as if absent (ENI files come from vendor tools; a real master would not run them).
constexpr std::uint32_t kMaxEniCycleTimeUs = 1'000'000;        // <Cyclic><CycleTime>, 1 s
constexpr std::uint32_t kMaxEniDcCycleTimeNs = 1'000'000'000;  // <DC><CycleTime0>, 1 s

struct EniConfig {
  std::filesystem::path file;         // for messages
  std::vector<std::string> warnings;  // "file, line N: ..." for values ignored
  EniMaster master;
  std::vector<EniSlave> slaves;  // in bus order
  std::vector<EniCyclic> cyclic;
  EniProcessImage processImage;

  const EniSlave* findSlave(std::uint16_t physAddr) const;
};

Result<EniConfig> parseEni(std::string_view xml, const std::filesystem::path& file);
Result<EniConfig> loadEniFile(const std::filesystem::path& path);

// Writes `eni` as ENI XML that parseEni reads back to the same structs (config/eni_format.cpp):
// numbers in decimal, identity and addresses as #x hex, Data as hex bytes.
std::string formatEni(const EniConfig& eni);

// The name of the root element of an XML file ("EtherCATConfig", "Topology", ...), for tools
// that accept several kinds of file.
Result<std::string> xmlRootName(const std::filesystem::path& path);

}  // namespace ecsim
