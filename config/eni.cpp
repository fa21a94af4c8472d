// Reads ENI files with tinyxml2 through config/xml_util.hpp (errors name file and line).
#include "config/eni.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>

#include "config/xml_util.hpp"
#include "protocol/frame.hpp"  // kMaxSlaves
#include "protocol/read_file.hpp"

namespace ecsim {
namespace {

using xml::Children;
using xml::Context;
using xml::Element;

// A child number that must be present.
template <typename T>
Result<T> required(const Context& ctx, const Element* parent, const char* name) {
  ECSIM_ASSIGN_OR_RETURN(std::optional<T> value, xml::childNumber<T>(ctx, parent, name));
  if (!value) {
    return ctx.error(parent, "<" + std::string(parent->Name()) + "> needs <" + name + ">");
  }
  return *value;
}

template <typename T>
Result<T> orZero(const Context& ctx, const Element* parent, const char* name) {
  ECSIM_ASSIGN_OR_RETURN(std::optional<T> value, xml::childNumber<T>(ctx, parent, name));
  return value.value_or(T{0});
}

Result<bool> childBool(const Context& ctx, const Element* parent, const char* name) {
  const Element* child = parent->FirstChildElement(name);
  if (child == nullptr || xml::text(child).empty()) return false;
  auto value = parseEsiBool(xml::text(child));
  if (!value.ok()) return ctx.error(child, std::string(name) + ": " + value.error().context);
  return *value;
}

Result<std::vector<EniTransition>> transitions(const Context& ctx, const Element* cmd) {
  std::vector<EniTransition> list;
  for (const Element* t : Children(cmd, "Transition")) {
    auto parsed = parseEniTransition(xml::text(t));
    if (!parsed) {
      return ctx.error(t, "Transition '" + std::string(xml::text(t)) +
                              "' is not a state transition (IP, PS, SO, ...)");
    }
    list.push_back(*parsed);
  }
  if (list.empty()) return ctx.error(cmd, "<InitCmd> without <Transition>");
  return list;
}

Result<EniRegisterCmd> registerCmd(const Context& ctx, const Element* e) {
  EniRegisterCmd c;
  c.line = e->GetLineNum();
  ECSIM_ASSIGN_OR_RETURN(c.transitions, transitions(ctx, e));
  ECSIM_ASSIGN_OR_RETURN(c.beforeSlave, childBool(ctx, e, "BeforeSlave"));
  c.comment = std::string(xml::childText(e, "Comment"));
  ECSIM_ASSIGN_OR_RETURN(c.cmd, required<std::uint8_t>(ctx, e, "Cmd"));
  ECSIM_ASSIGN_OR_RETURN(c.adp, orZero<std::uint16_t>(ctx, e, "Adp"));
  ECSIM_ASSIGN_OR_RETURN(c.ado, required<std::uint16_t>(ctx, e, "Ado"));
  ECSIM_ASSIGN_OR_RETURN(c.data, xml::childHex(ctx, e, "Data"));
  ECSIM_ASSIGN_OR_RETURN(c.dataLength, xml::childNumber<std::uint16_t>(ctx, e, "DataLength"));
  if (c.data.empty() && !c.dataLength) {
    return ctx.error(e, "<InitCmd> needs <Data> or <DataLength>");
  }
  ECSIM_ASSIGN_OR_RETURN(c.cnt, xml::childNumber<std::uint16_t>(ctx, e, "Cnt"));
  ECSIM_ASSIGN_OR_RETURN(c.retries, orZero<std::uint32_t>(ctx, e, "Retries"));
  return c;
}

Result<std::vector<EniRegisterCmd>> registerCmds(const Context& ctx, const Element* parent) {
  std::vector<EniRegisterCmd> list;
  for (const Element* e : Children(parent->FirstChildElement("InitCmds"), "InitCmd")) {
    ECSIM_ASSIGN_OR_RETURN(EniRegisterCmd c, registerCmd(ctx, e));
    list.push_back(std::move(c));
  }
  return list;
}

Result<EniCoeCmd> coeCmd(const Context& ctx, const Element* e) {
  EniCoeCmd c;
  c.line = e->GetLineNum();
  ECSIM_ASSIGN_OR_RETURN(c.transitions, transitions(ctx, e));
  ECSIM_ASSIGN_OR_RETURN(c.fixed, xml::attrBool(ctx, e, "Fixed", false));
  ECSIM_ASSIGN_OR_RETURN(c.completeAccess, xml::attrBool(ctx, e, "CompleteAccess", false));
  c.comment = std::string(xml::childText(e, "Comment"));
  ECSIM_ASSIGN_OR_RETURN(auto ccs, xml::childNumber<std::uint8_t>(ctx, e, "Ccs"));
  c.ccs = ccs.value_or(1);
  if (c.ccs != 1 && c.ccs != 2) {
    return ctx.error(e, "Ccs " + std::to_string(c.ccs) + ": 1 (download) or 2 (upload) expected");
  }
  ECSIM_ASSIGN_OR_RETURN(c.index, required<std::uint16_t>(ctx, e, "Index"));
  ECSIM_ASSIGN_OR_RETURN(c.subIndex, orZero<std::uint8_t>(ctx, e, "SubIndex"));
  ECSIM_ASSIGN_OR_RETURN(c.data, xml::childHex(ctx, e, "Data"));
  if (c.ccs == 1 && c.data.empty()) return ctx.error(e, "SDO download without <Data>");
  ECSIM_ASSIGN_OR_RETURN(c.timeoutMs, orZero<std::uint32_t>(ctx, e, "Timeout"));
  return c;
}

Result<EniMailbox> mailbox(const Context& ctx, const Element* e) {
  EniMailbox m;
  m.line = e->GetLineNum();
  const Element* send = e->FirstChildElement("Send");
  const Element* recv = e->FirstChildElement("Recv");
  if (send == nullptr || recv == nullptr) return ctx.error(e, "<Mailbox> needs <Send> and <Recv>");
  ECSIM_ASSIGN_OR_RETURN(m.sendStart, required<std::uint16_t>(ctx, send, "Start"));
  ECSIM_ASSIGN_OR_RETURN(m.sendLength, required<std::uint16_t>(ctx, send, "Length"));
  ECSIM_ASSIGN_OR_RETURN(m.recvStart, required<std::uint16_t>(ctx, recv, "Start"));
  ECSIM_ASSIGN_OR_RETURN(m.recvLength, required<std::uint16_t>(ctx, recv, "Length"));
  for (const Element* p : Children(e, "Protocol")) m.protocols.emplace_back(xml::text(p));
  if (const Element* coe = e->FirstChildElement("CoE")) {
    if (!m.has("CoE")) m.protocols.emplace_back("CoE");
    for (const Element* c : Children(coe->FirstChildElement("InitCmds"), "InitCmd")) {
      ECSIM_ASSIGN_OR_RETURN(EniCoeCmd cmd, coeCmd(ctx, c));
      m.coeInitCmds.push_back(std::move(cmd));
    }
  }
  // Init commands of the other mailbox protocols (ETG.2100: SoE, EoE, FoE, AoE, VoE) are
  // read by nobody: a master configured from this ENI would not send them. A warning, not an
  // error (vendor format), and only for what is dropped; other extensions stay silent.
  for (const char* protocol : {"SoE", "EoE", "FoE", "AoE", "VoE"}) {
    const Element* other = e->FirstChildElement(protocol);
    const Element* cmds = other == nullptr ? nullptr : other->FirstChildElement("InitCmds");
    std::size_t n = 0;
    for ([[maybe_unused]] const Element* c : Children(cmds, "InitCmd")) ++n;
    if (n > 0) {
      ctx.warn(cmds, std::to_string(n) + " <" + protocol +
                         "> init command(s) ignored: only CoE init commands are sent");
    }
  }
  return m;
}

Result<EniPdo> pdo(const Context& ctx, const Element* e) {
  EniPdo p;
  ECSIM_ASSIGN_OR_RETURN(p.index, required<std::uint16_t>(ctx, e, "Index"));
  p.name = std::string(xml::childText(e, "Name"));
  ECSIM_ASSIGN_OR_RETURN(p.sm, xml::attrNumber<std::uint8_t>(ctx, e, "Sm"));
  ECSIM_ASSIGN_OR_RETURN(p.fixed, xml::attrBool(ctx, e, "Fixed", false));
  for (const Element* en : Children(e, "Entry")) {
    EniPdoEntry entry;
    ECSIM_ASSIGN_OR_RETURN(entry.index, required<std::uint16_t>(ctx, en, "Index"));
    ECSIM_ASSIGN_OR_RETURN(entry.subIndex, orZero<std::uint8_t>(ctx, en, "SubIndex"));
    ECSIM_ASSIGN_OR_RETURN(entry.bitLen, required<std::uint16_t>(ctx, en, "BitLen"));
    entry.name = std::string(xml::childText(en, "Name"));
    entry.dataType = std::string(xml::childText(en, "DataType"));
    p.entries.push_back(std::move(entry));
  }
  return p;
}

Result<EniProcessData> processData(const Context& ctx, const Element* e) {
  EniProcessData d;
  auto ranges = [&](const char* name, std::vector<EniBitRange>& out) -> Status {
    for (const Element* r : Children(e, name)) {
      EniBitRange range;
      ECSIM_ASSIGN_OR_RETURN(range.bitStart, required<std::uint32_t>(ctx, r, "BitStart"));
      ECSIM_ASSIGN_OR_RETURN(range.bitLength, required<std::uint32_t>(ctx, r, "BitLength"));
      out.push_back(range);
    }
    return okStatus();
  };
  ECSIM_TRY(ranges("Send", d.send));
  ECSIM_TRY(ranges("Recv", d.recv));
  for (std::uint8_t n = 0; n < 16; ++n) {
    const std::string tag = "Sm" + std::to_string(n);
    const Element* s = e->FirstChildElement(tag.c_str());
    if (s == nullptr) continue;
    EniSyncManager sm;
    sm.number = n;
    sm.type = std::string(xml::childText(s, "Type"));
    ECSIM_ASSIGN_OR_RETURN(sm.startAddress, orZero<std::uint16_t>(ctx, s, "StartAddress"));
    ECSIM_ASSIGN_OR_RETURN(sm.length, orZero<std::uint16_t>(ctx, s, "DefaultSize"));
    ECSIM_ASSIGN_OR_RETURN(sm.control, orZero<std::uint8_t>(ctx, s, "ControlByte"));
    if (s->FirstChildElement("Enable") != nullptr) {
      ECSIM_ASSIGN_OR_RETURN(sm.enable, childBool(ctx, s, "Enable"));
    }
    for (const Element* p : Children(s, "Pdo")) {
      ECSIM_ASSIGN_OR_RETURN(std::uint16_t index,
                             xml::parseNumber<std::uint16_t>(ctx, p, "Pdo", xml::text(p)));
      sm.pdos.push_back(index);
    }
    d.syncManagers.push_back(std::move(sm));
  }
  for (const Element* p : Children(e, "TxPdo")) {
    ECSIM_ASSIGN_OR_RETURN(EniPdo parsed, pdo(ctx, p));
    d.txPdos.push_back(std::move(parsed));
  }
  for (const Element* p : Children(e, "RxPdo")) {
    ECSIM_ASSIGN_OR_RETURN(EniPdo parsed, pdo(ctx, p));
    d.rxPdos.push_back(std::move(parsed));
  }
  return d;
}

Result<unsigned> portNumber(const Context& ctx, const Element* e) {
  const std::string_view t = xml::text(e);
  if (t.size() == 1 && t[0] >= 'A' && t[0] <= 'D') return static_cast<unsigned>(t[0] - 'A');
  ECSIM_ASSIGN_OR_RETURN(std::uint8_t n, xml::parseNumber<std::uint8_t>(ctx, e, "Port", t));
  if (n > 3) return ctx.error(e, "Port " + std::string(t) + ": A..D or 0..3 expected");
  return unsigned{n};
}

Result<EniSlave> slave(const Context& ctx, const Element* e) {
  EniSlave s;
  s.line = e->GetLineNum();
  const Element* info = e->FirstChildElement("Info");
  if (info == nullptr) return ctx.error(e, "<Slave> needs <Info>");
  s.name = std::string(xml::childText(info, "Name"));
  ECSIM_ASSIGN_OR_RETURN(s.physAddr, required<std::uint16_t>(ctx, info, "PhysAddr"));
  ECSIM_ASSIGN_OR_RETURN(s.autoIncAddr, xml::childNumber<std::int32_t>(ctx, info, "AutoIncAddr"));
  s.physics = std::string(xml::childText(info, "Physics"));
  ECSIM_ASSIGN_OR_RETURN(s.vendorId, required<std::uint32_t>(ctx, info, "VendorId"));
  ECSIM_ASSIGN_OR_RETURN(s.productCode, required<std::uint32_t>(ctx, info, "ProductCode"));
  ECSIM_ASSIGN_OR_RETURN(s.revisionNo, xml::childNumber<std::uint32_t>(ctx, info, "RevisionNo"));
  ECSIM_ASSIGN_OR_RETURN(s.serialNo, xml::childNumber<std::uint32_t>(ctx, info, "SerialNo"));
  if (const Element* m = e->FirstChildElement("Mailbox")) {
    ECSIM_ASSIGN_OR_RETURN(EniMailbox parsed, mailbox(ctx, m));
    s.mailbox = std::move(parsed);
  }
  ECSIM_ASSIGN_OR_RETURN(s.initCmds, registerCmds(ctx, e));
  if (const Element* p = e->FirstChildElement("ProcessData")) {
    ECSIM_ASSIGN_OR_RETURN(s.processData, processData(ctx, p));
  }
  for (const Element* p : Children(e, "PreviousPort")) {
    EniPreviousPort prev;
    ECSIM_ASSIGN_OR_RETURN(prev.physAddr, required<std::uint16_t>(ctx, p, "PhysAddr"));
    const Element* port = p->FirstChildElement("Port");
    if (port == nullptr) return ctx.error(p, "<PreviousPort> needs <Port>");
    ECSIM_ASSIGN_OR_RETURN(prev.port, portNumber(ctx, port));
    ECSIM_ASSIGN_OR_RETURN(prev.selected, xml::attrBool(ctx, p, "Selected", true));
    s.previousPorts.push_back(prev);
  }
  if (const Element* dc = e->FirstChildElement("DC")) {
    s.dcCapable = true;
    ECSIM_ASSIGN_OR_RETURN(s.dcCycleTimeNs, xml::childNumber<std::uint32_t>(ctx, dc, "CycleTime0"));
  }
  return s;
}

Result<EniCyclicCmd> cyclicCmd(const Context& ctx, const Element* e) {
  EniCyclicCmd c;
  c.line = e->GetLineNum();
  for (const Element* st : Children(e, "State")) {
    c.state += (c.state.empty() ? "" : " ") + std::string(xml::text(st));
  }
  ECSIM_ASSIGN_OR_RETURN(c.cmd, required<std::uint8_t>(ctx, e, "Cmd"));
  ECSIM_ASSIGN_OR_RETURN(c.adp, xml::childNumber<std::uint16_t>(ctx, e, "Adp"));
  ECSIM_ASSIGN_OR_RETURN(c.ado, xml::childNumber<std::uint16_t>(ctx, e, "Ado"));
  ECSIM_ASSIGN_OR_RETURN(c.addr, xml::childNumber<std::uint32_t>(ctx, e, "Addr"));
  if (!c.addr && !c.ado) return ctx.error(e, "cyclic <Cmd> needs <Addr> or <Adp>/<Ado>");
  ECSIM_ASSIGN_OR_RETURN(c.dataLength, required<std::uint16_t>(ctx, e, "DataLength"));
  ECSIM_ASSIGN_OR_RETURN(c.cnt, xml::childNumber<std::uint16_t>(ctx, e, "Cnt"));
  ECSIM_ASSIGN_OR_RETURN(c.inputOffs, xml::childNumber<std::uint32_t>(ctx, e, "InputOffs"));
  ECSIM_ASSIGN_OR_RETURN(c.outputOffs, xml::childNumber<std::uint32_t>(ctx, e, "OutputOffs"));
  return c;
}

Status variables(const Context& ctx, const Element* e, std::optional<std::uint32_t>& byteSize,
                 std::vector<EniVariable>& out) {
  if (e == nullptr) return okStatus();
  ECSIM_ASSIGN_OR_RETURN(byteSize, xml::childNumber<std::uint32_t>(ctx, e, "ByteSize"));
  for (const Element* v : Children(e, "Variable")) {
    EniVariable var;
    var.line = v->GetLineNum();
    var.name = std::string(xml::childText(v, "Name"));
    if (var.name.empty()) return ctx.error(v, "<Variable> without <Name>");
    var.dataType = std::string(xml::childText(v, "DataType"));
    ECSIM_ASSIGN_OR_RETURN(var.bitSize, required<std::uint32_t>(ctx, v, "BitSize"));
    ECSIM_ASSIGN_OR_RETURN(var.bitOffs, required<std::uint32_t>(ctx, v, "BitOffs"));
    out.push_back(std::move(var));
  }
  return okStatus();
}

}  // namespace

std::optional<EniTransition> parseEniTransition(std::string_view text) {
  static constexpr std::string_view kValid[] = {"IP", "PS", "SO", "OS", "SP", "PI", "SI",
                                                "OI", "OP", "IB", "BI", "II", "PP", "SS"};
  for (std::string_view v : kValid) {
    if (text == v) return EniTransition{v[0], v[1]};
  }
  return std::nullopt;
}

bool EniMailbox::has(std::string_view protocol) const {
  for (const auto& p : protocols) {
    if (p == protocol) return true;
  }
  return false;
}

std::uint32_t EniPdo::bitLength() const {
  std::uint32_t bits = 0;
  for (const auto& e : entries) bits += e.bitLen;
  return bits;
}

const EniPreviousPort* EniSlave::previousPort() const {
  for (const auto& p : previousPorts) {
    if (p.selected) return &p;
  }
  return nullptr;
}

const EniSlave* EniConfig::findSlave(std::uint16_t physAddr) const {
  for (const auto& s : slaves) {
    if (s.physAddr == physAddr) return &s;
  }
  return nullptr;
}

Result<EniConfig> parseEni(std::string_view text, const std::filesystem::path& file) {
  EniConfig eni;
  const Context ctx(file.string(), &eni.warnings);
  tinyxml2::XMLDocument doc;
  ECSIM_TRY(xml::parseDocument(text, ctx, doc));
  const Element* root = doc.RootElement();
  if (root == nullptr || std::string_view(root->Name()) != "EtherCATConfig") {
    return ctx.error(root, "root element must be <EtherCATConfig>");
  }
  const Element* config = root->FirstChildElement("Config");
  if (config == nullptr) return ctx.error(root, "<EtherCATConfig> needs <Config>");
  eni.file = file;
  if (const Element* m = config->FirstChildElement("Master")) {
    eni.master.name = std::string(xml::childText(m->FirstChildElement("Info"), "Name"));
    ECSIM_ASSIGN_OR_RETURN(eni.master.initCmds, registerCmds(ctx, m));
  }
  // The line of the slave at each station address (0: none yet): checks in constant time,
  // so reading is linear in the number of slaves.
  std::vector<int> lineAt(std::size_t{1} << 16, 0);
  for (const Element* s : Children(config, "Slave")) {
    if (eni.slaves.size() == kMaxSlaves) {
      return ctx.error(s, "more than " + std::to_string(kMaxSlaves) +
                              " slaves (the address space of a segment)");
    }
    ECSIM_ASSIGN_OR_RETURN(EniSlave parsed, slave(ctx, s));
    if (const int twin = lineAt[parsed.physAddr]; twin != 0) {
      return ctx.error(s, "PhysAddr " + std::to_string(parsed.physAddr) +
                              " is already used by the slave on line " + std::to_string(twin));
    }
    for (const auto& prev : parsed.previousPorts) {
      if (lineAt[prev.physAddr] == 0) {
        return ctx.error(s, "PreviousPort names PhysAddr " + std::to_string(prev.physAddr) +
                                ", which no earlier slave has");
      }
    }
    if (parsed.dcCycleTimeNs == 0u) parsed.dcCycleTimeNs.reset();  // 0: not used
    if (parsed.dcCycleTimeNs && *parsed.dcCycleTimeNs > kMaxEniDcCycleTimeNs) {
      const Element* at = s->FirstChildElement("DC")->FirstChildElement("CycleTime0");
      eni.warnings.push_back(ctx.error(at, "DC CycleTime0 " +
                                               std::to_string(*parsed.dcCycleTimeNs) +
                                               " ns is outside [0, " +
                                               std::to_string(kMaxEniDcCycleTimeNs) + "]: ignored")
                                 .context);
      parsed.dcCycleTimeNs.reset();
    }
    lineAt[parsed.physAddr] = std::max(parsed.line, 1);
    eni.slaves.push_back(std::move(parsed));
  }
  for (const Element* c : Children(config, "Cyclic")) {
    EniCyclic cyclic;
    ECSIM_ASSIGN_OR_RETURN(cyclic.cycleTimeUs,
                           xml::childNumber<std::uint32_t>(ctx, c, "CycleTime"));
    if (cyclic.cycleTimeUs &&
        (*cyclic.cycleTimeUs == 0 || *cyclic.cycleTimeUs > kMaxEniCycleTimeUs)) {
      eni.warnings.push_back(ctx.error(c->FirstChildElement("CycleTime"),
                                       "CycleTime " + std::to_string(*cyclic.cycleTimeUs) +
                                           " us is outside [1, " +
                                           std::to_string(kMaxEniCycleTimeUs) + "]: ignored")
                                 .context);
      cyclic.cycleTimeUs.reset();
    }
    for (const Element* f : Children(c, "Frame")) {
      EniFrame frame;
      for (const Element* cmd : Children(f, "Cmd")) {
        ECSIM_ASSIGN_OR_RETURN(EniCyclicCmd parsed, cyclicCmd(ctx, cmd));
        frame.cmds.push_back(std::move(parsed));
      }
      cyclic.frames.push_back(std::move(frame));
    }
    eni.cyclic.push_back(std::move(cyclic));
  }
  if (const Element* image = config->FirstChildElement("ProcessImage")) {
    ECSIM_TRY(variables(ctx, image->FirstChildElement("Inputs"), eni.processImage.inputByteSize,
                        eni.processImage.inputs));
    ECSIM_TRY(variables(ctx, image->FirstChildElement("Outputs"), eni.processImage.outputByteSize,
                        eni.processImage.outputs));
  }
  return eni;
}

Result<EniConfig> loadEniFile(const std::filesystem::path& path) {
  ECSIM_ASSIGN_OR_RETURN(const std::string text, readRegularFile(path, kMaxXmlFileBytes));
  return parseEni(text, path);
}

Result<std::string> xmlRootName(const std::filesystem::path& path) {
  ECSIM_ASSIGN_OR_RETURN(const std::string text, readRegularFile(path, kMaxXmlFileBytes));
  const Context ctx(path.string());
  tinyxml2::XMLDocument doc;
  ECSIM_TRY(xml::parseDocument(text, ctx, doc));
  const Element* root = doc.RootElement();
  if (root == nullptr) return ctx.error(1, "no root element");
  return std::string(root->Name());
}

}  // namespace ecsim
