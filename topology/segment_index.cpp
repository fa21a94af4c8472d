// Segment's indexes (segment.hpp): the station addresses of the ESCs on the recorded route, the
// ESCs asking for IRQ bits, the frames owed to the ESCs a pass did not visit, and the slaves
// whose firmware has work. The slaves' ESCs keep them current through FirmwarePoller.
#include <algorithm>
#include <bit>

#include "topology/segment.hpp"

namespace ecsim::topology {
namespace {

constexpr std::size_t kAddresses = 0x10000;  // configured station addresses and aliases

}  // namespace

Segment::~Segment() {
  for (auto& slave : slaves_) slave->setPoller(nullptr, 0);
}

void Segment::indexNewSlave(std::size_t i) {
  const std::size_t n = slaves_.size();
  routePos_.push_back(kOffRoute);
  answering_.push_back({});
  addressingQueued_.push_back(0);
  irqSlot_.push_back(0);
  irqKnown_.push_back(0);
  eventQueued_.push_back(0);
  // Everything a poll or pass fills later is reserved now: no allocation while frames pass.
  addressingQueue_.reserve(n);
  irqSet_.reserve(n);
  visits_.reserve(n + 128);
  eventful_.reserve(n);
  polling_.reserve(n);
  firmwareSlaves_.reserve(n);
  firmwareDirty_ = true;
  slaves_[i]->setPoller(this, static_cast<std::uint32_t>(i));
}

std::uint64_t Segment::framesSeen(std::size_t i) const {
  const std::uint64_t own = slaves_[i]->esc().counters().framesSeen;
  return routePos_[i] == kOffRoute ? own : own + framesOwed_;
}

void Segment::escEventsRaised(std::uint32_t id) {
  if (eventQueued_[id] != 0) return;
  eventQueued_[id] = 1;
  eventful_.push_back(id);
}

void Segment::escAddressingChanged(std::uint32_t id) {
  ++addressingEpoch_;
  if (addressingQueued_[id] != 0) return;
  addressingQueued_[id] = 1;
  addressingQueue_.push_back(id);
}

void Segment::countIrq(std::uint16_t irq, int delta) {
  for (unsigned bits = irq; bits != 0; bits &= bits - 1) {
    irqCount_[static_cast<std::size_t>(std::countr_zero(bits))] +=
        static_cast<std::uint32_t>(delta);
  }
}

void Segment::escIrqChanged(std::uint32_t id, std::uint16_t irq, bool followsSm) {
  if (routePos_[id] != kOffRoute) {
    countIrq(irqKnown_[id], -1);
    countIrq(irq, +1);
  }
  irqKnown_[id] = irq;
  if (followsSm == (irqSlot_[id] != 0)) return;
  if (followsSm) {
    irqSet_.push_back(id);
    irqSlot_[id] = static_cast<std::uint32_t>(irqSet_.size());
    return;
  }
  const std::uint32_t slot = irqSlot_[id] - 1;
  const std::uint32_t last = irqSet_.back();
  irqSet_[slot] = last;
  irqSlot_[last] = slot + 1;
  irqSet_.pop_back();
  irqSlot_[id] = 0;
}

void Segment::routeChanging() {
  if (framesOwed_ != 0) {
    for (const RouteStop& stop : route_) escs_[stop.slave]->addFramesSeen(framesOwed_);
    framesOwed_ = 0;
  }
  for (const RouteStop& stop : route_) routePos_[stop.slave] = kOffRoute;
  irqCount_ = {};
  tablesValid_ = false;
}

void Segment::routeRecorded() {
  for (std::size_t k = 0; k < route_.size(); ++k) {
    routePos_[route_[k].slave] = static_cast<std::uint32_t>(k);
    countIrq(irqKnown_[route_[k].slave], +1);
  }
  tablesValid_ = false;
}

void Segment::tableAdd(std::uint32_t slave) {
  Answering& a = answering_[slave];
  const slavesim::Esc& esc = *escs_[slave];
  a = {esc.stationAddress(), esc.stationAlias(), esc.aliasEnabled(), false};
  const std::uint32_t pos = routePos_[slave];
  if (pos == kOffRoute) return;
  a.listed = true;
  auto add = [&](std::uint16_t address) {
    addrOwner_[address] = addrCount_[address]++ == 0 ? pos + 1 : 0;
  };
  add(a.station);
  if (a.aliasOn && a.alias != a.station) add(a.alias);
}

void Segment::tableRemove(std::uint32_t slave) {
  Answering& a = answering_[slave];
  if (!a.listed) return;
  a.listed = false;
  // With one ESC left answering, which one it is is found again when asked (ownerOf).
  auto remove = [&](std::uint16_t address) {
    --addrCount_[address];
    addrOwner_[address] = 0;
  };
  remove(a.station);
  if (a.aliasOn && a.alias != a.station) remove(a.alias);
}

void Segment::updateAddressTables() {
  if (!tablesValid_) {
    addrCount_.assign(kAddresses, 0);
    addrOwner_.assign(kAddresses, 0);
    for (auto& a : answering_) a.listed = false;
    for (const RouteStop& stop : route_) tableAdd(stop.slave);
    for (const std::uint32_t id : addressingQueue_) addressingQueued_[id] = 0;
    addressingQueue_.clear();
    tablesValid_ = true;
    return;
  }
  for (const std::uint32_t id : addressingQueue_) {
    addressingQueued_[id] = 0;
    tableRemove(id);
    tableAdd(id);
  }
  addressingQueue_.clear();
}

std::uint32_t Segment::ownerOf(std::uint16_t address) {
  if (addrCount_[address] != 1) return 0;
  if (addrOwner_[address] != 0) return addrOwner_[address];
  for (std::size_t k = 0; k < route_.size(); ++k) {  // rare: after a duplicate went away
    const slavesim::Esc& esc = *escs_[route_[k].slave];
    if (esc.stationAddress() == address || (esc.aliasEnabled() && esc.stationAlias() == address)) {
      addrOwner_[address] = static_cast<std::uint32_t>(k + 1);
      break;
    }
  }
  return addrOwner_[address];
}

void Segment::pollSlaves(SimTime now) {
  if (now >= nextLoopRevert_) revertTemporaryLoops(now);
  if (firmwareDirty_) {
    firmwareSlaves_.clear();
    for (std::size_t i = 0; i < slaves_.size(); ++i) {
      if (slaves_[i]->hasFirmware()) firmwareSlaves_.push_back(static_cast<std::uint32_t>(i));
    }
    firmwareDirty_ = false;
  }
  // The slaves with firmware and those whose ESC raised events, in index order (as a loop
  // over all slaves polled them); events raised meanwhile wait for the next poll.
  polling_.swap(eventful_);
  std::sort(polling_.begin(), polling_.end());
  for (const std::uint32_t id : polling_) eventQueued_[id] = 0;
  bool dlChanged = false;
  auto poll = [&](std::size_t i) {
    auto& slave = *slaves_[i];
    if (slave.esc().hasEvents() && slave.esc().peekEvents().dlControlWritten) {
      dlChanged = true;
      noteDlControlWrite(i, now);
    }
    if (slave.esc().hasEvents() || slave.hasFirmware()) slave.poll(now);
  };
  auto f = firmwareSlaves_.begin();
  auto e = polling_.begin();
  while (f != firmwareSlaves_.end() || e != polling_.end()) {
    std::uint32_t next;
    if (e == polling_.end() || (f != firmwareSlaves_.end() && *f <= *e)) {
      next = *f++;
      if (e != polling_.end() && *e == next) ++e;
    } else {
      next = *e++;
    }
    poll(next);
  }
  polling_.clear();
  if (dlChanged) refreshLinkStatus();
}

}  // namespace ecsim::topology
