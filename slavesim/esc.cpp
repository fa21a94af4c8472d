#include "slavesim/esc.hpp"

#include <algorithm>
#include <cstring>

namespace ecsim::slavesim {
namespace {

constexpr std::uint16_t kRamStart = reg::kRegisterSpaceEnd;

// DC system time is a 64-bit counter that wraps; offsets come from the master unchecked.
SimTime wrapAdd(SimTime a, std::uint64_t b) {
  return static_cast<SimTime>(static_cast<std::uint64_t>(a) + b);
}

// The SII words the ESC loads into registers at power-on (datasheet section I §11.1).
constexpr std::size_t kSiiPdiControlWord = 0x00;
constexpr std::size_t kSiiPdiConfigWord = 0x01;
constexpr std::size_t kSiiSyncPulseWord = 0x02;
constexpr std::size_t kSiiExtendedPdiWord = 0x03;
constexpr std::size_t kSiiAliasWord = 0x04;
constexpr std::size_t kSiiChecksumWord = 0x07;

std::uint8_t siiCrc(const std::vector<std::uint8_t>& sii) {
  std::uint8_t crc = 0xFF;
  for (std::size_t i = 0; i < 14 && i < sii.size(); ++i) {
    crc ^= sii[i];
    for (int b = 0; b < 8; ++b) {
      crc = static_cast<std::uint8_t>((crc & 0x80) ? (crc << 1) ^ 0x07 : (crc << 1));
    }
  }
  return crc;
}

std::uint16_t siiWord(const std::vector<std::uint8_t>& sii, std::size_t word) {
  std::size_t at = 2 * word;
  if (at + 1 >= sii.size()) return 0xFFFF;
  return static_cast<std::uint16_t>(sii[at] | (sii[at + 1] << 8));
}

bool overlaps(std::uint32_t begin, std::uint32_t end, std::uint16_t regBegin, std::uint16_t width) {
  return begin < static_cast<std::uint32_t>(regBegin + width) && regBegin < end;
}

}  // namespace

std::optional<EscType> escTypeByName(std::string_view name) {
  for (const EscType& t : {kEt1100, kEt1200, kLan9252}) {
    if (t.name == name) return t;
  }
  return std::nullopt;
}

// ECAT write masks of the register space, one byte per register byte: the same for every ESC
// type this simulator models, so one immutable table is shared by all ESCs (it stays hot in
// the cache when a frame passes a thousand of them).
const std::array<std::uint8_t, kRamStart>& ecatWriteMasks() {
  static const std::array<std::uint8_t, kRamStart> table = [] {
    std::array<std::uint8_t, kRamStart> masks{};
    // ECAT write masks (datasheet section II register tables, column "ECAT"). Everything not
    // listed is read-only for the master.
    auto allow = [&](std::uint16_t address, std::uint16_t width, std::uint8_t mask = 0xFF) {
      for (std::uint16_t i = 0; i < width; ++i) masks[address + i] = mask;
    };
    allow(reg::kConfiguredStationAddress.address, 2);
    allow(reg::kRegisterWriteEnable.address, 1, 0x01);
    allow(reg::kRegisterWriteProtection.address, 1, 0x01);
    allow(reg::kEscWriteEnable.address, 1, 0x01);
    allow(reg::kEscWriteProtection.address, 1, 0x01);
    allow(reg::kEscResetEcat.address, 1);
    allow(reg::kDlControl.address, 4);
    allow(reg::kPhysicalRwOffset.address, 2);
    allow(reg::kAlControl.address, 2);
    allow(reg::kRunLedOverride.address, 2);
    allow(reg::kEcatEventMask.address, 2);
    allow(reg::kErrorCountersBegin, reg::kErrorCountersEnd - reg::kErrorCountersBegin);
    allow(reg::kWatchdogDivider.address, 2);
    allow(reg::kWatchdogTimePdi.address, 2);
    allow(reg::kWatchdogTimeProcessData.address, 2);
    allow(reg::kWatchdogCounterProcessData.address, 2);
    allow(reg::kSiiConfiguration.address, 1, 0x03);
    allow(reg::kSiiControlStatus.address, 1, 0x01);      // write enable
    allow(reg::kSiiControlStatus.address + 1, 1, 0x07);  // command bits 8-10
    allow(reg::kSiiAddress.address, 4);
    allow(reg::kSiiData.address, 8);
    allow(reg::kMiiControlStatus.address, 6);
    allow(reg::kMiiEcatAccessState.address, 1, 0x01);
    allow(reg::kFmmuBase, reg::kFmmuSize * reg::kMaxFmmus);
    for (unsigned n = 0; n < reg::kMaxSyncManagers; ++n) {
      std::uint16_t base = reg::smChannel(n);
      allow(base, 5);                                     // start, length, control
      allow(base + reg::sm::kActivate.address, 1, 0xC3);  // enable, repeat, latch bits
    }
    allow(reg::kReceiveTimePort0.address, 4);  // a write latches, content not changed
    allow(reg::kSystemTime.address, 8);
    allow(reg::kSystemTimeOffset.address, 8);
    allow(reg::kSystemTimeDelay.address, 4);
    allow(reg::kSpeedCounterStart.address, 2);
    allow(reg::kSystemTimeDifferenceFilterDepth.address, 3);
    allow(reg::kCyclicUnitControl.address, 2);
    allow(reg::kStartTimeCyclicOperation.address, 8);
    allow(reg::kSync0CycleTime.address, 8);
    allow(reg::kLatch0Control.address, 2);
    allow(reg::kDigitalIoOutputData.address, 4);
    allow(reg::kGeneralPurposeOutputs.address, 8);
    allow(reg::kUserRam.address, reg::kUserRam.width);
    return masks;
  }();
  return table;
}

Esc::Esc(const EscType& type, std::vector<std::uint8_t> siiImage)
    : type_(type),
      memory_(kRamStart + static_cast<std::size_t>(type.ramKb) * 1024, 0),
      writable_(ecatWriteMasks()),
      buffers_(3 * (kRamStart + static_cast<std::size_t>(type.ramKb) * 1024), 0),
      sii_(std::move(siiImage)) {
  lastMailboxResponse_.resize(static_cast<std::size_t>(type.ramKb) * 1024);
  scratch_.resize(kMaxDatagramLength + 1);
  reset();
}

void Esc::reset() {
  std::fill(memory_.begin(), memory_.end(), 0);
  std::fill(buffers_.begin(), buffers_.end(), 0);
  sm_ = {};
  pdWatchdog_ = {};
  sync_ = {};
  activeFmmuCount_ = 0;
  smRangeCount_ = 0;
  lastMailboxResponseSize_ = 0;
  memory_[reg::kType.address] = type_.typeRegister;
  memory_[reg::kRevision.address] = type_.revisionRegister;
  writeLe16(memory_, reg::kBuild.address, type_.build);
  memory_[reg::kFmmusSupported.address] = type_.fmmus;
  memory_[reg::kSyncManagersSupported.address] = type_.syncManagers;
  memory_[reg::kRamSize.address] = type_.ramKb;
  // Port descriptor: 2 bits per port, 11 = MII, 00 = not implemented.
  std::uint8_t ports = 0;
  for (unsigned p = 0; p < type_.maxPorts; ++p)
    ports = static_cast<std::uint8_t>(ports | (3u << (2 * p)));
  memory_[reg::kPortDescriptor.address] = ports;
  writeLe16(memory_, reg::kEscFeatures.address, type_.features);
  writeLe16(memory_, reg::kAlStatus.address, 0x0001);  // INIT
  writeLe16(memory_, reg::kAlControl.address, 0x0001);
  writeLe16(memory_, reg::kWatchdogDivider.address, 0x09C2);  // 2498 -> 100 us (datasheet)
  writeLe16(memory_, reg::kWatchdogTimePdi.address, 0x03E8);  // 1000 -> 100 ms
  writeLe16(memory_, reg::kWatchdogTimeProcessData.address, 0x03E8);
  writeLe16(memory_, reg::kSpeedCounterStart.address, 0x1000);
  memory_[reg::kSystemTimeDifferenceFilterDepth.address] = 0x04;
  memory_[reg::kSpeedCounterFilterDepth.address] = 0x0C;
  loadFromSii();
}

void Esc::powerOnReset() {
  reset();
}

void Esc::loadFromSii() {
  std::uint16_t status = type_.siiRead8Bytes ? reg::sii::kReadSize8Bytes : 0;
  if (sii_.size() > 2048) status |= reg::sii::kTwoAddressBytes;  // > 16 kbit
  std::uint16_t dl = reg16(reg::kDlStatus.address);
  if (sii_.size() >= 16 && (siiCrc(sii_) == (siiWord(sii_, kSiiChecksumWord) & 0xFF) ||
                            siiWord(sii_, kSiiChecksumWord) == 0x88A4)) {
    std::uint16_t pdi = siiWord(sii_, kSiiPdiControlWord);
    memory_[reg::kPdiControl.address] = static_cast<std::uint8_t>(pdi);
    memory_[reg::kEscConfiguration.address] = static_cast<std::uint8_t>(pdi >> 8);
    writeLe16(memory_, reg::kPdiConfiguration.address, siiWord(sii_, kSiiPdiConfigWord));
    writeLe16(memory_, reg::kSyncPulseLength.address, siiWord(sii_, kSiiSyncPulseWord));
    writeLe16(memory_, reg::kExtendedPdiConfiguration.address, siiWord(sii_, kSiiExtendedPdiWord));
    writeLe16(memory_, reg::kConfiguredStationAlias.address, siiWord(sii_, kSiiAliasWord));
    dl = static_cast<std::uint16_t>(dl | reg::dl_status::kPdiOperational);
  } else {
    // Checksum error: the ESC does not load the configuration and the PDI stays off.
    status |= reg::sii::kChecksumError;
    dl = static_cast<std::uint16_t>(dl & ~reg::dl_status::kPdiOperational);
  }
  writeLe16(memory_, reg::kSiiControlStatus.address, status);
  writeLe16(memory_, reg::kDlStatus.address, dl);
}

// ---- ECAT side ------------------------------------------------------------------------------

SimTime Esc::systemTime(SimTime time) const {
  return wrapAdd(dc_.localTime(time), reg64(reg::kSystemTimeOffset.address));
}

void Esc::processDatagram(DatagramView d, SimTime time) {
  lastWkcIncrement_ = 0;
  now_ = time;
  localNow_ = dc_.localTime(time);
  if (!isKnownCommand(d.rawCommand())) return;  // unknown command: forwarded untouched
  const Command cmd = d.command();
  const std::uint16_t len = d.length();
  std::uint16_t inc = 0;
  switch (addressMode(cmd)) {
    case AddressMode::kNone:
      return;
    case AddressMode::kLogical: {
      bool doRead = cmd != Command::kLwr;
      bool doWrite = cmd != Command::kLrd;
      auto [readHit, writeHit] = processLogical(d, doRead, doWrite);
      inc = static_cast<std::uint16_t>((readHit ? 1 : 0) +
                                       (writeHit ? (cmd == Command::kLwr ? 1 : 2) : 0));
      break;
    }
    case AddressMode::kAutoIncrement:
    case AddressMode::kConfigured:
    case AddressMode::kBroadcast: {
      const AddressMode mode = addressMode(cmd);
      bool addressed;
      if (mode == AddressMode::kAutoIncrement) {
        addressed = d.adp() == 0;
        d.setAdp(static_cast<std::uint16_t>(d.adp() + 1));
      } else if (mode == AddressMode::kBroadcast) {
        addressed = true;
        d.setAdp(static_cast<std::uint16_t>(d.adp() + 1));
      } else {
        std::uint16_t station = reg16(reg::kConfiguredStationAddress.address);
        bool aliasOn = (memory_[reg::kDlControl.address + 3] & 0x01) != 0;
        addressed = d.adp() == station ||
                    (aliasOn && d.adp() == reg16(reg::kConfiguredStationAlias.address));
      }
      const std::uint16_t ado = d.ado();
      const auto end = static_cast<std::uint32_t>(ado) + len;
      if (cmd == Command::kArmw || cmd == Command::kFrmw) {
        // Read at the addressed slave, write at every other one (datasheet Table 7).
        if (addressed) {
          refreshVolatile(ado, static_cast<std::uint16_t>(std::min<std::uint32_t>(end, 0xFFFF)));
          readMemory(ado, d.data(), false);
          inc = 1;
        } else if (writeMemory(ado, d.data())) {
          inc = 1;
        }
        break;
      }
      if (!addressed) break;
      ++counters_.datagramsAddressed;
      CommandAccess access = commandAccess(cmd);
      if (access.read) {
        refreshVolatile(ado, static_cast<std::uint16_t>(std::min<std::uint32_t>(end, 0xFFFF)));
        // Read-write commands: the data read is the memory before the write.
        if (access.write) {
          std::copy(d.data().begin(), d.data().end(), scratch_.begin());
          bool readOk = readMemory(ado, d.data(), mode == AddressMode::kBroadcast);
          bool writeOk = writeMemory(ado, ConstBytes(scratch_.data(), len));
          inc = static_cast<std::uint16_t>((readOk ? 1 : 0) + (writeOk ? 2 : 0));
        } else {
          inc = readMemory(ado, d.data(), mode == AddressMode::kBroadcast) ? 1 : 0;
        }
      } else if (access.write) {
        if (ado <= reg::kReceiveTimePort0.address && end > reg::kReceiveTimePort0.address) {
          latchReceiveTimes();
        }
        inc = writeMemory(ado, d.data()) ? 1 : 0;
      }
      break;
    }
  }
  lastWkcIncrement_ = inc;
  if (inc != 0) d.setWkc(static_cast<std::uint16_t>(d.wkc() + inc));
}

}  // namespace ecsim::slavesim

namespace ecsim::slavesim {

bool Esc::readMemory(std::uint32_t address, Bytes out, bool orInto) {
  const std::uint32_t size = static_cast<std::uint32_t>(out.size());
  const std::uint32_t memEnd = static_cast<std::uint32_t>(memory_.size());
  bool any = false;
  std::uint32_t at = address;
  while (at < address + size) {
    Bytes piece = out.subspan(at - address);
    if (at >= memEnd) {
      // Beyond the ESC's memory: reads give 0 (datasheet: unused addresses read as 0).
      if (!orInto) std::fill(piece.begin(), piece.end(), 0);
      ++counters_.outOfRangeAccesses;
      any = true;
      break;
    }
    // SyncManagers may cover process RAM and the upper register area (digital I/O terminals
    // put their output SM at 0x0F00): split the access at SM boundaries first.
    auto a16 = static_cast<std::uint16_t>(at);
    std::uint32_t limit = std::min(address + size, memEnd);
    int smIndex = smLookup(at, limit);
    if (smIndex < 0 && at < kRamStart) {
      std::uint32_t n = std::min<std::uint32_t>(limit, kRamStart) - at;
      for (std::uint32_t i = 0; i < n; ++i) {
        piece[i] = orInto ? static_cast<std::uint8_t>(piece[i] | memory_[at + i]) : memory_[at + i];
      }
      any |= implemented(at, n);
      at += n;
      continue;
    }
    std::uint32_t n = limit - at;
    if (readRam(a16, piece.first(n), orInto, smIndex)) any = true;
    at += n;
  }
  return any;
}

bool Esc::writeMemory(std::uint32_t address, ConstBytes data) {
  const std::uint32_t size = static_cast<std::uint32_t>(data.size());
  const std::uint32_t memEnd = static_cast<std::uint32_t>(memory_.size());
  bool any = false;
  std::uint32_t at = address;
  while (at < address + size) {
    ConstBytes piece = data.subspan(at - address);
    if (at >= memEnd) {
      ++counters_.outOfRangeAccesses;
      any = true;  // accepted and ignored
      break;
    }
    auto a16 = static_cast<std::uint16_t>(at);
    std::uint32_t limit = std::min(address + size, memEnd);
    int smIndex = smLookup(at, limit);
    if (smIndex < 0 && at < kRamStart) {
      std::uint32_t n = std::min<std::uint32_t>(limit, kRamStart) - at;
      // A write only counts when some byte of it is writable (real ESCs give no WKC for a
      // write to read-only registers such as 0x092C: replay-dc.pcapng frame 75).
      any |= writeRegisters(static_cast<std::uint16_t>(at), piece.first(n)) && implemented(at, n);
      at += n;
      continue;
    }
    std::uint32_t n = limit - at;
    if (writeRam(a16, piece.first(n), smIndex)) any = true;
    at += n;
  }
  return any;
}

bool Esc::implemented(std::uint32_t at, std::uint32_t n) const {
  // Registers of FMMU and SM channels beyond what the ESC has, and of a DC unit it lacks, do
  // not exist: an access that touches only those gets no working-counter increment (seen on
  // real ET1200 terminals and an EK1100, docs/fidelity.md). Everything else answers.
  const std::uint32_t end = at + n;
  const std::uint32_t fmmuEnd =
      reg::kFmmuBase + reg::kFmmuSize * static_cast<std::uint32_t>(type_.fmmus);
  const std::uint32_t smEnd =
      reg::kSmBase + reg::kSmSize * static_cast<std::uint32_t>(type_.syncManagers);
  constexpr std::uint32_t kDcBegin = reg::kReceiveTimePort0.address;
  constexpr std::uint32_t kDcEnd = 0x0A00;
  constexpr std::uint32_t kDelayOnlyEnd = reg::kReceiveTimePort3.end();
  for (std::uint32_t a = at; a < end; ++a) {
    if (a >= reg::kFmmuBase && a < reg::kFmmuBase + reg::kFmmuSize * reg::kMaxFmmus) {
      if (a < fmmuEnd) return true;
    } else if (a >= reg::kSmBase && a < reg::kSmBase + reg::kSmSize * reg::kMaxSyncManagers) {
      if (a < smEnd) return true;
    } else if (a >= kDcBegin && a < kDcEnd) {
      if (dcUnit_ == DcUnit::kFull || (dcUnit_ == DcUnit::kDelayOnly && a < kDelayOnlyEnd))
        return true;
    } else {
      return true;
    }
  }
  return false;
}

int Esc::smLookup(std::uint32_t at, std::uint32_t& limit) const {
  for (std::uint8_t k = 0; k < smRangeCount_; ++k) {
    const SmRange& r = smRanges_[k];
    if (at >= r.start && at < r.end) {
      limit = std::min(limit, r.end);
      return r.index;
    }
    if (r.start > at) limit = std::min<std::uint32_t>(limit, r.start);
  }
  return -1;
}

void Esc::rebuildSmCache() {
  smRangeCount_ = 0;
  for (unsigned s = 0; s < type_.syncManagers; ++s) {
    const SmConfig c = smConfig(s);
    if (!c.enabled || c.length == 0) continue;
    smRanges_[smRangeCount_++] = {c.start, static_cast<std::uint32_t>(c.start) + c.length,
                                  static_cast<std::uint8_t>(s)};
    smCache_[s] = c;
  }
}

Esc::SmConfig Esc::smConfig(unsigned s) const {
  std::uint16_t base = reg::smChannel(s);
  SmConfig c;
  c.start = readLe16(memory_, base + reg::sm::kPhysicalStart.address);
  c.length = readLe16(memory_, base + reg::sm::kLength.address);
  c.control = memory_[base + reg::sm::kControl.address];
  // An SM that does not exist on this ESC, or whose area runs past the ESC's memory, never
  // works: treated as disabled (so no buffer logic can reach outside the memory).
  c.enabled = s < type_.syncManagers &&
              (memory_[base + reg::sm::kActivate.address] & reg::sm::kActivateEnable) != 0 &&
              (memory_[base + reg::sm::kPdiControl.address] & reg::sm::kPdiDeactivate) == 0 &&
              static_cast<std::size_t>(c.start) + c.length <= memory_.size();
  return c;
}

Esc::FmmuConfig Esc::fmmuConfig(unsigned n) const {
  std::uint16_t base = reg::fmmuChannel(n);
  FmmuConfig f;
  f.logicalStart = readLe32(memory_, base + reg::fmmu::kLogicalStart.address);
  f.length = readLe16(memory_, base + reg::fmmu::kLength.address);
  f.logicalStartBit = memory_[base + reg::fmmu::kLogicalStartBit.address];
  f.logicalStopBit = memory_[base + reg::fmmu::kLogicalStopBit.address];
  f.physicalStart = readLe16(memory_, base + reg::fmmu::kPhysicalStart.address);
  f.physicalStartBit = memory_[base + reg::fmmu::kPhysicalStartBit.address];
  f.type = memory_[base + reg::fmmu::kType.address];
  f.active = (memory_[base + reg::fmmu::kActivate.address] & 0x01) != 0;
  return f;
}

namespace {
bool isMailbox(std::uint8_t control) {
  return (control & reg::sm::kControlModeMask) == reg::sm::kControlModeMailbox;
}
bool isEcatWrite(std::uint8_t control) {
  return (control & reg::sm::kControlDirectionMask) == reg::sm::kControlDirectionWrite;
}
}  // namespace

bool Esc::readRam(std::uint16_t address, Bytes out, bool orInto, int smIndex) {
  auto copyOut = [&](const std::uint8_t* src) {
    if (!orInto) {
      std::copy_n(src, out.size(), out.begin());
      return;
    }
    for (std::size_t i = 0; i < out.size(); ++i)
      out[i] = static_cast<std::uint8_t>(out[i] | src[i]);
  };
  if (smIndex < 0) {
    copyOut(&memory_[address]);
    return true;
  }
  const auto s = static_cast<unsigned>(smIndex);
  const SmConfig& cfg = smCache_[s];  // smIndex comes from smLookup: the SM is cached
  SmState& st = sm_[s];
  const std::uint16_t base = reg::smChannel(s);
  const bool lastByte = address + out.size() == static_cast<std::size_t>(cfg.start) + cfg.length;
  if (isMailbox(cfg.control)) {
    if (isEcatWrite(cfg.control) || !st.mailboxFull) return false;  // nothing to read
    copyOut(&memory_[address]);
    if (lastByte) {  // reading the last byte empties the mailbox
      st.mailboxFull = false;
      memory_[base + reg::sm::kStatus.address] &=
          static_cast<std::uint8_t>(~reg::sm::kStatusMailboxFull);
      events_.mailboxRead = true;
    }
    return true;
  }
  // 3-buffer mode: the master reads the newest complete buffer the PDI wrote.
  const std::size_t offset = static_cast<std::size_t>(address - cfg.start);
  const std::size_t bufBase = 3u * static_cast<std::size_t>(cfg.start);
  if (isEcatWrite(cfg.control)) {
    // Reading back an output SM gives the newest complete buffer as well.
    copyOut(&buffers_[bufBase + st.latest * cfg.length + offset]);
    return true;
  }
  copyOut(&buffers_[bufBase + st.latest * cfg.length + offset]);
  return true;
}

bool Esc::writeRam(std::uint16_t address, ConstBytes data, int smIndex) {
  if (smIndex < 0) {
    std::copy(data.begin(), data.end(), memory_.begin() + address);
    return true;
  }
  const auto s = static_cast<unsigned>(smIndex);
  const SmConfig& cfg = smCache_[s];  // smIndex comes from smLookup: the SM is cached
  SmState& st = sm_[s];
  const std::uint16_t base = reg::smChannel(s);
  const bool lastByte = address + data.size() == static_cast<std::size_t>(cfg.start) + cfg.length;
  if (isMailbox(cfg.control)) {
    if (!isEcatWrite(cfg.control)) return false;  // master may not write a read mailbox
    if (st.mailboxFull) {
      ++counters_.mailboxWritesRejected;
      return false;  // full: write refused, no WKC (the master retries)
    }
    std::copy(data.begin(), data.end(), memory_.begin() + address);
    if ((cfg.control & reg::sm::kControlWatchdog) != 0) triggerPdWatchdog();
    if (lastByte) {
      st.mailboxFull = true;
      st.hasLatest = true;  // for 1-buffer process data: outputs received
      memory_[base + reg::sm::kStatus.address] |= reg::sm::kStatusMailboxFull;
      ++counters_.mailboxWrites;
      events_.mailboxReceived = true;
    }
    return true;
  }
  if (!isEcatWrite(cfg.control)) return false;  // inputs: master writes are ignored
  if ((cfg.control & reg::sm::kControlWatchdog) != 0) triggerPdWatchdog();
  const std::size_t offset = static_cast<std::size_t>(address - cfg.start);
  const std::size_t bufBase = 3u * static_cast<std::size_t>(cfg.start);
  std::copy(
      data.begin(), data.end(),
      buffers_.begin() + static_cast<std::ptrdiff_t>(bufBase + st.writing * cfg.length + offset));
  if (lastByte) {  // buffer complete: it becomes the newest, writing continues in a free one
    std::uint8_t done = st.writing;
    std::uint8_t next = 0;
    while (next == done || next == st.latest) ++next;
    // Carry the complete buffer forward so a partial next write keeps unwritten bytes.
    std::copy_n(buffers_.begin() + static_cast<std::ptrdiff_t>(bufBase + done * cfg.length),
                cfg.length,
                buffers_.begin() + static_cast<std::ptrdiff_t>(bufBase + next * cfg.length));
    st.latest = done;
    st.writing = next;
    st.hasLatest = true;
    memory_[base + reg::sm::kStatus.address] = static_cast<std::uint8_t>(
        (memory_[base + reg::sm::kStatus.address] & ~reg::sm::kStatusBufferMask) | (done << 4) |
        reg::sm::kStatusInterruptWrite);
    events_.outputsWritten = true;
  }
  return true;
}

}  // namespace ecsim::slavesim

namespace ecsim::slavesim {

void Esc::systemTimeWritten(std::uint32_t begin, std::uint32_t end, ConstBytes data) {
  // Written system time is compared with the local copy; the difference feeds the drift
  // control loop (datasheet section I §9.1.3). A 32-bit write compares the low 32 bits.
  // 0x092C: bit 31 set = local copy smaller than the received time.
  const SimTime local = wrapAdd(localNow_, reg64(reg::kSystemTimeOffset.address));
  std::uint64_t written = static_cast<std::uint64_t>(local);
  if (begin == reg::kSystemTime.address && end == reg::kSystemTime.end()) {
    written = readLe64(data, 0);  // the usual 64-bit distribution (ARMW/FRMW)
  } else {
    for (std::uint32_t i = 0; i < 8; ++i) {
      std::uint32_t a = reg::kSystemTime.address + i;
      if (a >= begin && a < end) {
        written = (written & ~(0xFFull << (8 * i))) |
                  (static_cast<std::uint64_t>(data[a - begin]) << (8 * i));
      }
    }
  }
  const SimTime received =
      wrapAdd(static_cast<SimTime>(written), reg32(reg::kSystemTimeDelay.address));
  const std::int64_t diff = dc_.onSystemTimeWrite(
      now_, local, received, memory_[reg::kSystemTimeDifferenceFilterDepth.address] & 0x0F);
  writeLe32(memory_, reg::kSystemTimeDifference.address, systemTimeDifferenceRegister(diff));
}

bool Esc::writeRegisters(std::uint16_t address, ConstBytes data) {
  const std::uint32_t begin = address;
  const std::uint32_t end = address + static_cast<std::uint32_t>(data.size());
  if (begin >= reg::kSystemTime.address && end <= reg::kSystemTime.end()) {
    // Fast path for the cyclic DC distribution (ARMW/FRMW of 0x0910 reaches every ESC but the
    // reference once per frame): no other register with side effects lies in this range.
    bool accepted = false;
    if (data.size() == 8) {
      // All of it: one masked merge of 8 bytes at once (bitwise, so byte order is irrelevant).
      std::uint64_t mask = 0;
      std::uint64_t old = 0;
      std::uint64_t value = 0;
      std::memcpy(&mask, writable_.data() + begin, 8);
      std::memcpy(&old, memory_.data() + begin, 8);
      std::memcpy(&value, data.data(), 8);
      const std::uint64_t merged = (old & ~mask) | (value & mask);
      std::memcpy(memory_.data() + begin, &merged, 8);
      accepted = mask != 0;
    }
    for (std::uint32_t i = 0; data.size() != 8 && i < data.size(); ++i) {
      const std::uint32_t a = begin + i;
      const std::uint8_t mask = writable_[a];
      accepted |= mask != 0;
      memory_[a] = static_cast<std::uint8_t>((memory_[a] & ~mask) | (data[i] & mask));
    }
    systemTimeWritten(begin, end, data);
    return accepted;
  }
  // SM channel registers 0x0800-0x0804 are writable only while the SM is disabled
  // (datasheet section II, SyncManager register description).
  std::array<bool, reg::kMaxSyncManagers> smWasEnabled{};
  const bool smTouched = overlaps(begin, end, reg::kSmBase, reg::kSmSize * reg::kMaxSyncManagers);
  for (unsigned s = 0; smTouched && s < type_.syncManagers; ++s) {
    smWasEnabled[s] =
        (memory_[reg::smChannel(s) + reg::sm::kActivate.address] & reg::sm::kActivateEnable) != 0;
  }
  bool accepted = false;
  for (std::uint32_t a = begin; a < end && !accepted; ++a) accepted = writable_[a] != 0;
  bool errorCounterWrite = false;
  bool lostLinkWrite = false;
  // Fast path (cyclic DC writes, AL control, ...): no register with per-byte special rules.
  const bool special =
      smTouched ||
      overlaps(begin, end, reg::kErrorCountersBegin,
               reg::kErrorCountersEnd - reg::kErrorCountersBegin) ||
      overlaps(begin, end, reg::kWatchdogCounterProcessData.address, 2) ||
      overlaps(begin, end, reg::kReceiveTimePort0.address, reg::kReceiveTimePort0.width);
  for (std::uint32_t i = 0; !special && i < data.size(); ++i) {
    const std::uint32_t a = begin + i;
    const std::uint8_t mask = writable_[a];
    memory_[a] = static_cast<std::uint8_t>((memory_[a] & ~mask) | (data[i] & mask));
  }
  for (std::uint32_t i = 0; special && i < data.size(); ++i) {
    const std::uint32_t a = begin + i;
    std::uint8_t mask = writable_[a];
    if (mask == 0) continue;
    if (a >= reg::kSmBase &&
        a < reg::kSmBase + reg::kSmSize * static_cast<std::uint32_t>(type_.syncManagers)) {
      unsigned s = (a - reg::kSmBase) / reg::kSmSize;
      unsigned off = (a - reg::kSmBase) % reg::kSmSize;
      if (off < reg::sm::kStatus.address && smWasEnabled[s]) continue;
    }
    if (a >= reg::kErrorCountersBegin && a < reg::kErrorCountersEnd) {
      // Error counters are cleared by a write of any value (datasheet section II §2.9).
      if (a < 0x030C)
        errorCounterWrite = true;
      else if (a >= 0x0310)
        lostLinkWrite = true;
      else
        memory_[a] = 0;
      continue;
    }
    if (a == reg::kWatchdogCounterProcessData.address || a == reg::kWatchdogCounterPdi.address) {
      memory_[a] = 0;
      continue;
    }
    if (a >= reg::kReceiveTimePort0.address && a < reg::kReceiveTimePort0.end()) continue;
    memory_[a] = static_cast<std::uint8_t>((memory_[a] & ~mask) | (data[i] & mask));
  }
  if (errorCounterWrite) std::fill_n(memory_.begin() + reg::kErrorCountersBegin, 0x0C, 0);
  if (lostLinkWrite) std::fill_n(memory_.begin() + 0x0310, 4, 0);

  if (overlaps(begin, end, reg::kDlControl.address, reg::kDlControl.width)) {
    events_.dlControlWritten = true;
  }
  if (overlaps(begin, end, reg::kAlControl.address, reg::kAlControl.width)) {
    events_.alControlWritten = true;
    memory_[reg::kAlEventRequest.address] |= 0x01;
  }
  if (overlaps(begin, end, reg::kSiiControlStatus.address + 1, 1)) {
    // The command byte was written: execute it (write needs the enable bit in the same access).
    siiCommand(reg16(reg::kSiiControlStatus.address));
  }
  if (overlaps(begin, end, reg::kSystemTime.address, reg::kSystemTime.width)) {
    systemTimeWritten(begin, end, data);
  }
  if (overlaps(begin, end, reg::kSpeedCounterStart.address, reg::kSpeedCounterStart.width)) {
    dc_.resetControl();
  }
  if (overlaps(begin, end, reg::kDcActivation.address, 1)) onSyncActivationWrite();
  if (overlaps(begin, end, reg::kFmmuBase, reg::kFmmuSize * reg::kMaxFmmus)) rebuildFmmuCache();
  if (overlaps(begin, end, reg::kSmBase, reg::kSmSize * reg::kMaxSyncManagers)) {
    for (unsigned s = 0; s < type_.syncManagers; ++s) {
      bool nowEnabled =
          (memory_[reg::smChannel(s) + reg::sm::kActivate.address] & reg::sm::kActivateEnable) != 0;
      if (nowEnabled != smWasEnabled[s]) smActivationChanged(s);
      if (overlaps(begin, end, reg::smChannel(s) + reg::sm::kActivate.address, 1) &&
          (memory_[reg::smChannel(s) + reg::sm::kActivate.address] &
           reg::sm::kActivateRepeatRequest) !=
              (memory_[reg::smChannel(s) + reg::sm::kPdiControl.address] &
               reg::sm::kPdiRepeatAck)) {
        events_.mailboxRead = true;  // firmware sees the repeat request toggle
      }
    }
    rebuildSmCache();
    events_.smConfigChanged = true;
  }
  return accepted;
}

void Esc::smActivationChanged(unsigned s) {
  SmState& st = sm_[s];
  st = {};
  std::uint16_t base = reg::smChannel(s);
  memory_[base + reg::sm::kStatus.address] = 0;
}

void Esc::refreshVolatile(std::uint16_t begin, std::uint16_t end) {
  if (overlaps(begin, end, reg::kCyclicUnitControl.address, 0x28)) refreshSyncRegisters(begin, end);
  if (overlaps(begin, end, reg::kSystemTime.address, reg::kSystemTime.width)) {
    writeLe64(
        memory_, reg::kSystemTime.address,
        static_cast<std::uint64_t>(wrapAdd(localNow_, reg64(reg::kSystemTimeOffset.address))));
  }
}

void Esc::completeReceiveTimeLatch(const std::array<SimTime, 4>& times, std::uint8_t portMask) {
  if (!latchArmed_) return;
  latchArmed_ = false;
  for (unsigned p = 0; p < 4; ++p) {
    if ((portMask & (1u << p)) != 0) {
      writeLe32(memory_, reg::receiveTime(p), static_cast<std::uint32_t>(dc_.localTime(times[p])));
    }
  }
}

void Esc::latchReceiveTimes() {
  latchArmed_ = true;
  writeLe64(memory_, reg::kReceiveTimeEcatProcessingUnit.address,
            static_cast<std::uint64_t>(localNow_));
  events_.dcLatched = true;
}

void Esc::siiCommand(std::uint16_t control) {
  std::uint16_t status = reg16(reg::kSiiControlStatus.address);
  status = static_cast<std::uint16_t>(
      status & ~(reg::sii::kCommandMask | reg::sii::kBusy | reg::sii::kWriteEnable));
  const std::uint16_t command = control & reg::sii::kCommandMask;
  const std::uint32_t word = reg32(reg::kSiiAddress.address);
  const std::size_t words = sii_.size() / 2;
  switch (command) {
    case reg::sii::kCommandNop:
      // A NOP clears the error bits (datasheet section II, 0x0502 description).
      status = static_cast<std::uint16_t>(status &
                                          ~(reg::sii::kCommandError | reg::sii::kWriteEnableError));
      break;
    case reg::sii::kCommandRead: {
      const unsigned count = type_.siiRead8Bytes ? 4 : 2;
      for (unsigned i = 0; i < count; ++i) {
        std::uint16_t value = (word + i < words) ? siiWord(sii_, word + i) : 0xFFFF;
        writeLe16(memory_, static_cast<std::uint16_t>(reg::kSiiData.address + 2 * i), value);
      }
      status = static_cast<std::uint16_t>(status & ~reg::sii::kCommandError);
      break;
    }
    case reg::sii::kCommandWrite:
      if ((control & reg::sii::kWriteEnable) == 0) {
        status |= reg::sii::kWriteEnableError;
      } else if (word < words) {
        writeLe16(sii_, 2 * word, reg16(reg::kSiiData.address));
      } else {
        status |= reg::sii::kCommandError;
      }
      break;
    case reg::sii::kCommandReload:
      loadFromSii();
      status = reg16(reg::kSiiControlStatus.address);
      events_.eepromReloaded = true;
      break;
    default:
      status |= reg::sii::kCommandError;  // two command bits at once: invalid
      break;
  }
  writeLe16(memory_, reg::kSiiControlStatus.address, status);
}

void Esc::rebuildFmmuCache() {
  activeFmmuCount_ = 0;
  for (unsigned n = 0; n < type_.fmmus; ++n) {
    FmmuConfig f = fmmuConfig(n);
    if (!f.active || f.length == 0 || (f.type & 0x03) == 0) continue;
    ActiveFmmu a;
    a.logicalStartBit = static_cast<std::uint64_t>(f.logicalStart) * 8 + (f.logicalStartBit & 7);
    a.logicalEndBit =
        (static_cast<std::uint64_t>(f.logicalStart) + f.length - 1) * 8 + (f.logicalStopBit & 7);
    if (a.logicalEndBit < a.logicalStartBit) continue;
    a.physicalStartBit = static_cast<std::uint32_t>(f.physicalStart) * 8 + (f.physicalStartBit & 7);
    a.type = f.type;
    a.byteAligned = (f.logicalStartBit & 7) == 0 && (f.logicalStopBit & 7) == 7 &&
                    (f.physicalStartBit & 7) == 0;
    activeFmmus_[activeFmmuCount_++] = a;
  }
}

std::pair<bool, bool> Esc::processLogical(DatagramView d, bool doRead, bool doWrite) {
  bool readHit = false;
  bool writeHit = false;
  if (activeFmmuCount_ == 0) return {false, false};
  const std::uint64_t dStart = static_cast<std::uint64_t>(d.address()) * 8;
  const std::uint64_t dEnd = dStart + static_cast<std::uint64_t>(d.length()) * 8;  // exclusive
  Bytes data = d.data();
  // Writes first, from the incoming data, then reads: the result equals the ESC's on-the-fly
  // "read before write" for any mapping where input and output FMMUs map different physical
  // memory, including masters that overlap inputs and outputs in the logical image.
  for (int pass = 0; pass < 2; ++pass) {
    const bool writing = pass == 0;
    if (writing ? !doWrite : !doRead) continue;
    const std::uint8_t need = writing ? reg::fmmu::kTypeWrite : reg::fmmu::kTypeRead;
    for (std::uint8_t k = 0; k < activeFmmuCount_; ++k) {
      const ActiveFmmu& f = activeFmmus_[k];
      if ((f.type & need) == 0) continue;
      const std::uint64_t lo = std::max(dStart, f.logicalStartBit);
      const std::uint64_t hi = std::min(dEnd, f.logicalEndBit + 1);  // exclusive
      if (lo >= hi) continue;
      const std::uint64_t physBit = f.physicalStartBit + (lo - f.logicalStartBit);
      const std::uint64_t nBits = hi - lo;
      const std::size_t dOff = static_cast<std::size_t>((lo - dStart) / 8);
      if (f.byteAligned) {
        const auto phys = static_cast<std::uint32_t>(physBit / 8);
        const std::size_t nBytes = static_cast<std::size_t>(nBits / 8);
        bool ok = writing ? writeMemory(phys, ConstBytes(data.subspan(dOff, nBytes)))
                          : readMemory(phys, data.subspan(dOff, nBytes), false);
        (writing ? writeHit : readHit) |= ok;
        continue;
      }
      // Bit-granular mapping: gather the physical bytes covered, move bits, write back.
      const auto physFirst = static_cast<std::uint32_t>(physBit / 8);
      const auto physLast = static_cast<std::uint32_t>((physBit + nBits - 1) / 8);
      const std::size_t physBytes = physLast - physFirst + 1;
      if (physBytes > scratch_.size()) continue;
      Bytes tmp(scratch_.data(), physBytes);
      bool ok = readMemory(physFirst, tmp, false);
      if (!writing) {
        if (!ok) continue;
        for (std::uint64_t b = 0; b < nBits; ++b) {
          const std::uint64_t pb = physBit + b - static_cast<std::uint64_t>(physFirst) * 8;
          const std::uint64_t db = lo - dStart + b;
          const bool bit = (tmp[pb / 8] >> (pb % 8)) & 1;
          auto& out = data[db / 8];
          out =
              static_cast<std::uint8_t>(bit ? (out | (1u << (db % 8))) : (out & ~(1u << (db % 8))));
        }
        readHit = true;
      } else {
        for (std::uint64_t b = 0; b < nBits; ++b) {
          const std::uint64_t pb = physBit + b - static_cast<std::uint64_t>(physFirst) * 8;
          const std::uint64_t db = lo - dStart + b;
          const bool bit = (data[db / 8] >> (db % 8)) & 1;
          auto& out = tmp[pb / 8];
          out =
              static_cast<std::uint8_t>(bit ? (out | (1u << (pb % 8))) : (out & ~(1u << (pb % 8))));
        }
        writeHit |= writeMemory(physFirst, tmp);
      }
    }
  }
  return {readHit, writeHit};
}

// ---- PDI side -------------------------------------------------------------------------------

void Esc::pdiSetAlStatus(std::uint16_t status, std::uint16_t code) {
  writeLe16(memory_, reg::kAlStatus.address, status);
  writeLe16(memory_, reg::kAlStatusCode.address, code);
}

namespace {
int findMailboxSm(const Esc& esc, unsigned count, bool ecatWrite) {
  for (unsigned s = 0; s < count; ++s) {
    auto c = esc.smConfig(s);
    if (c.enabled && c.length > 0 && isMailbox(c.control) && isEcatWrite(c.control) == ecatWrite) {
      return static_cast<int>(s);
    }
  }
  return -1;
}
}  // namespace

bool Esc::pdiMailboxAvailable() const {
  return findMailboxSm(*this, type_.syncManagers, true) >= 0 &&
         findMailboxSm(*this, type_.syncManagers, false) >= 0;
}

std::size_t Esc::pdiMailboxReceive(Bytes out) {
  int s = findMailboxSm(*this, type_.syncManagers, true);
  if (s < 0 || !sm_[static_cast<unsigned>(s)].mailboxFull) return 0;
  auto c = smConfig(static_cast<unsigned>(s));
  std::size_t n = std::min<std::size_t>(out.size(), c.length);
  std::copy_n(memory_.begin() + c.start, n, out.begin());
  sm_[static_cast<unsigned>(s)].mailboxFull = false;
  memory_[reg::smChannel(static_cast<unsigned>(s)) + reg::sm::kStatus.address] &=
      static_cast<std::uint8_t>(~reg::sm::kStatusMailboxFull);
  return n;
}

bool Esc::pdiMailboxSend(ConstBytes data) {
  int s = findMailboxSm(*this, type_.syncManagers, false);
  if (s < 0) return false;
  auto& st = sm_[static_cast<unsigned>(s)];
  if (st.mailboxFull) return false;
  auto c = smConfig(static_cast<unsigned>(s));
  std::size_t n = std::min<std::size_t>(data.size(), c.length);
  std::copy_n(data.begin(), n, memory_.begin() + c.start);
  std::fill_n(memory_.begin() + c.start + static_cast<std::ptrdiff_t>(n), c.length - n, 0);
  std::copy_n(memory_.begin() + c.start, c.length, lastMailboxResponse_.begin());
  lastMailboxResponseSize_ = c.length;
  st.mailboxFull = true;
  memory_[reg::smChannel(static_cast<unsigned>(s)) + reg::sm::kStatus.address] |=
      reg::sm::kStatusMailboxFull;
  return true;
}

bool Esc::pdiMailboxResponsePending() const {
  int s = findMailboxSm(*this, type_.syncManagers, false);
  return s >= 0 && sm_[static_cast<unsigned>(s)].mailboxFull;
}

void Esc::pdiMailboxRepeat() {
  int s = findMailboxSm(*this, type_.syncManagers, false);
  if (s < 0) return;
  const auto su = static_cast<unsigned>(s);
  const std::uint16_t base = reg::smChannel(su);
  auto c = smConfig(su);
  if (lastMailboxResponseSize_ > 0 && lastMailboxResponseSize_ <= c.length) {
    std::copy_n(lastMailboxResponse_.begin(), lastMailboxResponseSize_, memory_.begin() + c.start);
    sm_[su].mailboxFull = true;
    memory_[base + reg::sm::kStatus.address] |= reg::sm::kStatusMailboxFull;
  }
  // Acknowledge: copy the repeat request bit into the PDI control repeat-ack bit.
  std::uint8_t req = memory_[base + reg::sm::kActivate.address] & reg::sm::kActivateRepeatRequest;
  memory_[base + reg::sm::kPdiControl.address] = static_cast<std::uint8_t>(
      (memory_[base + reg::sm::kPdiControl.address] & ~reg::sm::kPdiRepeatAck) | req);
}

ConstBytes Esc::pdiOutputs(unsigned s) const {
  if (s >= type_.syncManagers) return {};
  auto c = smConfig(s);
  if (!c.enabled || !isEcatWrite(c.control) || c.length == 0) return {};
  // 1-buffer (mailbox-mode) process data: the buffer is the memory itself.
  if (isMailbox(c.control)) return ConstBytes(memory_.data() + c.start, c.length);
  const std::size_t bufBase = 3u * static_cast<std::size_t>(c.start);
  return ConstBytes(buffers_.data() + bufBase + sm_[s].latest * c.length, c.length);
}

bool Esc::pdiWriteInputs(unsigned s, ConstBytes data) {
  if (s >= type_.syncManagers) return false;
  auto c = smConfig(s);
  if (!c.enabled || isEcatWrite(c.control) || c.length == 0) return false;
  auto& st = sm_[s];
  if (isMailbox(c.control)) {
    // 1-buffer inputs: the PDI may write only when the master has read the last buffer.
    if (st.mailboxFull) return false;
    const std::size_t n1 = std::min<std::size_t>(data.size(), c.length);
    std::copy_n(data.begin(), n1, memory_.begin() + c.start);
    st.mailboxFull = true;
    memory_[reg::smChannel(s) + reg::sm::kStatus.address] |= reg::sm::kStatusMailboxFull;
    return true;
  }
  const std::size_t bufBase = 3u * static_cast<std::size_t>(c.start);
  std::size_t n = std::min<std::size_t>(data.size(), c.length);
  std::copy_n(data.begin(), n,
              buffers_.begin() + static_cast<std::ptrdiff_t>(bufBase + st.writing * c.length));
  std::uint8_t done = st.writing;
  std::uint8_t next = 0;
  while (next == done || next == st.latest) ++next;
  st.latest = done;
  st.writing = next;
  st.hasLatest = true;
  return true;
}

void Esc::pdiReleaseBuffer(unsigned s) {
  if (s >= type_.syncManagers) return;
  auto c = smConfig(s);
  if (!c.enabled || !isMailbox(c.control) || !isEcatWrite(c.control)) return;
  sm_[s].mailboxFull = false;
  memory_[reg::smChannel(s) + reg::sm::kStatus.address] &=
      static_cast<std::uint8_t>(~reg::sm::kStatusMailboxFull);
}

void Esc::countRxError(unsigned port, bool invalidFrame) {
  if (port > 3) return;
  std::uint16_t at =
      static_cast<std::uint16_t>(reg::rxErrorCounters(port) + (invalidFrame ? 0 : 1));
  if (memory_[at] < 0xFF) ++memory_[at];
}

void Esc::countForwardedRxError(unsigned port) {
  if (port > 3) return;
  std::uint16_t at = reg::forwardedRxErrorCounter(port);
  if (memory_[at] < 0xFF) ++memory_[at];
}

void Esc::countLostLink(unsigned port) {
  if (port > 3) return;
  std::uint16_t at = reg::lostLinkCounter(port);
  if (memory_[at] < 0xFF) ++memory_[at];
}

}  // namespace ecsim::slavesim
