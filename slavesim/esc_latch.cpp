// The DC latch unit (ESC datasheet section I "Distributed Clocks: LatchSignals"; section II
// 0x0980, 0x09A8-0x09CF, 0x0210 bit 0, 0x0220 bit 1).
//
// Two latch inputs (LATCH0/LATCH1) whose edges are time-stamped with the system time:
//  - each unit belongs to ECAT or to the PDI (0x0980 bit 4 for unit 0, bit 5 for unit 1);
//    only the owner writes its control register 0x09A8/0x09A9, and only the owner's read of a
//    latch time clears the event it shows;
//  - control bit 0 (positive edge) / bit 1 (negative edge): 0 = continuous, every edge
//    overwrites the time register and no event is shown; 1 = single event, only the first
//    edge is stored and the status 0x09AE/0x09AF bit 0/1 set, until the owner reads that time
//    register (0x09B0 + 16 unit + 8 negative; the read of its bits 7:0, which also latch the
//    upper bytes, section II note);
//  - status bit 2 is the pin's level;
//  - an event of an ECAT-owned unit is the DC latch event 0x0210 bit 0 (masked by 0x0200 into
//    the datagrams' IRQ field, esc_events.cpp), of a PDI-owned one AL event 0x0220 bit 1.
// The input is driven from outside (Slave::setLatchSignal, the "latch" fault action) with the
// simulation time of each edge, so the stored time is the system time at that instant.
#include <algorithm>

#include "slavesim/esc.hpp"
#include "slavesim/esc_internal.hpp"

namespace ecsim::slavesim {
using namespace esc_detail;

namespace {
std::uint16_t statusAddress(unsigned unit) {
  return static_cast<std::uint16_t>(reg::kLatch0Status.address + unit);
}
std::uint16_t controlAddress(unsigned unit) {
  return static_cast<std::uint16_t>(reg::kLatch0Control.address + unit);
}
}  // namespace

void Esc::latchReset() {
  latchEcatEvent_ = false;
  for (unsigned u = 0; u < reg::latch::kUnits; ++u) {
    memory_[statusAddress(u)] = latchPin_[u] ? reg::latch::kStatusPin : 0;
  }
}

void Esc::setLatchInput(unsigned unit, bool level, SimTime time) {
  if (unit >= reg::latch::kUnits || dcUnit_ != DcUnit::kFull) return;
  const bool previous = latchPin_[unit];
  latchPin_[unit] = level;
  std::uint8_t& status = memory_[statusAddress(unit)];
  status = static_cast<std::uint8_t>(level ? status | reg::latch::kStatusPin
                                           : status & ~reg::latch::kStatusPin);
  if (previous == level) return;
  // Positive and negative edge: control bit, status bit and time register of the edge.
  const bool negative = !level;
  const std::uint8_t bit =
      negative ? reg::latch::kStatusNegativeEvent : reg::latch::kStatusPositiveEvent;
  const bool single = (memory_[controlAddress(unit)] & bit) != 0;
  if (single && (status & bit) != 0) return;  // only the first edge until it is read
  writeLe64(memory_, reg::latch::timeRegister(unit, negative),
            static_cast<std::uint64_t>(systemTime(time)));
  if (!single) return;  // continuous mode: the time only, no event
  status |= bit;
  latchEventsChanged();
}

void Esc::latchTimesRead(std::uint32_t begin, std::uint32_t end) {
  bool changed = false;
  for (unsigned u = 0; u < reg::latch::kUnits; ++u) {
    if (latchOwnedByPdi(u)) continue;
    for (const bool negative : {false, true}) {
      const std::uint16_t first = reg::latch::timeRegister(u, negative);
      if (first < begin || first >= end) continue;
      memory_[statusAddress(u)] &= static_cast<std::uint8_t>(
          ~(negative ? reg::latch::kStatusNegativeEvent : reg::latch::kStatusPositiveEvent));
      changed = true;
    }
  }
  if (changed) latchEventsChanged();
}

std::uint64_t Esc::pdiReadLatchTime(unsigned unit, bool negativeEdge) {
  if (unit >= reg::latch::kUnits) return 0;
  const std::uint64_t time = reg64(reg::latch::timeRegister(unit, negativeEdge));
  if (latchOwnedByPdi(unit)) {
    memory_[statusAddress(unit)] &= static_cast<std::uint8_t>(
        ~(negativeEdge ? reg::latch::kStatusNegativeEvent : reg::latch::kStatusPositiveEvent));
    latchEventsChanged();
  }
  return time;
}

void Esc::latchControlWritten() {
  // Status bits 0/1: "0: edge not detected or continuous mode" (section II 0x09AE): an edge
  // switched to continuous mode shows no event.
  for (unsigned u = 0; u < reg::latch::kUnits; ++u) {
    const auto single = static_cast<std::uint8_t>(memory_[controlAddress(u)] &
                                                  reg::latch::kControlMask);
    memory_[statusAddress(u)] = static_cast<std::uint8_t>(
        memory_[statusAddress(u)] & (reg::latch::kStatusPin | single));
  }
  latchEventsChanged();
}

void Esc::latchEventsChanged() {
  bool ecat = false;
  bool pdi = false;
  for (unsigned u = 0; u < reg::latch::kUnits; ++u) {
    if ((memory_[statusAddress(u)] & reg::latch::kStatusEvents) == 0) continue;
    (latchOwnedByPdi(u) ? pdi : ecat) = true;
  }
  const std::uint32_t al = read(reg::kAlEventRequest);
  pdiWrite(reg::kAlEventRequest,
           pdi ? al | reg::al_event::kDcLatch : al & ~reg::al_event::kDcLatch);
  if (ecat == latchEcatEvent_) return;
  latchEcatEvent_ = ecat;
  refreshEcatEvents();
}

}  // namespace ecsim::slavesim
