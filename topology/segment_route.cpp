// Segment::passRoute: a frame along the recorded route (no faults, no observers).
#include <algorithm>
#include <bit>

#include "topology/segment.hpp"

namespace ecsim::topology {
namespace {

// FPRD/FPWR/FPRW: one ESC (its station address or enabled alias) acts on it. FRMW writes at
// every ESC but the addressed one, so it goes everywhere like auto-increment, broadcast and
// logical datagrams; NOP and unknown commands only collect the IRQ field.
enum class Reach { kEverywhere, kAddressed, kHeaderOnly };

Reach reach(const DatagramView& d) {
  if (!isKnownCommand(d.rawCommand())) return Reach::kHeaderOnly;
  const Command cmd = d.command();
  switch (addressMode(cmd)) {
    case AddressMode::kNone:
      return Reach::kHeaderOnly;
    case AddressMode::kConfigured:
      return cmd == Command::kFrmw ? Reach::kEverywhere : Reach::kAddressed;
    default:
      return Reach::kEverywhere;
  }
}

}  // namespace

void Segment::passRoute(std::size_t count, const std::array<SimTime, 128>& leads,
                        SimTime sendTime) {
  bool addressedOnly = false;
  for (std::size_t i = 0; i < count && !addressedOnly; ++i) {
    addressedOnly = reach(datagrams_[i]) == Reach::kAddressed;
  }
  if (addressedOnly) {
    passRouteIndexed(count, leads, sendTime);
    return;
  }
  for (const RouteStop& stop : route_) {
    slavesim::Esc& esc = *escs_[stop.slave];
    esc.beginFrame();
    const SimTime t = sendTime + stop.at;
    for (std::size_t i = 0; i < count; ++i) esc.processDatagram(datagrams_[i], t + leads[i]);
    if (esc.receiveTimeLatchArmed()) latched_.push_back(stop.slave);
  }
}

void Segment::passRouteIndexed(std::size_t count, const std::array<SimTime, 128>& leads,
                               SimTime sendTime) {
  // byAddress_ holds ADP << 8 | index, sorted: one ADP's datagrams in frame order.
  std::size_t nEverywhere = 0;
  std::size_t nAddressed = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const Reach r = reach(datagrams_[i]);
    if (r == Reach::kEverywhere) everywhere_[nEverywhere++] = static_cast<std::uint8_t>(i);
    if (r == Reach::kAddressed) {
      byAddress_[nAddressed++] = static_cast<std::uint32_t>(datagrams_[i].adp()) << 8 | static_cast<std::uint32_t>(i);
    }
  }
  std::sort(byAddress_.begin(), byAddress_.begin() + static_cast<std::ptrdiff_t>(nAddressed));
  const auto* addrBegin = byAddress_.data();
  const auto* addrEnd = byAddress_.data() + nAddressed;
  // The first datagram of `adp` at index >= from, and the end of that ADP's run.
  auto run = [&](std::uint16_t adp, std::size_t from) {
    const std::uint32_t key = static_cast<std::uint32_t>(adp) << 8;
    const auto* b = std::lower_bound(addrBegin, addrEnd, key | static_cast<std::uint32_t>(from));
    const auto* e = std::lower_bound(b, addrEnd, key + 0x100);
    return std::pair{b, e};
  };
  for (auto& bit : irqRuns_) std::fill(bit.begin(), bit.begin() + static_cast<std::ptrdiff_t>(count) + 1, 0);
  // This ESC's event request `irq` goes into the IRQ field of datagrams [from, to).
  auto addIrq = [&](std::uint16_t irq, std::size_t from, std::size_t to) {
    if (irq == 0 || from >= to) return;
    for (unsigned bits = irq; bits != 0; bits &= bits - 1) {
      const auto b = static_cast<unsigned>(std::countr_zero(bits));
      ++irqRuns_[b][from];
      --irqRuns_[b][to];
    }
  };
  constexpr std::size_t kNone = 128;
  // The ESCs further down the route are brought into the cache while this one works (a long
  // line's ESCs do not stay in the cache between frames).
  constexpr std::size_t kPrefetch = 8;
  const std::size_t stops = route_.size();
  for (std::size_t k = 0; k < stops; ++k) {
    const RouteStop& stop = route_[k];
    if (k + kPrefetch < stops) escs_[route_[k + kPrefetch].slave]->prefetchFrameState();
    slavesim::Esc& esc = *escs_[stop.slave];
    esc.beginFrame();
    const SimTime t = sendTime + stop.at;
    std::uint16_t station = esc.stationAddress();
    bool aliasOn = esc.aliasEnabled();
    std::uint16_t alias = esc.stationAlias();
    auto [s, sEnd] = run(station, 0);
    auto [a, aEnd] = aliasOn && alias != station ? run(alias, 0) : std::pair{addrEnd, addrEnd};
    std::size_t e = 0;
    std::size_t from = 0;  // datagrams before this have this ESC's IRQ accounted for
    std::uint16_t irq = esc.headerIrq();
    for (;;) {
      const std::size_t next = std::min({e < nEverywhere ? everywhere_[e] : kNone,
                                         s != sEnd ? (*s & 0xFF) : kNone,
                                         a != aEnd ? (*a & 0xFF) : kNone});
      if (next == kNone) break;
      addIrq(irq, from, next);
      esc.processDatagram(datagrams_[next], t + leads[next]);
      irq = esc.headerIrq();
      from = next + 1;
      if (e < nEverywhere && everywhere_[e] == next) ++e;
      if (s != sEnd && (*s & 0xFF) == next) ++s;
      if (a != aEnd && (*a & 0xFF) == next) ++a;
      // A datagram that changed the ESC's address (APWR 0x0010, alias, DL control) decides
      // which of the following ones are its own.
      if (esc.stationAddress() != station || esc.aliasEnabled() != aliasOn ||
          esc.stationAlias() != alias) {
        station = esc.stationAddress();
        aliasOn = esc.aliasEnabled();
        alias = esc.stationAlias();
        std::tie(s, sEnd) = run(station, from);
        std::tie(a, aEnd) =
            aliasOn && alias != station ? run(alias, from) : std::pair{addrEnd, addrEnd};
      }
    }
    addIrq(irq, from, count);
    if (esc.receiveTimeLatchArmed()) latched_.push_back(stop.slave);
  }
  for (std::size_t b = 0; b < irqRuns_.size(); ++b) {
    std::int32_t asking = 0;
    for (std::size_t i = 0; i < count; ++i) {
      asking += irqRuns_[b][i];
      if (asking > 0) datagrams_[i].setIrq(static_cast<std::uint16_t>(datagrams_[i].irq() | (1u << b)));
    }
  }
}

}  // namespace ecsim::topology
