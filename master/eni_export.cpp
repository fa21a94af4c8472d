#include "master/eni_export.hpp"

namespace ecsim::master {
namespace {

// IEC 61131 names of the CoE basic data types (ETG.1000.6 table 63), else by size.
std::string dataTypeName(std::uint16_t type, unsigned bits) {
  switch (type) {
    case 0x0001:
      return "BOOL";
    case 0x0002:
      return "SINT";
    case 0x0003:
      return "INT";
    case 0x0004:
      return "DINT";
    case 0x0005:
      return "USINT";
    case 0x0006:
      return "UINT";
    case 0x0007:
      return "UDINT";
    case 0x0008:
      return "REAL";
    case 0x0011:
      return "LREAL";
    case 0x0015:
      return "LINT";
    case 0x001B:
      return "ULINT";
    default:
      break;
  }
  switch (bits) {
    case 1:
      return "BOOL";
    case 8:
      return "USINT";
    case 16:
      return "UINT";
    case 32:
      return "UDINT";
    case 64:
      return "ULINT";
    default:
      return "BIT" + std::to_string(bits);
  }
}

std::vector<std::string> protocolNames(std::uint16_t bits) {
  std::vector<std::string> out;
  if ((bits & SiiMailboxProtocol::kAoe) != 0) out.emplace_back("AoE");
  if ((bits & SiiMailboxProtocol::kEoe) != 0) out.emplace_back("EoE");
  if ((bits & SiiMailboxProtocol::kCoe) != 0) out.emplace_back("CoE");
  if ((bits & SiiMailboxProtocol::kFoe) != 0) out.emplace_back("FoE");
  if ((bits & SiiMailboxProtocol::kSoe) != 0) out.emplace_back("SoE");
  return out;
}

EniPdo pdoOf(const PdoInfo& pdo, unsigned sm) {
  EniPdo p;
  p.index = pdo.index;
  p.name = pdo.name;
  p.sm = static_cast<std::uint8_t>(sm);
  for (const auto& e : pdo.entries) {
    p.entries.push_back(
        {e.index, e.subindex, e.bitLength, e.name, dataTypeName(e.dataType, e.bitLength)});
  }
  return p;
}

// LogicalDatagram::states as an ENI <State> list; a datagram sent in every state is written
// for the states cyclic frames run in.
std::string statesText(std::uint8_t states) {
  if (states == kAllStates) return "SAFEOP OP";
  std::string text;
  for (const auto& [state, name] :
       {std::pair{AlState::kInit, "INIT"}, std::pair{AlState::kPreOp, "PREOP"},
        std::pair{AlState::kSafeOp, "SAFEOP"}, std::pair{AlState::kOp, "OP"},
        std::pair{AlState::kBootstrap, "BOOT"}}) {
    if ((states & stateBit(state)) == 0) continue;
    if (!text.empty()) text += ' ';
    text += name;
  }
  return text;
}

}  // namespace

std::optional<unsigned> parentPort(const std::vector<SlaveInfo>& slaves, std::size_t position) {
  if (position >= slaves.size() || slaves[position].parent < 0) return std::nullopt;
  const auto parent = static_cast<std::size_t>(slaves[position].parent);
  std::size_t k = 0;  // children of the parent before this one
  for (std::size_t i = parent + 1; i < position; ++i) {
    if (slaves[i].parent == slaves[position].parent) ++k;
  }
  for (unsigned port : {3u, 1u, 2u}) {
    if ((slaves[parent].activePorts >> port & 1u) == 0) continue;
    if (k == 0) return port;
    --k;
  }
  return std::nullopt;
}

EniConfig eniFromMaster(const Master& master) {
  EniConfig eni;
  eni.master.name = "ecsim master";
  const auto& slaves = master.slaves();
  const ProcessImageLayout& layout = master.layout();
  const bool configured = layout.slaves.size() == slaves.size();
  for (const SlaveInfo& s : slaves) {
    EniSlave e;
    e.line = 0;
    e.name = s.displayName().empty() ? "slave " + std::to_string(s.position) : s.displayName();
    e.physAddr = s.station;
    e.autoIncAddr = -static_cast<std::int32_t>(s.position);
    e.vendorId = s.identity().vendorId;
    e.productCode = s.identity().productCode;
    e.revisionNo = s.identity().revision;
    e.serialNo = s.identity().serial;
    if (s.mailbox) {
      EniMailbox m;
      m.sendStart = s.mailbox->outStart;
      m.sendLength = s.mailbox->outSize;
      m.recvStart = s.mailbox->inStart;
      m.recvLength = s.mailbox->inSize;
      m.protocols = protocolNames(s.mailbox->protocols);
      e.mailbox = std::move(m);
    }
    if (s.parent >= 0) {
      const SlaveInfo& parent = slaves[static_cast<std::size_t>(s.parent)];
      e.previousPorts.push_back({parent.station, parentPort(slaves, s.position).value_or(1), true});
    }
    for (const auto& mode : s.siiContents.dcOpModes) {
      if (s.hasDc() && (mode.assignActivate & 0x0200) != 0) {
        e.dcCapable = true;
        if (mode.cycleTime0 != 0) e.dcCycleTimeNs = mode.cycleTime0;
      }
    }
    if (configured) {
      const SlaveLayout& sl = layout.slaves[s.position];
      if (sl.outputBytes > 0) {
        e.processData.send.push_back(
            {(sl.outputOffset + layout.logicalBase) * 8, sl.outputBytes * 8});
      }
      if (sl.inputBytes > 0) {
        e.processData.recv.push_back(
            {(sl.inputOffset + layout.logicalBase) * 8, sl.inputBytes * 8});
      }
      for (const SmLayout& sm : sl.sms) {
        EniSyncManager esm;
        esm.number = static_cast<std::uint8_t>(sm.sm);
        esm.type = sm.outputs ? "Outputs" : "Inputs";
        esm.startAddress = sm.setting.start;
        esm.length = sm.setting.length;
        esm.control = sm.setting.control.encode();
        esm.enable = sm.setting.length > 0;
        for (const PdoInfo& pdo : sm.pdos) {
          esm.pdos.push_back(pdo.index);
          (sm.outputs ? e.processData.rxPdos : e.processData.txPdos).push_back(pdoOf(pdo, sm.sm));
        }
        e.processData.syncManagers.push_back(std::move(esm));
      }
    }
    eni.slaves.push_back(std::move(e));
  }
  if (!configured) return eni;
  EniCyclic cyclic;
  cyclic.cycleTimeUs = static_cast<std::uint32_t>(master.options().cycleTime / 1000);
  // Offsets in the frame: Ethernet header 14 + EtherCAT header 2, then per datagram a 10-byte
  // header, the data and a 2-byte WKC.
  std::vector<std::uint32_t> frameOffset(layout.frameCount, 14 + 2);
  cyclic.frames.resize(layout.frameCount);
  for (const LogicalDatagram& d : layout.datagrams) {
    EniCyclicCmd cmd;
    cmd.state = statesText(d.states);
    cmd.cmd = static_cast<std::uint8_t>(d.command);
    if (isLogical(d.command)) {
      cmd.addr = d.logicalStart;
    } else {  // ADP | ADO << 16 (master/process_image.hpp)
      cmd.adp = static_cast<std::uint16_t>(d.logicalStart & 0xFFFFu);
      cmd.ado = static_cast<std::uint16_t>(d.logicalStart >> 16);
    }
    cmd.dataLength = d.length;
    if (d.checkWkc) cmd.cnt = d.expectedWkc;
    cmd.inputOffs = frameOffset[d.frame] + 10;
    cmd.outputOffs = frameOffset[d.frame] + 10;
    frameOffset[d.frame] += 10u + d.length + 2u;
    cyclic.frames[d.frame].cmds.push_back(cmd);
  }
  eni.cyclic.push_back(std::move(cyclic));
  eni.processImage.outputByteSize = layout.outputBytes;
  eni.processImage.inputByteSize = layout.inputBytes;
  for (const ProcessVariable& v : processVariables(layout)) {
    const EniSlave& owner = eni.slaves[v.position];
    std::uint16_t type = 0;
    for (const auto& sm : layout.slaves[v.position].sms) {
      for (const auto& pdo : sm.pdos) {
        for (const auto& entry : pdo.entries) {
          if (entry.index == v.index && entry.subindex == v.subindex) type = entry.dataType;
        }
      }
    }
    EniVariable var;
    var.name = owner.name + "." + v.pdoName + "." + v.entryName;
    var.dataType = dataTypeName(type, v.bitLength);
    var.bitSize = v.bitLength;
    var.bitOffs = v.bitOffset + layout.logicalBase * 8;
    (v.output ? eni.processImage.outputs : eni.processImage.inputs).push_back(std::move(var));
  }
  return eni;
}

}  // namespace ecsim::master
