// AL control as the ESC itself handles it, and the ECAT event request register with the IRQ
// field of the datagrams (ESC datasheet section II 0x0120, 0x0200, 0x0210, 0x0220).
//
// AL control: with device emulation (0x0141 bit 0, loaded from SII word 0) the ESC copies
// every value the master writes into AL status, error-acknowledge bit included, without any
// state check: a real EK1100 answers BWR 0x0120 = 0x0011 with AL status 0x0011
// (replay-dc.pcapng frames 4/96) and FPWR 0x0012 with 0x0012 (soem-sdinfo-ek1100-el1004.pcapng
// frames 197/291). Without device emulation AL control behaves like a mailbox: once the master
// wrote it, it cannot write again until the firmware has read it through the PDI (0x0120
// note); the firmware's read also clears AL event request 0x0220 bit 0.
//
// ECAT events: 0x0210 collects DC latch (bit 0), DL status change (bit 2, cleared by an ECAT
// read of 0x0110), AL status change (bit 3, cleared by an ECAT read of 0x0130) and SyncManager
// events (bit 4 + n); masked by 0x0200 it is ORed into the IRQ field of every datagram as the
// header passes (so the datagram that reads 0x0110 still carries the DL status event, and the
// next one does not: soem-sdinfo-ek1100-el1004.pcapng frames 201 and 203).
#include <algorithm>
#include <bit>

#include "slavesim/esc.hpp"
#include "slavesim/esc_internal.hpp"

namespace ecsim::slavesim {
using namespace esc_detail;

void Esc::resetEventState() {
  // Reset values of DL control and 0x0210 are the table's (esc_register_table.cpp).
  alControlUnread_ = false;  // "After reset, AL control can be written by ECAT" (0x0120 note)
  smEventMask_ = 0;
  refreshEcatEvents();
}

std::uint16_t Esc::pdiReadAlControl() {
  alControlUnread_ = false;
  pdiWrite(reg::kAlEventRequest, read(reg::kAlEventRequest) & ~reg::al_event::kAlControl);
  return read(reg::kAlControl);
}

void Esc::ecatAlControlWritten() {
  events_.alControlWritten = true;
  noteEvent();
  pdiWrite(reg::kAlEventRequest, read(reg::kAlEventRequest) | reg::al_event::kAlControl);
  if (!deviceEmulation()) {
    alControlUnread_ = true;
    return;
  }
  // Copied as written (all 16 bits; the AL status code 0x0134 is left alone).
  pdiWrite(reg::kAlStatus, read(reg::kAlControl));
  pdiWrite(reg::kEcatEventRequest,
           static_cast<std::uint16_t>(read(reg::kEcatEventRequest) | reg::ecat_event::kAlStatus));
  refreshEcatEvents();
}

void Esc::dlStatusChanged() {
  pdiWrite(reg::kEcatEventRequest,
           static_cast<std::uint16_t>(read(reg::kEcatEventRequest) | reg::ecat_event::kDlStatus));
  refreshEcatEvents();
}

void Esc::refreshEcatEvents() {
  namespace ev = reg::ecat_event;
  auto request = static_cast<std::uint16_t>(read(reg::kEcatEventRequest) &
                                            (ev::kDlStatus | ev::kAlStatus));
  // DC latch event: pending while an ECAT-owned latch unit's status shows an edge event
  // (esc_latch.cpp keeps the flag as the status changes).
  if (latchEcatEvent_) request |= ev::kDcLatch;
  // SyncManager n event (section I §8, SM control bit 4 "interrupt in ECAT event request"):
  // pending while the buffer has something for the master (read direction: mailbox full or a
  // new buffer written by the PDI) or the PDI has taken what the master wrote (write
  // direction: "interrupt read"), as the SM's status register shows it.
  const unsigned count = std::min<unsigned>(type_.syncManagers, ev::kMaxSmEvents);
  // Only the SMs whose control byte asks for it (smEventControl_, decoded when written).
  for (unsigned bits = smEventControl_ & ((1u << count) - 1); bits != 0; bits &= bits - 1) {
    const auto s = static_cast<unsigned>(std::countr_zero(bits));
    const std::uint16_t base = reg::smChannel(s);
    const SmControl& control = smCache_[s].control;
    if ((memory_[base + reg::sm::kActivate.address] & reg::sm::kActivateEnable) == 0) continue;
    const std::uint8_t status = memory_[base + reg::sm::kStatus.address];
    const std::uint8_t pending = control.isEcatWrite() ? reg::sm::kStatusInterruptRead
                                 : control.isMailbox() ? reg::sm::kStatusMailboxFull
                                                      : reg::sm::kStatusInterruptWrite;
    if ((status & pending) != 0) request = static_cast<std::uint16_t>(request | (1u << (ev::kSmShift + s)));
  }
  pdiWrite(reg::kEcatEventRequest, request);
  ecatIrq_ = static_cast<std::uint16_t>(request & read(reg::kEcatEventMask));
  noteIrq();
}

void Esc::ecatEventMaskWritten() {
  smEventMask_ = static_cast<std::uint16_t>(read(reg::kEcatEventMask) & reg::ecat_event::kSmBits);
  refreshEcatEvents();
}

void Esc::clearEcatEvents(std::uint16_t bits) {
  pdiWrite(reg::kEcatEventRequest, static_cast<std::uint16_t>(read(reg::kEcatEventRequest) & ~bits));
  refreshEcatEvents();
}

}  // namespace ecsim::slavesim
