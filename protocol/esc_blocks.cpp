#include "protocol/esc_blocks.hpp"

#include <algorithm>
#include <bit>
#include <string>

namespace ecsim {
namespace {

namespace sm = reg::sm;
namespace fm = reg::fmmu;

// The value of a multi-bit field, and the bits that put it back (shift taken from the mask).
constexpr std::uint8_t field(std::uint8_t byte, std::uint8_t mask) {
  return static_cast<std::uint8_t>((byte & mask) >> std::countr_zero(mask));
}
constexpr std::uint8_t place(std::uint8_t value, std::uint8_t mask) {
  return static_cast<std::uint8_t>((value << std::countr_zero(mask)) & mask);
}
constexpr std::uint8_t flag(bool on, std::uint8_t bit) {
  return on ? bit : std::uint8_t{0};
}

constexpr std::uint8_t kControlKnown = sm::kControlModeMask | sm::kControlDirectionMask |
                                       sm::kControlEcatEvent | sm::kControlPdiEvent |
                                       sm::kControlWatchdog;
constexpr std::uint8_t kStatusKnown = sm::kStatusInterruptWrite | sm::kStatusInterruptRead |
                                      sm::kStatusMailboxFull | sm::kStatusBufferMask |
                                      sm::kStatusReadBufferOpen | sm::kStatusWriteBufferOpen;
constexpr std::uint8_t kActivateKnown = sm::kActivateEnable | sm::kActivateRepeatRequest |
                                        sm::kActivateLatchEcat | sm::kActivateLatchPdi;
constexpr std::uint8_t kPdiControlKnown = sm::kPdiDeactivate | sm::kPdiRepeatAck;
constexpr std::uint8_t kTypeKnown = fm::kTypeRead | fm::kTypeWrite;

constexpr std::uint8_t unknown(std::uint8_t byte, std::uint8_t known) {
  return static_cast<std::uint8_t>(byte & ~known);
}

Error tooShort(std::string_view what, std::size_t have, std::size_t need) {
  return makeError(ErrorCode::kTruncated, std::string(what) + ": " + std::to_string(have) +
                                              " bytes, a channel has " + std::to_string(need));
}

}  // namespace

SmControl SmControl::decode(std::uint8_t b) {
  SmControl c;
  c.mode = static_cast<SmMode>(field(b, sm::kControlModeMask));
  c.direction = static_cast<SmDirection>(field(b, sm::kControlDirectionMask));
  c.ecatEvent = (b & sm::kControlEcatEvent) != 0;
  c.pdiEvent = (b & sm::kControlPdiEvent) != 0;
  c.watchdogTrigger = (b & sm::kControlWatchdog) != 0;
  c.reserved = unknown(b, kControlKnown);
  return c;
}

std::uint8_t SmControl::encode() const {
  return static_cast<std::uint8_t>(
      place(static_cast<std::uint8_t>(mode), sm::kControlModeMask) |
      place(static_cast<std::uint8_t>(direction), sm::kControlDirectionMask) |
      flag(ecatEvent, sm::kControlEcatEvent) | flag(pdiEvent, sm::kControlPdiEvent) |
      flag(watchdogTrigger, sm::kControlWatchdog) | unknown(reserved, kControlKnown));
}

SmStatus SmStatus::decode(std::uint8_t b) {
  SmStatus s;
  s.interruptWrite = (b & sm::kStatusInterruptWrite) != 0;
  s.interruptRead = (b & sm::kStatusInterruptRead) != 0;
  s.mailboxFull = (b & sm::kStatusMailboxFull) != 0;
  s.lastBuffer = field(b, sm::kStatusBufferMask);
  s.readBufferOpen = (b & sm::kStatusReadBufferOpen) != 0;
  s.writeBufferOpen = (b & sm::kStatusWriteBufferOpen) != 0;
  s.reserved = unknown(b, kStatusKnown);
  return s;
}

std::uint8_t SmStatus::encode() const {
  return static_cast<std::uint8_t>(
      flag(interruptWrite, sm::kStatusInterruptWrite) |
      flag(interruptRead, sm::kStatusInterruptRead) | flag(mailboxFull, sm::kStatusMailboxFull) |
      place(lastBuffer, sm::kStatusBufferMask) | flag(readBufferOpen, sm::kStatusReadBufferOpen) |
      flag(writeBufferOpen, sm::kStatusWriteBufferOpen) | unknown(reserved, kStatusKnown));
}

SmActivate SmActivate::decode(std::uint8_t b) {
  SmActivate a;
  a.enable = (b & sm::kActivateEnable) != 0;
  a.repeatRequest = (b & sm::kActivateRepeatRequest) != 0;
  a.latchEcat = (b & sm::kActivateLatchEcat) != 0;
  a.latchPdi = (b & sm::kActivateLatchPdi) != 0;
  a.reserved = unknown(b, kActivateKnown);
  return a;
}

std::uint8_t SmActivate::encode() const {
  return static_cast<std::uint8_t>(
      flag(enable, sm::kActivateEnable) | flag(repeatRequest, sm::kActivateRepeatRequest) |
      flag(latchEcat, sm::kActivateLatchEcat) | flag(latchPdi, sm::kActivateLatchPdi) |
      unknown(reserved, kActivateKnown));
}

SmPdiControl SmPdiControl::decode(std::uint8_t b) {
  SmPdiControl p;
  p.deactivate = (b & sm::kPdiDeactivate) != 0;
  p.repeatAck = (b & sm::kPdiRepeatAck) != 0;
  p.reserved = unknown(b, kPdiControlKnown);
  return p;
}

std::uint8_t SmPdiControl::encode() const {
  return static_cast<std::uint8_t>(flag(deactivate, sm::kPdiDeactivate) |
                                   flag(repeatAck, sm::kPdiRepeatAck) |
                                   unknown(reserved, kPdiControlKnown));
}

Result<SyncManagerBlock> SyncManagerBlock::parse(ConstBytes b) {
  if (b.size() < reg::kSmSize) return tooShort("SyncManager channel", b.size(), reg::kSmSize);
  SyncManagerBlock s;
  s.start = readLe16(b, sm::kPhysicalStart.address);
  s.length = readLe16(b, sm::kLength.address);
  s.control = SmControl::decode(b[sm::kControl.address]);
  s.status = SmStatus::decode(b[sm::kStatus.address]);
  s.activate = SmActivate::decode(b[sm::kActivate.address]);
  s.pdiControl = SmPdiControl::decode(b[sm::kPdiControl.address]);
  return s;
}

void SyncManagerBlock::emit(Bytes out) const {
  writeLe16(out, sm::kPhysicalStart.address, start);
  writeLe16(out, sm::kLength.address, length);
  out[sm::kControl.address] = control.encode();
  out[sm::kStatus.address] = status.encode();
  out[sm::kActivate.address] = activate.encode();
  out[sm::kPdiControl.address] = pdiControl.encode();
}

std::array<std::uint8_t, reg::kSmSize> SyncManagerBlock::bytes() const {
  std::array<std::uint8_t, reg::kSmSize> b{};
  emit(b);
  return b;
}

Result<FmmuBlock> FmmuBlock::parse(ConstBytes b) {
  if (b.size() < reg::kFmmuSize) return tooShort("FMMU channel", b.size(), reg::kFmmuSize);
  FmmuBlock f;
  f.logicalStart = readLe32(b, fm::kLogicalStart.address);
  f.length = readLe16(b, fm::kLength.address);
  f.logicalStartBit = b[fm::kLogicalStartBit.address];
  f.logicalStopBit = b[fm::kLogicalStopBit.address];
  f.physicalStart = readLe16(b, fm::kPhysicalStart.address);
  f.physicalStartBit = b[fm::kPhysicalStartBit.address];
  const std::uint8_t type = b[fm::kType.address];
  f.read = (type & fm::kTypeRead) != 0;
  f.write = (type & fm::kTypeWrite) != 0;
  f.typeReserved = unknown(type, kTypeKnown);
  const std::uint8_t activate = b[fm::kActivate.address];
  f.enable = (activate & fm::kActivateEnable) != 0;
  f.activateReserved = unknown(activate, fm::kActivateEnable);
  std::copy_n(b.begin() + fm::kReserved.address, fm::kReserved.width, f.reserved.begin());
  return f;
}

void FmmuBlock::emit(Bytes out) const {
  writeLe32(out, fm::kLogicalStart.address, logicalStart);
  writeLe16(out, fm::kLength.address, length);
  out[fm::kLogicalStartBit.address] = logicalStartBit;
  out[fm::kLogicalStopBit.address] = logicalStopBit;
  writeLe16(out, fm::kPhysicalStart.address, physicalStart);
  out[fm::kPhysicalStartBit.address] = physicalStartBit;
  out[fm::kType.address] = static_cast<std::uint8_t>(
      flag(read, fm::kTypeRead) | flag(write, fm::kTypeWrite) | unknown(typeReserved, kTypeKnown));
  out[fm::kActivate.address] = static_cast<std::uint8_t>(
      flag(enable, fm::kActivateEnable) | unknown(activateReserved, fm::kActivateEnable));
  std::copy(reserved.begin(), reserved.end(), out.begin() + fm::kReserved.address);
}

std::array<std::uint8_t, reg::kFmmuSize> FmmuBlock::bytes() const {
  std::array<std::uint8_t, reg::kFmmuSize> b{};
  emit(b);
  return b;
}

}  // namespace ecsim
