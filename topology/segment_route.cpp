// Segment::passRoute: a frame along the recorded route (no faults, no observers).
#include <algorithm>
#include <bit>

#include "topology/segment.hpp"

namespace ecsim::topology {
namespace {

// FPRD/FPWR/FPRW: one ESC (its station address or enabled alias) acts on it. APRD/APWR/APRW:
// the ESC at the route position the ADP counts to (every ESC increments it, the one seeing 0
// acts). FRMW and ARMW write at every ESC but the addressed one, so they go everywhere like
// broadcast and logical datagrams; NOP and unknown commands only collect the IRQ field.
enum class Reach { kEverywhere, kAddressed, kPosition, kHeaderOnly };

Reach reach(const DatagramView& d) {
  if (!isKnownCommand(d.rawCommand())) return Reach::kHeaderOnly;
  const Command cmd = d.command();
  switch (addressMode(cmd)) {
    case AddressMode::kNone:
      return Reach::kHeaderOnly;
    case AddressMode::kConfigured:
      return cmd == Command::kFrmw ? Reach::kEverywhere : Reach::kAddressed;
    case AddressMode::kAutoIncrement:
      return cmd == Command::kArmw ? Reach::kEverywhere : Reach::kPosition;
    default:
      return Reach::kEverywhere;
  }
}

// How many ESCs ahead of the one processing the frame the next ones' state is asked for.
constexpr std::size_t kPrefetch = 8;

// The route position an auto-increment datagram sent with `adp` acts at.
std::uint32_t positionOf(std::uint16_t adp) {
  return static_cast<std::uint16_t>(0x10000u - adp);
}

}  // namespace

void Segment::passRoute(std::size_t count, const std::array<SimTime, 128>& leads,
                        SimTime sendTime) {
  bool addressedOnly = false;
  bool everywhere = false;
  bool physical = false;      // the frame has a physical (not logical) datagram,
  std::uint32_t address = 0;  // and this is the first one's ADO (fetched ahead below)
  for (std::size_t i = 0; i < count; ++i) {
    const Reach r = reach(datagrams_[i]);
    addressedOnly = addressedOnly || r == Reach::kAddressed;
    everywhere = everywhere || r == Reach::kEverywhere;
    if (!physical && r != Reach::kHeaderOnly && !isLogical(datagrams_[i].command())) {
      physical = true;
      address = datagrams_[i].ado();
    }
  }
  if (physical) lastPhysicalAdo_ = address;
  if (indexedPasses_ && !everywhere && passRouteAddressed(count, leads, sendTime)) return;
  if (addressedOnly) {
    passRouteIndexed(count, leads, sendTime);
    return;
  }
  auto visit = [&](const RouteStop& stop) {
    slavesim::Esc& esc = *escs_[stop.slave];
    esc.beginFrame();
    const SimTime t = sendTime + stop.at;
    for (std::size_t i = 0; i < count; ++i) esc.processDatagram(datagrams_[i], t + leads[i]);
    if (esc.receiveTimeLatchArmed()) latched_.push_back(stop.slave);
  };
  // A long line's ESCs do not stay in the cache between frames: the state of those further
  // down the route is asked for while this one works, in two steps (the per-frame state, then
  // the memory the frame's first physical datagram addresses, found through that state). A
  // short line gains nothing from it.
  const std::size_t stops = route_.size();
  std::size_t k = 0;
  if (stops > 2 * kPrefetch) {
    for (; k + 2 * kPrefetch < stops; ++k) {
      escs_[route_[k + 2 * kPrefetch].slave]->prefetchFrameState();
      if (physical) escs_[route_[k + kPrefetch].slave]->prefetchMemory(address);
      visit(route_[k]);
    }
  }
  for (; k < stops; ++k) visit(route_[k]);
}

void Segment::passRouteIndexed(std::size_t count, const std::array<SimTime, 128>& leads,
                               SimTime sendTime) {
  // byAddress_ holds ADP << 8 | index, sorted: one ADP's datagrams in frame order.
  std::size_t nEverywhere = 0;
  std::size_t nAddressed = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const Reach r = reach(datagrams_[i]);
    if (r == Reach::kEverywhere || r == Reach::kPosition) {
      everywhere_[nEverywhere++] = static_cast<std::uint8_t>(i);  // every ESC counts the ADP
    }
    if (r == Reach::kAddressed) {
      byAddress_[nAddressed++] =
          static_cast<std::uint32_t>(datagrams_[i].adp()) << 8 | static_cast<std::uint32_t>(i);
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
  for (auto& bit : irqRuns_)
    std::fill(bit.begin(), bit.begin() + static_cast<std::ptrdiff_t>(count) + 1, 0);
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
      const std::size_t next =
          std::min({e < nEverywhere ? everywhere_[e] : kNone, s != sEnd ? (*s & 0xFF) : kNone,
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
  applyIrqRuns(count);
}

void Segment::applyIrqRuns(std::size_t count) {
  for (std::size_t b = 0; b < irqRuns_.size(); ++b) {
    std::int32_t asking = 0;
    for (std::size_t i = 0; i < count; ++i) {
      asking += irqRuns_[b][i];
      if (asking > 0)
        datagrams_[i].setIrq(static_cast<std::uint16_t>(datagrams_[i].irq() | (1u << b)));
    }
  }
}

bool Segment::passRouteAddressed(std::size_t count, const std::array<SimTime, 128>& leads,
                                 SimTime sendTime) {
  updateAddressTables();
  const auto stops = static_cast<std::uint32_t>(route_.size());
  visits_.clear();
  bool configured = false;
  for (std::size_t i = 0; i < count; ++i) {
    const DatagramView& d = datagrams_[i];
    const Reach r = reach(d);
    std::uint32_t pos = kOffRoute;
    if (r == Reach::kPosition) {
      adpSent_[i] = d.adp();
      pos = positionOf(d.adp());
    } else if (r == Reach::kAddressed) {
      configured = true;
      if (addrCount_[d.adp()] > 1) return false;  // several ESCs answer it: the indexed pass
      const std::uint32_t owner = ownerOf(d.adp());
      if (owner != 0) pos = owner - 1;
    }
    if (pos < stops) visits_.push_back(pos << 8 | static_cast<std::uint32_t>(i));
  }
  constexpr std::uint32_t kHeaderOnlyVisit = 0xFF;  // sorts after the datagrams of a position
  for (const std::uint32_t slave : irqSet_) {
    if (routePos_[slave] != kOffRoute) visits_.push_back(routePos_[slave] << 8 | kHeaderOnlyVisit);
  }
  std::sort(visits_.begin(), visits_.end());
  for (auto& bit : irqRuns_)
    std::fill(bit.begin(), bit.begin() + static_cast<std::ptrdiff_t>(count) + 1, 0);
  const std::uint64_t epoch = addressingEpoch_;
  std::uint32_t last = kOffRoute;
  std::uint32_t rest = stops;  // from here on every ESC is visited (see below)
  for (const std::uint32_t v : visits_) {
    const std::uint32_t pos = v >> 8;
    if (pos == last) continue;
    last = pos;
    visitAddressed(pos, count, leads, sendTime);
    // A write changed an ESC's addressing: which ESC a later configured-address datagram of
    // this frame concerns is no longer what the tables say, so the rest of the route is
    // visited ESC by ESC (as the indexed pass does).
    if (configured && addressingEpoch_ != epoch) {
      rest = pos + 1;
      break;
    }
  }
  for (std::uint32_t pos = rest; pos < stops; ++pos) visitAddressed(pos, count, leads, sendTime);
  // The ESCs not visited OR what they ask for into every header: the bits set by ESCs on the
  // route, less those of the ESCs visited (theirs went in as each header passed them).
  std::array<std::uint32_t, 16> others = irqCount_;
  auto uncount = [&](std::uint32_t pos) {
    for (unsigned bits = irqKnown_[route_[pos].slave]; bits != 0; bits &= bits - 1) {
      --others[static_cast<std::size_t>(std::countr_zero(bits))];
    }
  };
  last = kOffRoute;
  for (const std::uint32_t v : visits_) {
    const std::uint32_t pos = v >> 8;
    if (pos >= rest) break;
    if (pos != last) uncount(pos);
    last = pos;
  }
  for (std::uint32_t pos = rest; pos < stops; ++pos) uncount(pos);
  std::uint16_t passing = 0;
  for (std::size_t b = 0; b < others.size(); ++b) {
    if (others[b] != 0) passing = static_cast<std::uint16_t>(passing | (1u << b));
  }
  for (std::size_t i = 0; i < count; ++i) {  // every ESC on the route counted the ADP on
    if (reach(datagrams_[i]) == Reach::kPosition) {
      datagrams_[i].setAdp(static_cast<std::uint16_t>(adpSent_[i] + stops));
    }
  }
  applyIrqRuns(count);
  if (passing != 0) {
    for (std::size_t i = 0; i < count; ++i) {
      datagrams_[i].setIrq(static_cast<std::uint16_t>(datagrams_[i].irq() | passing));
    }
  }
  ++framesOwed_;
  ++counters_.framesAddressedPass;
  return true;
}

void Segment::visitAddressed(std::size_t pos, std::size_t count,
                             const std::array<SimTime, 128>& leads, SimTime sendTime) {
  const RouteStop& stop = route_[pos];
  slavesim::Esc& esc = *escs_[stop.slave];
  esc.beginFrameUncounted();
  const SimTime t = sendTime + stop.at;
  std::size_t from = 0;  // datagrams before this have this ESC's IRQ accounted for
  std::uint16_t irq = esc.headerIrq();
  auto addIrq = [&](std::size_t to) {
    if (irq == 0 || from >= to) return;
    for (unsigned bits = irq; bits != 0; bits &= bits - 1) {
      const auto b = static_cast<unsigned>(std::countr_zero(bits));
      ++irqRuns_[b][from];
      --irqRuns_[b][to];
    }
  };
  for (std::size_t i = 0; i < count; ++i) {
    DatagramView& d = datagrams_[i];
    const Reach r = reach(d);
    bool mine = false;
    if (r == Reach::kPosition) {
      mine = positionOf(adpSent_[i]) == pos;
      if (mine) d.setAdp(0);  // the count the ESCs before it made
    } else if (r == Reach::kAddressed) {
      mine =
          d.adp() == esc.stationAddress() || (esc.aliasEnabled() && d.adp() == esc.stationAlias());
    }
    if (!mine) continue;
    addIrq(i);
    esc.processDatagram(d, t + leads[i]);
    irq = esc.headerIrq();
    from = i + 1;
  }
  addIrq(count);
  if (esc.receiveTimeLatchArmed()) latched_.push_back(stop.slave);
}

std::size_t Segment::prefetchForNextFrame(std::size_t first, std::size_t count) const {
  const std::size_t end = std::min(escs_.size(), first + count);
  for (std::size_t i = first; i < end; ++i) escs_[i]->prefetchForNextFrame(lastPhysicalAdo_);
  return end;
}

}  // namespace ecsim::topology
