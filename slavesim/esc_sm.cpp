// SyncManagers (datasheet section I §8): ECAT access to mailbox and 3-buffer areas and the PDI
// side the firmware uses (mailbox receive/send/repeat, process data buffers).
#include "slavesim/esc.hpp"

#include <algorithm>
#include <cstring>

#include "slavesim/esc_internal.hpp"

namespace ecsim::slavesim {
using namespace esc_detail;
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
  std::uint32_t wasBuffer = 0;
  for (std::uint8_t k = 0; k < smRangeCount_; ++k) wasBuffer |= 1u << smRanges_[k].index;
  smRangeCount_ = 0;
  smLowestStart_ = 0xFFFF;
  smTriggerOnlyCount_ = 0;
  smEventControl_ = 0;
  for (unsigned s = 0; s < type_.syncManagers; ++s) {
    const SmConfig c = smConfig(s);
    smCache_[s] = c;
    if (c.control.ecatEvent) smEventControl_ = static_cast<std::uint16_t>(smEventControl_ | (1u << s));
    if (!c.enabled || c.length == 0) continue;
    if (c.length == 1) {
      // Section II Table 90: "shall be greater 1, otherwise SyncManager is not activated. If
      // set to 1, only Watchdog Trigger is generated if configured" (EL2004: 0x0F00, 1 byte).
      smTriggerOnly_[smTriggerOnlyCount_++] = {c.start, static_cast<std::uint8_t>(s), c.control};
      continue;
    }
    smRanges_[smRangeCount_++] = {c.start, static_cast<std::uint32_t>(c.start) + c.length,
                                  static_cast<std::uint8_t>(s)};
    smLowestStart_ = std::min(smLowestStart_, c.start);
    if ((wasBuffer & (1u << s)) == 0 && !isMailbox(c.control)) {
      // Freshly activated 3-buffer SM: status bits 5:4 "last written buffer" = 11, no buffer
      // written yet (section II, SyncManager status register 0x0805+8n).
      memory_[reg::smChannel(s) + reg::sm::kStatus.address] |= reg::sm::kStatusBufferMask;
    }
  }
}

Esc::SmAccess Esc::smAccess(unsigned s, std::uint16_t address, std::size_t size) {
  // Section I §8: "A buffer has to be accessed beginning with the start address, otherwise the
  // access is denied. After accessing the start address, the whole buffer can be accessed [...]
  // in several strokes. A buffer access finishes by accessing the end address [...]. The end
  // address cannot be accessed twice inside a frame."
  const SmConfig& cfg = smCache_[s];
  SmState& st = sm_[s];
  const std::uint32_t bit = 1u << s;
  const bool atEnd = address + size == static_cast<std::size_t>(cfg.start) + cfg.length;
  if (address != cfg.start && !st.open) return SmAccess::kDenied;
  if (atEnd && (smEndAccessed_ & bit) != 0) return SmAccess::kDenied;
  // An invalid frame changes no buffer state (section I §14.1).
  if (invalidFrame_) return SmAccess::kInside;
  if (!atEnd) {
    st.open = true;
    return SmAccess::kInside;
  }
  st.open = false;
  smEndAccessed_ |= bit;
  return SmAccess::kEnd;
}

void Esc::smTriggerOnlyWrite(std::uint32_t address, std::uint32_t size) {
  for (std::uint8_t k = 0; k < smTriggerOnlyCount_; ++k) {
    const SmTriggerOnly& t = smTriggerOnly_[k];
    if (t.address < address || t.address >= address + size) continue;
    if (t.control.watchdogTrigger) triggerPdWatchdog();
    // For the firmware model: outputs have arrived (the ESM's SAFEOP->OP check).
    if (isEcatWrite(t.control)) sm_[t.index].hasLatest = true;
  }
}

bool Esc::writeUnshadowed(std::uint32_t address, ConstBytes data) {
  // Section I §14.1: with a frame error "RAM areas will be written, because they do not have a
  // shadow buffer for write data like registers"; registers are 0x0000-0x0F7F (user RAM
  // 0x0F80-0x0FFF is RAM, section I §17.3.1). SyncManager buffers do not change.
  const auto end = std::min<std::uint32_t>(address + static_cast<std::uint32_t>(data.size()),
                                           static_cast<std::uint32_t>(memory_.size()));
  bool any = false;
  for (std::uint32_t at = std::max<std::uint32_t>(address, reg::kUserRam.address); at < end;) {
    std::uint32_t limit = end;
    if (smLookup(at, limit) < 0) {
      std::copy_n(data.begin() + (at - address), limit - at, memory_.begin() + at);
      any = true;
    }
    at = limit;
  }
  return any;
}

Esc::SmConfig Esc::smConfig(unsigned s) const {
  const std::uint16_t base = reg::smChannel(s);
  SmConfig c;
  static_cast<SyncManagerBlock&>(c) =
      SyncManagerBlock::parse(ConstBytes(memory_).subspan(base, reg::kSmSize)).value();
  // An SM that does not exist on this ESC, or whose area runs past the ESC's memory, never
  // works: treated as disabled (so no buffer logic can reach outside the memory).
  c.enabled = s < type_.syncManagers && c.activate.enable && !c.pdiControl.deactivate &&
              static_cast<std::size_t>(c.start) + c.length <= memory_.size();
  return c;
}

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
  if (isMailbox(cfg.control)) {
    if (isEcatWrite(cfg.control) || !st.mailboxFull) return false;  // nothing to read
    const SmAccess access = smAccess(s, address, out.size());
    if (access == SmAccess::kDenied) return false;
    copyOut(&memory_[address]);
    if (invalidFrame_) return true;
    // Section II 0x0805, as for the 3-buffer below: the first byte read clears "interrupt
    // write", reading the end address empties the mailbox and sets "interrupt read".
    std::uint8_t& status = memory_[base + reg::sm::kStatus.address];
    if (address == cfg.start) status &= static_cast<std::uint8_t>(~reg::sm::kStatusInterruptWrite);
    if (access == SmAccess::kEnd) {  // reading the last byte empties the mailbox
      st.mailboxFull = false;
      status = static_cast<std::uint8_t>((status & ~reg::sm::kStatusMailboxFull) |
                                         reg::sm::kStatusInterruptRead);
      events_.mailboxRead = true;
      noteEvent();
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
  const SmAccess access = smAccess(s, address, out.size());
  if (access == SmAccess::kDenied) return false;
  copyOut(&buffers_[bufBase + st.latest * cfg.length + offset]);
  if (!invalidFrame_) {
    // Section II 0x0805: "interrupt write" (a buffer the PDI completed) is cleared by the
    // master's first byte; reading the end address sets "interrupt read" for the PDI.
    std::uint8_t& status = memory_[base + reg::sm::kStatus.address];
    if (address == cfg.start) status &= static_cast<std::uint8_t>(~reg::sm::kStatusInterruptWrite);
    if (access == SmAccess::kEnd) status |= reg::sm::kStatusInterruptRead;
  }
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
  if (isMailbox(cfg.control)) {
    if (!isEcatWrite(cfg.control)) return false;  // master may not write a read mailbox
    if (st.mailboxFull) {
      ++counters_.mailboxWritesRejected;
      return false;  // full: write refused, no WKC (the master retries)
    }
    const SmAccess access = smAccess(s, address, data.size());
    if (access == SmAccess::kDenied) return false;
    std::copy(data.begin(), data.end(), memory_.begin() + address);
    if (cfg.control.watchdogTrigger) triggerPdWatchdog();
    // Section II 0x0805: the writer's first byte clears "interrupt read" (the PDI's read of the
    // last mailbox, the master's SM event); a complete buffer sets "interrupt write".
    std::uint8_t& status = memory_[base + reg::sm::kStatus.address];
    if (address == cfg.start) status &= static_cast<std::uint8_t>(~reg::sm::kStatusInterruptRead);
    if (access == SmAccess::kEnd) {
      st.mailboxFull = true;
      st.hasLatest = true;  // for 1-buffer process data: outputs received
      status |= reg::sm::kStatusMailboxFull | reg::sm::kStatusInterruptWrite;
      ++counters_.mailboxWrites;
      events_.mailboxReceived = true;
      noteEvent();
    }
    return true;
  }
  if (!isEcatWrite(cfg.control)) return false;  // inputs: master writes are ignored
  const SmAccess access = smAccess(s, address, data.size());
  if (access == SmAccess::kDenied) return false;
  if (cfg.control.watchdogTrigger) triggerPdWatchdog();
  if (address == cfg.start) {  // the master's first byte clears "interrupt read" (0x0805)
    memory_[base + reg::sm::kStatus.address] &=
        static_cast<std::uint8_t>(~reg::sm::kStatusInterruptRead);
  }
  const std::size_t offset = static_cast<std::size_t>(address - cfg.start);
  const std::size_t bufBase = 3u * static_cast<std::size_t>(cfg.start);
  std::copy(
      data.begin(), data.end(),
      buffers_.begin() + static_cast<std::ptrdiff_t>(bufBase + st.writing * cfg.length + offset));
  if (access == SmAccess::kEnd) {  // buffer complete: it becomes the newest, writing goes on
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
    noteEvent();
  }
  return true;
}

// ---- PDI side -------------------------------------------------------------------------------

void Esc::pdiSetAlStatus(std::uint16_t status, std::uint16_t code) {
  const std::array<std::uint8_t, 2> s{static_cast<std::uint8_t>(status),
                                      static_cast<std::uint8_t>(status >> 8)};
  const std::array<std::uint8_t, 2> c{static_cast<std::uint8_t>(code),
                                      static_cast<std::uint8_t>(code >> 8)};
  pdiWriteRegisters(reg::kAlStatus.address, s);
  pdiWriteRegisters(reg::kAlStatusCode.address, c);
  // A PDI write of AL status is an AL status event for the master (0x0210 bit 3).
  pdiWrite(reg::kEcatEventRequest,
           static_cast<std::uint16_t>(read(reg::kEcatEventRequest) | reg::ecat_event::kAlStatus));
  refreshEcatEvents();
}

int Esc::mailboxSm(bool ecatWrite) const {
  // The enabled SMs of more than one byte are exactly those of smRanges_, in index order.
  for (std::uint8_t k = 0; k < smRangeCount_; ++k) {
    const SmConfig& c = smCache_[smRanges_[k].index];
    if (isMailbox(c.control) && isEcatWrite(c.control) == ecatWrite) return smRanges_[k].index;
  }
  return -1;
}

bool Esc::pdiMailboxAvailable() const {
  return mailboxSm(true) >= 0 && mailboxSm(false) >= 0;
}

std::size_t Esc::pdiMailboxReceive(Bytes out) {
  int s = mailboxSm(true);
  if (s < 0 || !sm_[static_cast<unsigned>(s)].mailboxFull) return 0;
  const SmConfig& c = smCache_[static_cast<unsigned>(s)];
  std::size_t n = std::min<std::size_t>(out.size(), c.length);
  std::copy_n(memory_.begin() + c.start, n, out.begin());
  pdiReadCompleted(static_cast<unsigned>(s));
  return n;
}

void Esc::pdiReadCompleted(unsigned s) {
  // The firmware read the whole buffer of a write-direction mailbox-mode SM (section II
  // 0x0805): its first byte cleared "interrupt write", the end address empties the mailbox and
  // sets "interrupt read", the SM's ECAT event. A real EL3004's SM0 reads 0x02 after its
  // firmware took a request (../shared/pcap/replay-ek1914-el3004-mailbox.pcapng frames 970, 984).
  sm_[s].mailboxFull = false;
  std::uint8_t& status = memory_[reg::smChannel(s) + reg::sm::kStatus.address];
  status = static_cast<std::uint8_t>(
      (status & ~(reg::sm::kStatusMailboxFull | reg::sm::kStatusInterruptWrite)) |
      reg::sm::kStatusInterruptRead);
  pdiSmStatusChanged();
}

bool Esc::pdiMailboxSend(ConstBytes data) {
  int s = mailboxSm(false);
  if (s < 0) return false;
  auto& st = sm_[static_cast<unsigned>(s)];
  if (st.mailboxFull) return false;
  const SmConfig& c = smCache_[static_cast<unsigned>(s)];
  std::size_t n = std::min<std::size_t>(data.size(), c.length);
  std::copy_n(data.begin(), n, memory_.begin() + c.start);
  std::fill_n(memory_.begin() + c.start + static_cast<std::ptrdiff_t>(n), c.length - n, 0);
  std::copy_n(memory_.begin() + c.start, c.length, lastMailboxResponse_.begin());
  lastMailboxResponseSize_ = c.length;
  st.mailboxFull = true;
  pdiWriteCompleted(static_cast<unsigned>(s));
  return true;
}

void Esc::pdiWriteCompleted(unsigned s) {
  // The firmware wrote a whole read-direction mailbox (section II 0x0805): its first byte
  // cleared "interrupt read", the end sets "interrupt write" with "mailbox full". A real
  // EL3004's SM1 reads 0x09 while a response waits (replay-ek1914-el3004-mailbox.pcapng
  // frames 964, 978, 992).
  std::uint8_t& status = memory_[reg::smChannel(s) + reg::sm::kStatus.address];
  status = static_cast<std::uint8_t>((status & ~reg::sm::kStatusInterruptRead) |
                                     reg::sm::kStatusMailboxFull |
                                     reg::sm::kStatusInterruptWrite);
  pdiSmStatusChanged();
}

bool Esc::pdiMailboxResponsePending() const {
  int s = mailboxSm(false);
  return s >= 0 && sm_[static_cast<unsigned>(s)].mailboxFull;
}

void Esc::pdiMailboxRepeat() {
  int s = mailboxSm(false);
  if (s < 0) return;
  const auto su = static_cast<unsigned>(s);
  const std::uint16_t base = reg::smChannel(su);
  const SmConfig& c = smCache_[su];
  if (lastMailboxResponseSize_ > 0 && lastMailboxResponseSize_ <= c.length) {
    std::copy_n(lastMailboxResponse_.begin(), lastMailboxResponseSize_, memory_.begin() + c.start);
    sm_[su].mailboxFull = true;
    pdiWriteCompleted(su);
  }
  // Acknowledge: copy the repeat request bit into the PDI control repeat-ack bit.
  std::uint8_t req = memory_[base + reg::sm::kActivate.address] & reg::sm::kActivateRepeatRequest;
  memory_[base + reg::sm::kPdiControl.address] = static_cast<std::uint8_t>(
      (memory_[base + reg::sm::kPdiControl.address] & ~reg::sm::kPdiRepeatAck) | req);
}

ConstBytes Esc::pdiOutputs(unsigned s) const {
  if (s >= type_.syncManagers) return {};
  const SmConfig& c = smCache_[s];
  if (!c.enabled || !isEcatWrite(c.control) || c.length == 0) return {};
  // 1-buffer (mailbox-mode) process data, and an SM of length 1 (no buffer at all): the
  // memory itself.
  if (isMailbox(c.control) || c.length == 1) return ConstBytes(memory_.data() + c.start, c.length);
  const std::size_t bufBase = 3u * static_cast<std::size_t>(c.start);
  return ConstBytes(buffers_.data() + bufBase + sm_[s].latest * c.length, c.length);
}

ConstBytes Esc::pdiReadOutputs(unsigned s) {
  const ConstBytes data = pdiOutputs(s);
  if (data.size() < 2 || isMailbox(smCache_[s].control) || !sm_[s].hasLatest) return data;
  // A 3-buffer output SM: the PDI reads the newest buffer from its start address to its end
  // (section II 0x0805: the first byte clears "interrupt write", the end sets "interrupt
  // read", signalled to the master as the SM's ECAT event; the master's next first byte
  // clears it). 1-buffer outputs are completed by pdiReleaseBuffer().
  std::uint8_t& status = memory_[reg::smChannel(s) + reg::sm::kStatus.address];
  status = static_cast<std::uint8_t>((status & ~reg::sm::kStatusInterruptWrite) |
                                     reg::sm::kStatusInterruptRead);
  pdiSmStatusChanged();
  return data;
}

bool Esc::pdiWriteInputs(unsigned s, ConstBytes data) {
  if (s >= type_.syncManagers) return false;
  const SmConfig& c = smCache_[s];
  if (!c.enabled || isEcatWrite(c.control) || c.length == 0) return false;
  auto& st = sm_[s];
  if (c.length == 1) {  // no buffer (section II Table 90): the PDI writes the memory itself
    if (!data.empty()) memory_[c.start] = data[0];
    return true;
  }
  if (isMailbox(c.control)) {
    // 1-buffer inputs: the PDI may write only when the master has read the last buffer.
    if (st.mailboxFull) return false;
    const std::size_t n1 = std::min<std::size_t>(data.size(), c.length);
    std::copy_n(data.begin(), n1, memory_.begin() + c.start);
    st.mailboxFull = true;
    pdiWriteCompleted(s);
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
  // The PDI completed a buffer: "interrupt write" for the master (its SM event, 0x0210), and
  // its own "interrupt read" is cleared by this write (section II 0x0805).
  std::uint8_t& status = memory_[reg::smChannel(s) + reg::sm::kStatus.address];
  status = static_cast<std::uint8_t>(
      (status & ~(reg::sm::kStatusBufferMask | reg::sm::kStatusInterruptRead)) | (done << 4) |
      reg::sm::kStatusInterruptWrite);
  pdiSmStatusChanged();
  return true;
}

void Esc::pdiReleaseBuffer(unsigned s) {
  if (s >= type_.syncManagers) return;
  const SmConfig& c = smCache_[s];
  if (!c.enabled || c.length < 2 || !isMailbox(c.control) || !isEcatWrite(c.control)) return;
  if (!sm_[s].mailboxFull) return;  // nothing taken: no read
  pdiReadCompleted(s);
}

}  // namespace ecsim::slavesim
