#include "master/eni_config.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>

#include "protocol/frame.hpp"

namespace ecsim::master {
namespace {

std::string hex8(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08X", v);
  return buf;
}

bool hasTransition(const std::vector<EniTransition>& list, char from, char to) {
  for (const auto& t : list) {
    if (t.from == from && t.to == to) return true;
  }
  return false;
}

}  // namespace

Status checkIdentities(const MasterConfig& config, const std::vector<SlaveInfo>& slaves,
                       IdentityCheck check) {
  if (config.slaves.size() != slaves.size()) {
    return makeError(ErrorCode::kNotFound,
                     config.file + " expects " + std::to_string(config.slaves.size()) +
                         " slaves, the bus has " + std::to_string(slaves.size()));
  }
  std::string context;
  for (std::size_t i = 0; i < slaves.size(); ++i) {
    const ExpectedSlave& want = config.slaves[i];
    const SiiIdentity& have = slaves[i].identity();
    std::string diff;
    auto compare = [&](std::string_view what, std::uint32_t expected, std::uint32_t found) {
      if (expected == found) return;
      diff += (diff.empty() ? "" : ", ") + std::string(what) + " " + hex8(found) + " (expected " +
              hex8(expected) + ")";
    };
    compare("vendor", want.vendorId, have.vendorId);
    compare("product code", want.productCode, have.productCode);
    if (want.revision) compare("revision", *want.revision, have.revision);
    if (want.serial && check.serial) compare("serial", *want.serial, have.serial);
    if (diff.empty()) continue;
    // The name the slave's SII gives, beside the one it is configured under.
    char found[48];
    std::snprintf(found, sizeof found, "slave %zu (0x%04X", slaves[i].position, slaves[i].station);
    std::string who =
        std::string(found) + (slaves[i].name.empty() ? "" : " '" + slaves[i].name + "'") + ")";
    std::string expected = want.name.empty() ? "" : " configured as '" + want.name + "'";
    context += (context.empty() ? "" : "; ") + who + expected + ", " + config.file + " line " +
               std::to_string(want.line) + ": " + diff;
  }
  if (context.empty()) return okStatus();
  return makeError(ErrorCode::kInvalidArgument, "identity mismatch: " + context);
}

char eniStateLetter(AlState state) {
  switch (state) {
    case AlState::kInit:
      return 'I';
    case AlState::kPreOp:
      return 'P';
    case AlState::kBootstrap:
      return 'B';
    case AlState::kSafeOp:
      return 'S';
    case AlState::kOp:
      return 'O';
  }
  return 'I';
}

std::size_t addEniRegisterCmds(DatagramBatch& batch, const EniSlave& slave, char from, char to,
                               std::vector<int>* lines) {
  constexpr std::uint16_t kAlControl = 0x0120;
  std::size_t added = 0;
  for (const EniRegisterCmd& c : slave.initCmds) {
    if (!hasTransition(c.transitions, from, to)) continue;
    if (c.ado == kAlControl) continue;
    const auto command = static_cast<Command>(c.cmd);
    const std::uint32_t address = DatagramHeader::physical(c.adp, c.ado);
    const std::uint16_t wkc = c.cnt.value_or(1);
    Datagram& d = batch.add();
    if (c.data.empty()) {
      d.prepare(command, address, static_cast<std::uint16_t>(c.length()), wkc);
    } else {
      d.prepare(command, address, ConstBytes(c.data.data(), c.data.size()), wkc);
    }
    if (lines != nullptr) lines->push_back(c.line);
    ++added;
  }
  return added;
}

std::vector<const EniCoeCmd*> eniCoeCmds(const EniSlave& slave, char from, char to) {
  std::vector<const EniCoeCmd*> list;
  if (!slave.mailbox) return list;
  for (const EniCoeCmd& c : slave.mailbox->coeInitCmds) {
    if (hasTransition(c.transitions, from, to)) list.push_back(&c);
  }
  return list;
}

namespace {

constexpr std::size_t kFrameDataCapacity =
    kMaxFrameSize - kEthernetHeaderSize - kEtherCatHeaderSize;
constexpr std::uint32_t kFramePrefix = kEthernetHeaderSize + kEtherCatHeaderSize;

std::string where(const EniConfig& eni, int line) {
  return eni.file.string() + " line " + std::to_string(line);
}

std::string hexAddress(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08X", v);
  return buf;
}

bool sameWord(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::toupper(static_cast<unsigned char>(x)) ==
                  std::toupper(static_cast<unsigned char>(y));
         });
}

Result<std::uint8_t> parseStates(const EniConfig& eni, const EniCyclicCmd& c) {
  if (c.state.empty()) return kAllStates;
  std::uint8_t mask = 0;
  std::size_t pos = 0;
  while (pos < c.state.size()) {
    const std::size_t end = std::min(c.state.find(' ', pos), c.state.size());
    const std::string_view word = std::string_view(c.state).substr(pos, end - pos);
    pos = end + 1;
    if (word.empty()) continue;
    if (sameWord(word, "INIT")) {
      mask |= stateBit(AlState::kInit);
    } else if (sameWord(word, "PREOP")) {
      mask |= stateBit(AlState::kPreOp);
    } else if (sameWord(word, "SAFEOP")) {
      mask |= stateBit(AlState::kSafeOp);
    } else if (sameWord(word, "OP")) {
      mask |= stateBit(AlState::kOp);
    } else if (sameWord(word, "BOOT")) {
      mask |= stateBit(AlState::kBootstrap);
    } else {
      return makeError(ErrorCode::kInvalidArgument, where(eni, c.line) + ": cyclic Cmd <State> '" +
                                                        std::string(word) +
                                                        "' is not INIT, PREOP, SAFEOP, OP or BOOT");
    }
  }
  return mask;
}

struct PlacedCmd {
  const EniCyclicCmd* cmd{nullptr};
  Command command{Command::kNop};
  std::size_t frame{0};
};

// The ENI's cyclic Cmds placed in frames, and how its process-image bits map to logical ones.
class EniImage {
 public:
  static Result<EniImage> make(const EniConfig& eni) {
    EniImage image;
    if (eni.cyclic.size() > 1) {
      return makeError(ErrorCode::kUnsupported, eni.file.string() + ": " +
                                                    std::to_string(eni.cyclic.size()) +
                                                    " <Cyclic> tasks; the master runs one cycle");
    }
    std::vector<std::uint32_t> dataOffsets;  // per Cmd: its data's offset in the frame
    std::size_t frame = 0;
    for (const EniCyclic& cyclic : eni.cyclic) {
      for (const EniFrame& f : cyclic.frames) {
        if (f.cmds.empty()) continue;
        std::size_t used = 0;
        for (const EniCyclicCmd& c : f.cmds) {
          const std::string at = where(eni, c.line);
          if (!isKnownCommand(c.cmd) || c.cmd == static_cast<std::uint8_t>(Command::kNop)) {
            return makeError(ErrorCode::kUnsupported,
                             at + ": cyclic Cmd " + std::to_string(c.cmd) +
                                 " is no EtherCAT command the master can send");
          }
          const auto command = static_cast<Command>(c.cmd);
          if (isLogical(command) && !c.addr) {
            return makeError(
                ErrorCode::kInvalidArgument,
                at + ": logical cyclic Cmd " + std::string(toString(command)) + " needs <Addr>");
          }
          const std::size_t wire = kDatagramOverhead + c.dataLength;
          if (used + wire > kFrameDataCapacity) {
            return makeError(
                ErrorCode::kTooLarge,
                at + ": DataLength " + std::to_string(c.dataLength) + " does not fit in frame " +
                    std::to_string(frame) + " (" + std::to_string(used) + " of " +
                    std::to_string(kFrameDataCapacity) + " bytes taken by the Cmds before it)");
          }
          dataOffsets.push_back(static_cast<std::uint32_t>(kFramePrefix + used) +
                                static_cast<std::uint32_t>(kDatagramHeaderSize));
          used += wire;
          image.cmds_.push_back({&c, command, frame});
        }
        if (f.cmds.size() > Transport::kMaxDatagramsPerFrame) {
          return makeError(ErrorCode::kTooLarge,
                           where(eni, f.cmds.back().line) + ": more than " +
                               std::to_string(Transport::kMaxDatagramsPerFrame) +
                               " Cmds in one frame");
        }
        ++frame;
      }
    }
    image.frameCount_ = frame;
    // ETG.2100 images when every logical Cmd's offsets lie inside them.
    const std::uint32_t outSize = eni.processImage.outputByteSize.value_or(0);
    const std::uint32_t inSize = eni.processImage.inputByteSize.value_or(0);
    bool anyOffset = false;
    bool inside = true;
    for (const PlacedCmd& p : image.cmds_) {
      if (!isLogical(p.command)) continue;
      const CommandAccess access = commandAccess(p.command);
      const EniCyclicCmd& c = *p.cmd;
      if (access.write && c.outputOffs) {
        anyOffset = true;
        inside = inside && *c.outputOffs + c.dataLength <= outSize;
      }
      if (access.read && c.inputOffs) {
        anyOffset = true;
        inside = inside && *c.inputOffs + c.dataLength <= inSize;
      }
    }
    image.frameImage_ = anyOffset && inside;
    if (image.frameImage_) return image;
    // Logical images: the offsets are the data's place in the frame.
    for (std::size_t i = 0; i < image.cmds_.size(); ++i) {
      const EniCyclicCmd& c = *image.cmds_[i].cmd;
      auto check = [&](const std::optional<std::uint32_t>& offs, std::string_view what,
                       std::uint32_t size) -> Status {
        if (!offs || *offs == dataOffsets[i]) return okStatus();
        return makeError(
            ErrorCode::kInvalidArgument,
            where(eni, c.line) + ": " + std::string(what) + " " + std::to_string(*offs) +
                " is neither the data's offset in the frame (" + std::to_string(dataOffsets[i]) +
                ") nor, with DataLength " + std::to_string(c.dataLength) + ", inside the " +
                std::to_string(size) + "-byte process image");
      };
      ECSIM_TRY(check(c.outputOffs, "OutputOffs", outSize));
      ECSIM_TRY(check(c.inputOffs, "InputOffs", inSize));
    }
    return image;
  }

  const std::vector<PlacedCmd>& cmds() const { return cmds_; }
  std::size_t frameCount() const { return frameCount_; }
  bool frameImage() const { return frameImage_; }

  // The logical bit address of bit `bit` of the ENI's output or input image.
  std::optional<std::uint64_t> logicalBit(bool output, std::uint32_t bit) const {
    if (!frameImage_) return bit;
    const std::uint32_t byte = bit / 8;
    for (const PlacedCmd& p : cmds_) {
      if (!isLogical(p.command)) continue;
      const CommandAccess access = commandAccess(p.command);
      const auto& offs = output ? p.cmd->outputOffs : p.cmd->inputOffs;
      if (!(output ? access.write : access.read) || !offs) continue;
      if (byte < *offs || byte >= *offs + p.cmd->dataLength) continue;
      return (static_cast<std::uint64_t>(*p.cmd->addr) + (byte - *offs)) * 8 + bit % 8;
    }
    return std::nullopt;
  }

 private:
  std::vector<PlacedCmd> cmds_;
  std::size_t frameCount_{0};
  bool frameImage_{false};
};

struct SlaveArea {
  std::uint64_t start{0};  // logical byte address
  std::uint64_t end{0};
  bool output{true};
  std::size_t position{0};
};

// Puts the SMs of `sl` with data in direction `outputs` where the ENI slave's ranges say.
Status placeSlave(const EniConfig& eni, const EniImage& image, const EniSlave& want,
                  const SlaveInfo& slave, SlaveLayout& sl, bool outputs,
                  std::vector<SlaveArea>& areas) {
  std::vector<SmLayout*> sms;
  std::uint32_t bytes = 0;
  for (auto& sm : sl.sms) {
    if (sm.outputs != outputs || sm.setting.length == 0) continue;
    sms.push_back(&sm);
    bytes += sm.setting.length;
  }
  if (sms.empty()) return okStatus();
  const auto& ranges = outputs ? want.processData.send : want.processData.recv;
  const std::string what = slave.label() + " (" + where(eni, want.line) + ")";
  const char* element = outputs ? "<Send>" : "<Recv>";
  if (ranges.empty()) {
    return makeError(ErrorCode::kInvalidArgument,
                     what + " has " + std::to_string(bytes) + (outputs ? " output" : " input") +
                         " bytes; its <ProcessData> has no " + element + " range");
  }
  if (ranges.size() != 1 && ranges.size() != sms.size()) {
    return makeError(ErrorCode::kInvalidArgument,
                     what + ": " + std::to_string(ranges.size()) + " " + element + " ranges for " +
                         std::to_string(sms.size()) + " SMs with data");
  }
  for (std::size_t r = 0; r < ranges.size(); ++r) {
    const EniBitRange& range = ranges[r];
    const std::uint32_t wantBytes = ranges.size() == 1 ? bytes : sms[r]->setting.length;
    if ((range.bitLength + 7) / 8 != wantBytes) {
      return makeError(ErrorCode::kInvalidArgument,
                       what + ": " + element + " BitLength " + std::to_string(range.bitLength) +
                           ", the slave's SM data is " + std::to_string(wantBytes) + " bytes");
    }
    const auto logical = image.logicalBit(outputs, range.bitStart);
    if (!logical || *logical % 8 != 0) {
      return makeError(
          ErrorCode::kInvalidArgument,
          what + ": " + element + " BitStart " + std::to_string(range.bitStart) +
              (logical ? " is not at a byte boundary" : " lies in no logical cyclic Cmd's data"));
    }
    std::uint64_t at = *logical / 8;
    if (at + wantBytes > 0xFFFFFFFFull) {
      return makeError(ErrorCode::kInvalidArgument,
                       what + ": " + element + " beyond the 4 GiB logical address space");
    }
    const std::size_t first = ranges.size() == 1 ? 0 : r;
    const std::size_t last = ranges.size() == 1 ? sms.size() : r + 1;
    for (std::size_t k = first; k < last; ++k) {
      sms[k]->logicalStart = static_cast<std::uint32_t>(at);
      areas.push_back({at, at + sms[k]->setting.length, outputs, sl.position});
      at += sms[k]->setting.length;
    }
  }
  return okStatus();
}

std::uint16_t dataTypeCode(std::string_view name) {
  static constexpr std::pair<std::string_view, std::uint16_t> kTypes[] = {
      {"BOOL", 0x0001},  {"BIT", 0x0001},  {"SINT", 0x0002},  {"INT", 0x0003},  {"DINT", 0x0004},
      {"USINT", 0x0005}, {"BYTE", 0x0005}, {"UINT", 0x0006},  {"WORD", 0x0006}, {"UDINT", 0x0007},
      {"DWORD", 0x0007}, {"REAL", 0x0008}, {"LREAL", 0x0011}, {"LINT", 0x0015}, {"ULINT", 0x001B}};
  for (const auto& [text, code] : kTypes) {
    if (sameWord(name, text)) return code;
  }
  return 0;
}

}  // namespace

Result<ProcessImageLayout> planLayout(const std::optional<MasterConfig>& config,
                                      const std::vector<SlaveInfo>& slaves,
                                      const std::vector<SlaveProcessData>& processData,
                                      const LayoutOptions& options) {
  if (config && config->eni && !config->eni->cyclic.empty()) {
    return planEniLayout(*config->eni, slaves, processData, options);
  }
  return planProcessImage(slaves, processData, options);
}

Result<ProcessImageLayout> planEniLayout(const EniConfig& eni, const std::vector<SlaveInfo>& slaves,
                                         const std::vector<SlaveProcessData>& processData,
                                         const LayoutOptions& options) {
  ECSIM_ASSIGN_OR_RETURN(EniImage image, EniImage::make(eni));
  if (eni.slaves.size() != slaves.size()) {
    return makeError(ErrorCode::kNotFound, eni.file.string() + " has " +
                                               std::to_string(eni.slaves.size()) +
                                               " slaves, the bus " + std::to_string(slaves.size()));
  }
  ECSIM_ASSIGN_OR_RETURN(ProcessImageLayout layout, planProcessImage(slaves, processData, options));
  // The slaves' SMs where the ENI puts them.
  std::vector<SlaveArea> areas;
  for (auto& sl : layout.slaves) {
    for (bool outputs : {true, false}) {
      ECSIM_TRY(
          placeSlave(eni, image, eni.slaves[sl.position], slaves[sl.position], sl, outputs, areas));
    }
  }
  std::sort(areas.begin(), areas.end(),
            [](const SlaveArea& a, const SlaveArea& b) { return a.start < b.start; });
  for (std::size_t i = 1; i < areas.size(); ++i) {
    if (areas[i].start < areas[i - 1].end) {
      return makeError(ErrorCode::kInvalidArgument,
                       eni.file.string() + ": the process data of " +
                           slaves[areas[i - 1].position].label() + " and " +
                           slaves[areas[i].position].label() + " overlap at logical " +
                           hexAddress(static_cast<std::uint32_t>(areas[i].start)));
    }
  }
  std::uint64_t base = options.logicalBase;
  if (!areas.empty()) {
    base = areas.front().start;
  } else {
    bool first = true;
    for (const PlacedCmd& p : image.cmds()) {
      if (!isLogical(p.command)) continue;
      base = first ? *p.cmd->addr : std::min<std::uint64_t>(base, *p.cmd->addr);
      first = false;
    }
  }
  std::uint64_t outEnd = base;
  std::uint64_t end = base;
  for (const SlaveArea& a : areas) {
    if (a.output) outEnd = std::max(outEnd, a.end);
    end = std::max(end, a.end);
  }
  for (const SlaveArea& a : areas) {
    if (a.output || a.start >= outEnd) continue;
    return makeError(ErrorCode::kUnsupported, eni.file.string() + ": the inputs of " +
                                                  slaves[a.position].label() + " at logical " +
                                                  hexAddress(static_cast<std::uint32_t>(a.start)) +
                                                  " lie below the end of the outputs (" +
                                                  hexAddress(static_cast<std::uint32_t>(outEnd)) +
                                                  "); the master's image keeps all outputs first");
  }
  layout.logicalBase = static_cast<std::uint32_t>(base);
  layout.outputBytes = static_cast<std::uint32_t>(outEnd - base);
  layout.inputBytes = static_cast<std::uint32_t>(end - outEnd);
  for (auto& sl : layout.slaves) {
    for (bool outputs : {true, false}) {
      std::optional<std::uint32_t> start;
      for (const auto& sm : sl.sms) {
        if (sm.outputs != outputs || sm.setting.length == 0) continue;
        start = std::min(start.value_or(sm.logicalStart), sm.logicalStart);
      }
      if (start) (outputs ? sl.outputOffset : sl.inputOffset) = *start - layout.logicalBase;
    }
    sl.fmmus = fmmusOf(sl);
  }
  // The datagrams: the ENI's Cmds.
  layout.datagrams.clear();
  const std::uint64_t imageEnd = base + layout.size();
  for (const PlacedCmd& p : image.cmds()) {
    const EniCyclicCmd& c = *p.cmd;
    const std::string at = where(eni, c.line);
    LogicalDatagram d;
    d.command = p.command;
    d.length = c.dataLength;
    d.frame = p.frame;
    d.line = c.line;
    ECSIM_ASSIGN_OR_RETURN(d.states, parseStates(eni, c));
    const CommandAccess access = commandAccess(p.command);
    std::uint32_t computed = 0;  // logical: the ESC rule; others: the most the slaves can add
    if (isLogical(p.command)) {
      d.logicalStart = *c.addr;
      const std::uint64_t from = *c.addr;
      const std::uint64_t to = from + c.dataLength;
      if (from < base || to > imageEnd) {
        return makeError(ErrorCode::kInvalidArgument,
                         at + ": " + std::string(toString(p.command)) + " " + hexAddress(*c.addr) +
                             "+" + std::to_string(c.dataLength) +
                             " reaches outside the process image (logical " +
                             hexAddress(static_cast<std::uint32_t>(base)) + " to " +
                             hexAddress(static_cast<std::uint32_t>(imageEnd)) + ")");
      }
      for (const auto& sl : layout.slaves) {
        bool out = false;
        bool in = false;
        for (const SlaveArea& a : areas) {
          if (a.position != sl.position || a.start >= to || from >= a.end) continue;
          (a.output ? out : in) = true;
        }
        const std::uint32_t add =
            (out && access.write ? (access.read ? 2u : 1u) : 0u) + (in && access.read ? 1u : 0u);
        if (add == 0) continue;
        computed += add;
        d.slaves.push_back(sl.position);
        d.contributions.push_back(static_cast<std::uint16_t>(add));
      }
    } else {
      const std::uint16_t adp = c.adp.value_or(0);
      d.logicalStart = DatagramHeader::physical(adp, c.ado.value_or(0));
      const std::uint32_t perSlave = access.read && access.write ? 3u : 1u;
      const bool everySlave = addressMode(p.command) == AddressMode::kBroadcast ||
                              p.command == Command::kArmw || p.command == Command::kFrmw;
      for (const SlaveInfo& s : slaves) {
        const bool addressed =
            everySlave ||
            (addressMode(p.command) == AddressMode::kAutoIncrement &&
             static_cast<std::uint16_t>(0x10000u - adp) == s.position) ||
            (addressMode(p.command) == AddressMode::kConfigured && s.station == adp);
        if (!addressed) continue;
        const std::uint32_t add =
            everySlave && !(addressMode(p.command) == AddressMode::kBroadcast) ? 1u : perSlave;
        d.slaves.push_back(s.position);
        d.contributions.push_back(static_cast<std::uint16_t>(add));
        computed += add;
      }
    }
    if (c.cnt) {
      const bool wrong = isLogical(p.command) ? *c.cnt != computed : *c.cnt > computed;
      if (wrong) {
        std::string why =
            isLogical(p.command)
                ? "the slaves mapped there give " + std::to_string(computed) +
                      " (2 per slave whose outputs an LRW writes, 1 per slave an LWR writes or "
                      "whose inputs it reads)"
                : "the slaves it addresses can add at most " + std::to_string(computed);
        return makeError(ErrorCode::kInvalidArgument,
                         at + ": Cnt " + std::to_string(*c.cnt) + " cannot be right: " + why);
      }
      d.expectedWkc = *c.cnt;
    } else {
      d.expectedWkc = static_cast<std::uint16_t>(std::min<std::uint32_t>(computed, 0xFFFF));
      d.checkWkc = isLogical(p.command);
    }
    layout.datagrams.push_back(std::move(d));
  }
  layout.frameCount = image.frameCount();
  return layout;
}

Status addEniVariables(std::vector<VariableInfo>& variables, const EniConfig& eni,
                       const ProcessImageLayout& layout) {
  ECSIM_ASSIGN_OR_RETURN(EniImage image, EniImage::make(eni));
  const std::size_t own = variables.size();
  for (bool output : {true, false}) {
    for (const EniVariable& var : output ? eni.processImage.outputs : eni.processImage.inputs) {
      if (var.bitSize == 0 || var.bitSize > 64) continue;  // no typed access beyond 64 bits
      const std::string what = "variable '" + var.name + "' (" + where(eni, var.line) + ")";
      const auto logical = image.logicalBit(output, var.bitOffs);
      if (!logical) continue;  // not in logical data (an ETG.2100 image's frame status, ...)
      const std::uint64_t lowest =
          (static_cast<std::uint64_t>(layout.logicalBase) + (output ? 0u : layout.outputBytes)) * 8;
      const std::uint64_t highest = (static_cast<std::uint64_t>(layout.logicalBase) +
                                     (output ? layout.outputBytes : layout.size())) *
                                    8;
      if (*logical < lowest || *logical + var.bitSize > highest) {
        return makeError(ErrorCode::kInvalidArgument,
                         what + " at bit " + std::to_string(var.bitOffs) + " lies outside the " +
                             (output ? "outputs" : "inputs") + " of the process image (logical " +
                             hexAddress(static_cast<std::uint32_t>(lowest / 8)) + " to " +
                             hexAddress(static_cast<std::uint32_t>(highest / 8)) + ")");
      }
      const auto bit = static_cast<std::uint32_t>(*logical - layout.logicalBase * 8ull);
      const auto length = static_cast<std::uint8_t>(var.bitSize);
      bool named = false;
      for (std::size_t k = 0; k < variables.size(); ++k) {
        if (variables[k].name == var.name) named = true;
      }
      if (named) continue;
      std::optional<VariableInfo> v;
      for (std::size_t k = 0; k < own; ++k) {
        const VariableInfo& mine = variables[k];
        if (mine.output == output && mine.bitOffset == bit && mine.bitLength == length) v = mine;
      }
      if (!v) {
        v = VariableInfo{};
        const auto dot = var.name.find('.');
        v->slave = var.name.substr(0, dot);
        v->entry = dot == std::string::npos ? var.name : var.name.substr(dot + 1);
        v->output = output;
        v->bitOffset = bit;
        v->bitLength = length;
        v->dataType = dataTypeCode(var.dataType);
        v->type = variableType(v->dataType, length);
        for (const auto& sl : layout.slaves) {
          const std::uint32_t start = output ? sl.outputOffset : sl.inputOffset;
          const std::uint32_t bytes = output ? sl.outputBytes : sl.inputBytes;
          if (bytes > 0 && bit / 8 >= start && bit / 8 < start + bytes) v->position = sl.position;
        }
      }
      v->name = var.name;
      variables.push_back(std::move(*v));
    }
  }
  return okStatus();
}

}  // namespace ecsim::master
