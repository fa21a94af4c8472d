// The ESC core: construction and reset, datagram processing with the working-counter rules,
// and the split of a physical access into registers and SyncManager-covered memory.
#include "slavesim/esc.hpp"

#include <algorithm>
#include <cstring>

#include "slavesim/esc_internal.hpp"

namespace ecsim::slavesim {
using namespace esc_detail;
std::optional<EscType> escTypeByName(std::string_view name) {
  for (const EscType& t : {kEt1100, kEt1200, kLan9252}) {
    if (t.name == name) return t;
  }
  return std::nullopt;
}

Esc::Esc(const EscType& type, std::vector<std::uint8_t> siiImage)
    : memory_(kRamStart + static_cast<std::size_t>(type.ramKb) * 1024, 0),
      regs_(escRegisterBytes()),
      type_(type),
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
  smLowestStart_ = 0xFFFF;
  smTriggerOnlyCount_ = 0;
  smCache_ = {};  // all zero: no SM enabled (rebuildSmCache's view of the zeroed registers)
  smEventControl_ = 0;
  smEndAccessed_ = 0;
  invalidFrame_ = false;
  lastMailboxResponseSize_ = 0;
  std::copy(regs_.reset.begin(), regs_.reset.end(), memory_.begin());  // table reset values
  // ESC information: what this ESC type is (section II 0x0000-0x0009).
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
  latchReset();       // DC latch unit (esc_latch.cpp), before the event state follows it
  resetEventState();  // AL control mailbox, ECAT event state (esc_events.cpp)
  miiReset();         // esc_mii.cpp
  loadFromSii();      // also takes the addressing copies (refreshAddressing)
}

void Esc::setObserver(EscObserver* observer, std::uint32_t id) {
  observer_ = observer;
  observerId_ = id;
  eventsNoted_ = false;
  irqNoted_ = 0;
  smNoted_ = false;
  if (observer_ == nullptr) return;
  if (hasEvents()) noteEvent();
  observer_->escIrqChanged(observerId_, ecatIrq_, smEventMask_ != 0);
  irqNoted_ = ecatIrq_;
  smNoted_ = smEventMask_ != 0;
  observer_->escAddressingChanged(observerId_);
}

void Esc::powerOnReset() {
  reset();
}

// ---- ECAT side ------------------------------------------------------------------------------

SimTime Esc::systemTime(SimTime time) const {
  return wrapAdd(dc_.localTime(time), reg64(reg::kSystemTimeOffset.address));
}

void Esc::processDatagram(DatagramView d, SimTime time) {
  lastWkcIncrement_ = 0;
  now_ = time;
  orEventsIntoIrq(d);                           // the header passes first (esc_events.cpp)
  if (!isKnownCommand(d.rawCommand())) return;  // unknown command: forwarded untouched
  const Command cmd = d.command();
  const std::uint16_t len = d.length();
  std::uint16_t inc = 0;
  const AddressMode mode = addressMode(cmd);
  if (mode == AddressMode::kConfigured && cmd != Command::kFrmw && d.adp() != stationAddress() &&
      !(aliasEnabled() && d.adp() == stationAlias())) {
    return;  // another ESC's datagram: only its header passed (the local clock is not needed)
  }
  localNow_ = dc_.localTime(time);
  switch (mode) {
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
      bool addressed;
      if (mode == AddressMode::kAutoIncrement) {
        addressed = d.adp() == 0;
        d.setAdp(static_cast<std::uint16_t>(d.adp() + 1));
      } else if (mode == AddressMode::kBroadcast) {
        addressed = true;
        d.setAdp(static_cast<std::uint16_t>(d.adp() + 1));
      } else {
        addressed = d.adp() == stationAddress() || (aliasEnabled() && d.adp() == stationAlias());
      }
      const std::uint16_t ado = d.ado();
      const auto end = static_cast<std::uint32_t>(ado) + len;
      if (cmd == Command::kArmw || cmd == Command::kFrmw) {
        // Read at the addressed slave, write at every other one (datasheet Table 7).
        if (addressed) {
          if (!invalidFrame_)  // register reads with side effects: discarded (section I §14.1)
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
        if (!invalidFrame_)
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
        inc = writeMemory(ado, d.data()) ? 1 : 0;
      }
      // Clear-on-read, a side effect discarded in an invalid frame (section I §14.1).
      if (access.read && ado < kRamStart && !invalidFrame_) afterRegisterRead(ado, end);
      break;
    }
  }
  lastWkcIncrement_ = inc;
  if (inc != 0) d.setWkc(static_cast<std::uint16_t>(d.wkc() + inc));
}

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
    const int smIndex = smRangeCount_ == 0 || limit <= smLowestStart_ ? -1 : smLookup(at, limit);
    if (smIndex < 0 && at >= kRamStart && !orInto) {  // plain process RAM (most FMMU reads)
      std::copy_n(memory_.begin() + at, limit - at, piece.begin());
      any = true;
      at = limit;
      continue;
    }
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
  if (invalidFrame_) return writeUnshadowed(address, data);
  const std::uint32_t size = static_cast<std::uint32_t>(data.size());
  if (smTriggerOnlyCount_ != 0) smTriggerOnlyWrite(address, size);
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
    const int smIndex = smRangeCount_ == 0 || limit <= smLowestStart_ ? -1 : smLookup(at, limit);
    if (smIndex < 0 && at >= kRamStart) {  // plain process RAM (most FMMU writes)
      std::copy_n(piece.begin(), limit - at, memory_.begin() + at);
      any = true;
      at = limit;
      continue;
    }
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
  // type_ is read only for FMMU and SM registers: it lies outside the hot group.
  const std::uint32_t end = at + n;
  constexpr std::uint32_t kDcBegin = reg::kReceiveTimePort0.address;
  constexpr std::uint32_t kDcEnd = 0x0A00;
  constexpr std::uint32_t kDelayOnlyEnd = reg::kReceiveTimePort3.end();
  for (std::uint32_t a = at; a < end; ++a) {
    if (a >= reg::kFmmuBase && a < reg::kFmmuBase + reg::kFmmuSize * reg::kMaxFmmus) {
      if (a < reg::kFmmuBase + reg::kFmmuSize * static_cast<std::uint32_t>(type_.fmmus))
        return true;
    } else if (a >= reg::kSmBase && a < reg::kSmBase + reg::kSmSize * reg::kMaxSyncManagers) {
      if (a < reg::kSmBase + reg::kSmSize * static_cast<std::uint32_t>(type_.syncManagers))
        return true;
    } else if (a >= kDcBegin && a < kDcEnd) {
      if (dcUnit_ == DcUnit::kFull || (dcUnit_ == DcUnit::kDelayOnly && a < kDelayOnlyEnd))
        return true;
    } else {
      return true;
    }
  }
  return false;
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

void Esc::countProcessingUnitError() {
  std::uint8_t& counter = memory_[reg::kEcatProcessingUnitErrorCounter.address];
  if (counter < 0xFF) ++counter;
}

void Esc::countLostLink(unsigned port) {
  if (port > 3) return;
  std::uint16_t at = reg::lostLinkCounter(port);
  if (memory_[at] < 0xFF) ++memory_[at];
}

}  // namespace ecsim::slavesim
