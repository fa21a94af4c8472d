#include "slavesim/process_data.hpp"

#include <algorithm>
#include <array>
#include <string>

#include "slavesim/coe/sdo_access.hpp"

namespace ecsim::slavesim {
namespace {

std::string hex4(std::uint32_t v) {
  constexpr char kDigits[] = "0123456789ABCDEF";
  std::string s = "0x";
  for (int shift = 12; shift >= 0; shift -= 4) s += kDigits[(v >> shift) & 0xF];
  return s;
}

constexpr std::uint16_t kUnusableLength = 0xFFFF;  // no master configuration matches it

// The ESC's 3-buffer model covers SMs in process RAM only (an SM over registers, such as the
// 2006-era EL2004's SM0 at 0x0F00, holds no buffer): copy only through SMs that lie there.
bool inProcessRam(const Esc& esc, unsigned sm) {
  const Esc::SmConfig c = esc.smConfig(sm);
  return c.start >= reg::kRegisterSpaceEnd &&
         static_cast<std::size_t>(c.start) + c.length <= esc.memorySize();
}

// Digital output terminals served by the ESC's digital I/O (the 2006-era EL2004, the EM2042:
// output SMs of one byte at 0x0F00/0x0F01, which activate no buffer, section II Table 90): the
// outputs are the Digital I/O Output Data register 0x0F00-0x0F03 the master's FMMU writes.
bool inDigitalOutputRegister(const Esc& esc, unsigned sm) {
  const Esc::SmConfig c = esc.smConfig(sm);
  constexpr std::uint32_t first = reg::kDigitalIoOutputData.address;
  return c.start >= first &&
         static_cast<std::uint32_t>(c.start) + c.length <= first + sizeof(std::uint32_t);
}

// Digital input terminals served by the ESC's digital I/O PDI (PDI control 0x01-0x04; the
// 2006-era EL1002/EL1004, whose ESI leaves their input SM at 0x1000 disabled, Enable="0", and
// so SOEM leaves it): the ESC writes the inputs into process RAM 0x1000-0x1003 itself (section
// II, Digital I/O Input Data), where the master's FMMU reads them with or without an SM.
bool digitalInputPdi(const Esc& esc) {
  const std::uint8_t pdi = esc.reg8(reg::kPdiControl.address);
  return pdi >= reg::kPdiFourDigitalInputs && pdi <= reg::kPdiDigitalIo;
}

}  // namespace

Result<std::vector<ProcessDataSmLayout>> computeProcessDataLayout(const coe::ObjectDictionary& od) {
  std::vector<ProcessDataSmLayout> out;
  const coe::Object* types = od.find(coe::kSmTypesIndex);
  if (types == nullptr) return out;
  for (const coe::Entry& t : types->entries) {
    if (t.subindex == 0 || t.value.empty()) continue;
    const bool outputs = t.value[0] == coe::kSmTypeOutputs;
    if (!outputs && t.value[0] != coe::kSmTypeInputs) continue;
    ProcessDataSmLayout sm;
    sm.sm = t.subindex - 1u;
    sm.outputs = outputs;
    const auto assignIndex = static_cast<std::uint16_t>(coe::kPdoAssignBase + sm.sm);
    if (!od.contains(assignIndex)) continue;
    for (std::uint16_t pdo : coe::assignedPdos(od, sm.sm)) {
      if (!od.contains(pdo)) {
        return makeError(ErrorCode::kNotFound, hex4(assignIndex) + " assigns PDO " + hex4(pdo) +
                                                   ", which does not exist");
      }
      for (const coe::MappedObject& m : coe::mappedObjects(od, pdo)) {
        if (!m.isPadding()) {
          const coe::Entry* e = od.findEntry(m.index, m.subindex);
          if (e == nullptr) {
            return makeError(ErrorCode::kNotFound, "PDO " + hex4(pdo) + " maps " + hex4(m.index) +
                                                       ":" + std::to_string(m.subindex) +
                                                       ", which does not exist");
          }
          if (m.bitLength > 8 * e->byteSize()) {
            return makeError(ErrorCode::kInvalidArgument,
                             "PDO " + hex4(pdo) + " maps " + std::to_string(m.bitLength) +
                                 " bits of " + hex4(m.index) + ":" + std::to_string(m.subindex) +
                                 ", which has " + std::to_string(e->bitLength));
          }
        }
        sm.entries.push_back(m);
        sm.bitLength += m.bitLength;
      }
    }
    out.push_back(std::move(sm));
  }
  return out;
}

Status ProcessDataBinding::bind(coe::ObjectDictionary& od, std::uint32_t skip) {
  layout_.clear();
  buffers_.clear();
  copies_.clear();
  auto layout = computeProcessDataLayout(od);
  if (!layout.ok()) return layout.takeError();
  layout_ = std::move(layout).value();
  for (const ProcessDataSmLayout& sm : layout_) {
    const std::size_t buffer = buffers_.size();
    buffers_.push_back({sm.sm, sm.outputs, std::vector<std::uint8_t>(sm.byteLength(), 0)});
    if (sm.sm < 32 && (skip & (1u << sm.sm)) != 0) continue;
    std::uint32_t offset = 0;
    for (const coe::MappedObject& m : sm.entries) {
      if (!m.isPadding() && m.bitLength > 0) {
        coe::Entry* e = od.findEntry(m.index, m.subindex);
        copies_.push_back({buffer, offset, m.bitLength, e->value.data(), e->value.size()});
      }
      offset += m.bitLength;
    }
  }
  return okStatus();
}

void ProcessDataBinding::fillProfile(SlaveProfile& profile, std::uint32_t unchecked) const {
  profile.processData.clear();
  for (const ProcessDataSmLayout& sm : layout_) {
    if (sm.sm < 32 && (unchecked & (1u << sm.sm)) != 0) continue;
    profile.processData.push_back({sm.sm, sm.outputs, sm.byteLength()});
  }
}

void ProcessDataBinding::readOutputs(Esc& esc) {
  // One PDI read of each output SM's buffer (its copies are consecutive), as firmware reads
  // the whole buffer: the ESC marks it read (SM status "interrupt read", Esc::pdiReadOutputs).
  std::size_t current = buffers_.size();
  ConstBytes src;
  std::array<std::uint8_t, sizeof(std::uint32_t)> digitalOutputs{};
  for (const Copy& c : copies_) {
    const Buffer& b = buffers_[c.buffer];
    if (!b.outputs) continue;
    if (c.buffer != current) {
      current = c.buffer;
      src = esc.pdiOutputsReceived(b.sm) && inProcessRam(esc, b.sm) ? esc.pdiReadOutputs(b.sm)
                                                                    : ConstBytes{};
      if (inDigitalOutputRegister(esc, b.sm)) {
        writeLe32(digitalOutputs, 0, esc.read(reg::kDigitalIoOutputData));
        const Esc::SmConfig sm = esc.smConfig(b.sm);
        src = ConstBytes(digitalOutputs.data() + (sm.start - reg::kDigitalIoOutputData.address),
                         sm.length);
      }
    }
    if (src.empty() || static_cast<std::size_t>(c.bitOffset) + c.bits > 8 * src.size()) continue;
    coe::copyBits(Bytes(c.value, c.valueSize), 0, src, c.bitOffset, c.bits);
  }
}

void ProcessDataBinding::writeInputs(Esc& esc) {
  for (const Copy& c : copies_) {
    Buffer& b = buffers_[c.buffer];
    if (b.outputs) continue;
    coe::copyBits(b.bytes, c.bitOffset, ConstBytes(c.value, c.valueSize), 0, c.bits);
  }
  for (Buffer& b : buffers_) {
    if (b.outputs || b.bytes.empty()) continue;
    if (inProcessRam(esc, b.sm) && esc.pdiWriteInputs(b.sm, b.bytes)) continue;
    if (digitalInputPdi(esc) && b.bytes.size() <= reg::kDigitalIoInputData.width) {
      // No SM buffer takes them: the digital I/O PDI writes the inputs to RAM itself.
      for (std::size_t i = 0; i < b.bytes.size(); ++i) {
        esc.pdiWrite8(static_cast<std::uint16_t>(reg::kDigitalIoInputData.address + i), b.bytes[i]);
      }
    }
  }
}

ProcessDataDevice::ProcessDataDevice(std::shared_ptr<coe::ObjectDictionary> od)
    : od_(std::move(od)) {
  bindStatus_ = binding_.bind(*od_);
}

void ProcessDataDevice::updateProfile(SlaveProfile& profile) {
  // Sync mode and minimum cycle time as the dictionary holds them now (0x1C32:01, :05).
  const coe::Entry* mode = od_->findEntry(coe::kSmOutputParameterIndex, 1);
  profile.sync.mode = mode != nullptr && mode->value.size() >= 2 ? readLe16(mode->value, 0)
                                                                 : SlaveProfile::kNoSyncObject;
  const coe::Entry* minCycle = od_->findEntry(coe::kSmOutputParameterIndex, 5);
  profile.sync.minCycleNs =
      minCycle != nullptr && minCycle->value.size() >= 4 ? readLe32(minCycle->value, 0) : 0;
  bindStatus_ = binding_.bind(*od_, virtualSms_);
  if (bindStatus_.ok()) {
    binding_.fillProfile(profile, virtualSms_);
    return;
  }
  // An unusable PDO configuration: no SM configuration can satisfy the ESM, so
  // PREOP->SAFEOP is refused with "invalid output/input configuration".
  profile.processData.clear();
  if (const coe::Object* types = od_->find(coe::kSmTypesIndex); types != nullptr) {
    for (const coe::Entry& t : types->entries) {
      if (t.subindex == 0 || t.value.empty()) continue;
      const unsigned sm = t.subindex - 1u;
      if (sm < 32 && (virtualSms_ & (1u << sm)) != 0) continue;
      if (t.value[0] == coe::kSmTypeOutputs || t.value[0] == coe::kSmTypeInputs) {
        profile.processData.push_back({sm, t.value[0] == coe::kSmTypeOutputs, kUnusableLength});
      }
    }
  }
}

void ProcessDataDevice::step(Esc& esc, AlState state, SimTime now) {
  const bool exchanging = state == AlState::kSafeOp || state == AlState::kOp;
  if (exchanging) binding_.readOutputs(esc);
  if (application_) {
    application_->setSyncActive(esc.syncActive(0));
    application_->step(*od_, state, now);
  }
  if (exchanging) binding_.writeInputs(esc);
}

void ProcessDataDevice::sync(Esc& esc, unsigned signal, AlState state, SimTime now) {
  if (!application_) return;
  const bool exchanging = state == AlState::kSafeOp || state == AlState::kOp;
  if (exchanging) binding_.readOutputs(esc);
  application_->setSyncActive(esc.syncActive(0));
  application_->sync(*od_, signal, state, now);
  if (exchanging) binding_.writeInputs(esc);
}

void ProcessDataDevice::powerUp() {
  if (!od_->hasPowerUpValues()) od_->capturePowerUpValues();
}

Status ProcessDataDevice::coldStart() {
  powerUp();  // switched off before the firmware ever ran: nothing to forget
  od_->restorePowerUpValues();
  bindStatus_ = binding_.bind(*od_, virtualSms_);
  if (restart_) return restart_(*this);
  return okStatus();
}

}  // namespace ecsim::slavesim
