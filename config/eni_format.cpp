// Writes ENI XML (the subset config/eni.hpp reads). Element text is escaped; the layout is
// what configuration tools write: one element per line, two-space indentation.
#include <cstdio>

#include "config/eni.hpp"
#include "config/xml_util.hpp"

namespace ecsim {
namespace {

using xml::escapeText;

std::string hex(std::uint32_t value, int digits) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "#x%0*X", digits, value);
  return buf;
}

std::string hexBytes(const std::vector<std::uint8_t>& data) {
  std::string out;
  char buf[4];
  for (std::uint8_t b : data) {
    std::snprintf(buf, sizeof buf, "%02X", b);
    out += buf;
  }
  return out;
}

class Writer {
 public:
  void open(std::string_view tag, std::string_view attributes = {}) {
    line("<" + std::string(tag) + (attributes.empty() ? "" : " ") + std::string(attributes) + ">");
    depth_ += 2;
  }
  void close(std::string_view tag) {
    depth_ -= 2;
    line("</" + std::string(tag) + ">");
  }
  void leaf(std::string_view tag, const std::string& value) {
    line("<" + std::string(tag) + ">" + escapeText(value) + "</" + std::string(tag) + ">");
  }
  void leaf(std::string_view tag, std::uint64_t value) { leaf(tag, std::to_string(value)); }
  void line(const std::string& text) {
    out_.append(static_cast<std::size_t>(depth_), ' ');
    out_ += text;
    out_ += '\n';
  }
  std::string take() { return std::move(out_); }

 private:
  std::string out_;
  int depth_{0};
};

void transitions(Writer& w, const std::vector<EniTransition>& list) {
  for (const auto& t : list) w.leaf("Transition", t.name());
}

void registerCmds(Writer& w, const std::vector<EniRegisterCmd>& cmds) {
  if (cmds.empty()) return;
  w.open("InitCmds");
  for (const auto& c : cmds) {
    w.open("InitCmd");
    transitions(w, c.transitions);
    if (c.beforeSlave) w.leaf("BeforeSlave", "true");
    if (!c.comment.empty()) w.leaf("Comment", c.comment);
    w.leaf("Cmd", c.cmd);
    w.leaf("Adp", c.adp);
    w.leaf("Ado", hex(c.ado, 4));
    if (!c.data.empty()) w.leaf("Data", hexBytes(c.data));
    if (c.dataLength) w.leaf("DataLength", *c.dataLength);
    if (c.cnt) w.leaf("Cnt", *c.cnt);
    if (c.retries != 0) w.leaf("Retries", c.retries);
    w.close("InitCmd");
  }
  w.close("InitCmds");
}

void pdo(Writer& w, const char* tag, const EniPdo& p) {
  std::string attributes;
  if (p.sm) attributes = "Sm=\"" + std::to_string(*p.sm) + "\"";
  if (p.fixed) attributes += std::string(attributes.empty() ? "" : " ") + "Fixed=\"true\"";
  w.open(tag, attributes);
  w.leaf("Index", hex(p.index, 4));
  w.leaf("Name", p.name);
  for (const auto& e : p.entries) {
    w.line("<Entry><Index>" + hex(e.index, 4) + "</Index><SubIndex>" + std::to_string(e.subIndex) +
           "</SubIndex><BitLen>" + std::to_string(e.bitLen) + "</BitLen><Name>" +
           escapeText(e.name) + "</Name><DataType>" + escapeText(e.dataType) +
           "</DataType></Entry>");
  }
  w.close(tag);
}

void slave(Writer& w, const EniSlave& s) {
  w.open("Slave");
  w.open("Info");
  w.leaf("Name", s.name);
  w.leaf("PhysAddr", s.physAddr);
  if (s.autoIncAddr) w.leaf("AutoIncAddr", std::to_string(*s.autoIncAddr));
  if (!s.physics.empty()) w.leaf("Physics", s.physics);
  w.leaf("VendorId", hex(s.vendorId, 8));
  w.leaf("ProductCode", hex(s.productCode, 8));
  if (s.revisionNo) w.leaf("RevisionNo", hex(*s.revisionNo, 8));
  if (s.serialNo) w.leaf("SerialNo", *s.serialNo);
  w.close("Info");
  const EniProcessData& d = s.processData;
  if (!d.send.empty() || !d.recv.empty() || !d.syncManagers.empty() || !d.txPdos.empty() ||
      !d.rxPdos.empty()) {
    w.open("ProcessData");
    for (const auto& r : d.send) {
      w.line("<Send><BitStart>" + std::to_string(r.bitStart) + "</BitStart><BitLength>" +
             std::to_string(r.bitLength) + "</BitLength></Send>");
    }
    for (const auto& r : d.recv) {
      w.line("<Recv><BitStart>" + std::to_string(r.bitStart) + "</BitStart><BitLength>" +
             std::to_string(r.bitLength) + "</BitLength></Recv>");
    }
    for (const auto& sm : d.syncManagers) {
      const std::string tag = "Sm" + std::to_string(sm.number);
      w.open(tag);
      w.leaf("Type", sm.type);
      w.leaf("StartAddress", hex(sm.startAddress, 4));
      w.leaf("DefaultSize", sm.length);
      w.leaf("ControlByte", hex(sm.control, 2));
      w.leaf("Enable", sm.enable ? "1" : "0");
      for (std::uint16_t p : sm.pdos) w.leaf("Pdo", hex(p, 4));
      w.close(tag);
    }
    for (const auto& p : d.txPdos) pdo(w, "TxPdo", p);
    for (const auto& p : d.rxPdos) pdo(w, "RxPdo", p);
    w.close("ProcessData");
  }
  if (s.mailbox) {
    const EniMailbox& m = *s.mailbox;
    w.open("Mailbox", "DataLinkLayer=\"true\"");
    w.line("<Send><Start>" + std::to_string(m.sendStart) + "</Start><Length>" +
           std::to_string(m.sendLength) + "</Length></Send>");
    w.line("<Recv><Start>" + std::to_string(m.recvStart) + "</Start><Length>" +
           std::to_string(m.recvLength) + "</Length></Recv>");
    for (const auto& p : m.protocols) w.leaf("Protocol", p);
    if (!m.coeInitCmds.empty()) {
      w.open("CoE");
      w.open("InitCmds");
      for (const auto& c : m.coeInitCmds) {
        w.open("InitCmd", std::string("Fixed=\"") + (c.fixed ? "true" : "false") +
                              "\" CompleteAccess=\"" + (c.completeAccess ? "true" : "false") +
                              "\"");
        transitions(w, c.transitions);
        if (!c.comment.empty()) w.leaf("Comment", c.comment);
        w.leaf("Timeout", c.timeoutMs);
        w.leaf("Ccs", c.ccs);
        w.leaf("Index", hex(c.index, 4));
        w.leaf("SubIndex", c.subIndex);
        if (!c.data.empty()) w.leaf("Data", hexBytes(c.data));
        w.close("InitCmd");
      }
      w.close("InitCmds");
      w.close("CoE");
    }
    w.close("Mailbox");
  }
  registerCmds(w, s.initCmds);
  for (const auto& p : s.previousPorts) {
    w.open("PreviousPort", std::string("Selected=\"") + (p.selected ? "1" : "0") + "\"");
    w.leaf("Port", std::string(1, static_cast<char>('A' + p.port)));
    w.leaf("PhysAddr", p.physAddr);
    w.close("PreviousPort");
  }
  if (s.dcCapable) {
    w.open("DC");
    if (s.dcCycleTimeNs) w.leaf("CycleTime0", *s.dcCycleTimeNs);
    w.close("DC");
  }
  w.close("Slave");
}

void variables(Writer& w, const char* tag, std::optional<std::uint32_t> byteSize,
               const std::vector<EniVariable>& list) {
  w.open(tag);
  if (byteSize) w.leaf("ByteSize", *byteSize);
  for (const auto& v : list) {
    w.line("<Variable><Name>" + escapeText(v.name) + "</Name><DataType>" + escapeText(v.dataType) +
           "</DataType><BitSize>" + std::to_string(v.bitSize) + "</BitSize><BitOffs>" +
           std::to_string(v.bitOffs) + "</BitOffs></Variable>");
  }
  w.close(tag);
}

}  // namespace

std::string formatEni(const EniConfig& eni) {
  Writer w;
  w.line("<?xml version=\"1.0\" encoding=\"UTF-8\"?>");
  w.open("EtherCATConfig", "Version=\"1.3\"");
  w.open("Config");
  w.open("Master");
  w.open("Info");
  w.leaf("Name", eni.master.name);
  w.close("Info");
  registerCmds(w, eni.master.initCmds);
  w.close("Master");
  for (const auto& s : eni.slaves) slave(w, s);
  for (const auto& c : eni.cyclic) {
    w.open("Cyclic");
    if (c.cycleTimeUs) w.leaf("CycleTime", *c.cycleTimeUs);
    for (const auto& f : c.frames) {
      w.open("Frame");
      for (const auto& cmd : f.cmds) {
        w.open("Cmd");
        std::size_t from = 0;
        while (from < cmd.state.size()) {
          std::size_t to = cmd.state.find(' ', from);
          if (to == std::string::npos) to = cmd.state.size();
          if (to > from) w.leaf("State", cmd.state.substr(from, to - from));
          from = to + 1;
        }
        w.leaf("Cmd", cmd.cmd);
        if (cmd.adp) w.leaf("Adp", *cmd.adp);
        if (cmd.ado) w.leaf("Ado", hex(*cmd.ado, 4));
        if (cmd.addr) w.leaf("Addr", *cmd.addr);
        w.leaf("DataLength", cmd.dataLength);
        if (cmd.cnt) w.leaf("Cnt", *cmd.cnt);
        if (cmd.inputOffs) w.leaf("InputOffs", *cmd.inputOffs);
        if (cmd.outputOffs) w.leaf("OutputOffs", *cmd.outputOffs);
        w.close("Cmd");
      }
      w.close("Frame");
    }
    w.close("Cyclic");
  }
  const EniProcessImage& image = eni.processImage;
  if (image.inputByteSize || image.outputByteSize || !image.inputs.empty() ||
      !image.outputs.empty()) {
    w.open("ProcessImage");
    variables(w, "Inputs", image.inputByteSize, image.inputs);
    variables(w, "Outputs", image.outputByteSize, image.outputs);
    w.close("ProcessImage");
  }
  w.close("Config");
  w.close("EtherCATConfig");
  return w.take();
}

}  // namespace ecsim
