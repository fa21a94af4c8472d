#include "topology/segment.hpp"

#include <algorithm>
#include <string>

#include "protocol/source_mac.hpp"

namespace ecsim::topology {
namespace {

// Frame processing order (datasheet section I §3.2 Table 10): 0 -> 3 -> 1 -> 2 -> 0.
constexpr std::array<std::uint8_t, kPortCount> kNextPort{3, 2, 0, 1};

// DL control 0x0100 bit 1: the loop setting holds for "about 1 second", then the previous one
// is back (ESC datasheet section II, ESC DL Control).
constexpr SimTime kTemporaryLoopNs = kNsPerSecond;

}  // namespace

std::size_t Segment::addSlave(std::unique_ptr<slavesim::Slave> slave) {
  const auto& type = slave->esc().type();
  slaves_.push_back(std::move(slave));
  links_.push_back({});
  cableNs_.push_back({});
  linkUp_.push_back({true, true, true, true});
  delays_.push_back({type.processingDelayNs, type.forwardingDelayNs});
  parent_.push_back(static_cast<int>(slaves_.size() - 1));
  arrival_.push_back({});
  arrivalMask_.push_back(0);
  openMask_.push_back(0);
  lostMask_.push_back(0);
  loopPermanent_.push_back(0);
  loopRevertAt_.push_back(kNoRevert);
  observers_.push_back({});
  stack_.reserve(slaves_.size() + 1);
  escs_.push_back(&slaves_.back()->esc());
  routeArrival_.push_back({});
  routeValid_ = false;
  latched_.reserve(slaves_.size());
  indexNewSlave(slaves_.size() - 1);
  refreshLinkStatus(slaves_.size() - 1);  // only its own status: it has no links yet
  return slaves_.size() - 1;
}

int Segment::findRoot(int i) {
  // Path halving keeps the tree check near constant time per link whatever the wiring order.
  while (parent_[static_cast<std::size_t>(i)] != i) {
    auto& up = parent_[static_cast<std::size_t>(i)];
    up = parent_[static_cast<std::size_t>(up)];
    i = up;
  }
  return i;
}

Status Segment::connect(std::size_t a, unsigned pa, std::size_t b, unsigned pb, double metres) {
  if (a >= slaves_.size() || b >= slaves_.size() || pa >= kPortCount || pb >= kPortCount) {
    return makeError(ErrorCode::kInvalidArgument, "connect: slave or port out of range");
  }
  if (pa >= slaves_[a]->esc().type().maxPorts || pb >= slaves_[b]->esc().type().maxPorts) {
    return makeError(ErrorCode::kInvalidArgument,
                     "connect: " + slaves_[a]->name() + " port " + std::to_string(pa) + " or " +
                         slaves_[b]->name() + " port " + std::to_string(pb) +
                         " does not exist on its ESC");
  }
  if (links_[a][pa].slave != kNoSlave || links_[b][pb].slave != kNoSlave) {
    return makeError(ErrorCode::kInvalidArgument, "connect: port already connected");
  }
  int ra = findRoot(static_cast<int>(a));
  int rb = findRoot(static_cast<int>(b));
  if (ra == rb) {
    return makeError(ErrorCode::kInvalidArgument,
                     "connect: " + slaves_[a]->name() + " and " + slaves_[b]->name() +
                         " are already connected (the topology must be a tree)");
  }
  parent_[static_cast<std::size_t>(rb)] = ra;
  links_[a][pa] = {static_cast<int>(b), static_cast<std::uint8_t>(pb), metres};
  links_[b][pb] = {static_cast<int>(a), static_cast<std::uint8_t>(pa), metres};
  cableNs_[a][pa] = cableNs_[b][pb] = cableDelay(metres);
  routeValid_ = false;
  // Only the two ends' link and loop bits change: refreshing them alone keeps building a
  // network linear in its size (all slaves per link took 77 s for 20,000 slaves).
  refreshLinkStatus(a);
  refreshLinkStatus(b);
  return okStatus();
}

Status Segment::setRedundantPort(std::size_t slave, unsigned port, double metres, bool linked) {
  if (slave >= slaves_.size() || port >= slaves_[slave]->esc().type().maxPorts) {
    return makeError(ErrorCode::kInvalidArgument,
                     "redundant port: slave or port out of range (or not on its ESC)");
  }
  if ((slave == 0 && port == 0) || links_[slave][port].slave != kNoSlave) {
    return makeError(ErrorCode::kInvalidArgument, "redundant port: " + slaves_[slave]->name() +
                                                      " port " + std::to_string(port) +
                                                      " is already connected");
  }
  redSlave_ = static_cast<int>(slave);
  redPort_ = static_cast<std::uint8_t>(port);
  redCable_ = metres;
  linkUp_[slave][port] = linked;
  routeValid_ = false;
  refreshLinkStatus(slave);
  return okStatus();
}

void Segment::wireLine(double metres) {
  for (std::size_t i = 1; i < slaves_.size(); ++i) {
    (void)connect(i - 1, 1, i, 0, metres);
  }
}

void Segment::updateCableDelays() {
  routeValid_ = false;
  for (std::size_t i = 0; i < slaves_.size(); ++i) {
    for (unsigned p = 0; p < kPortCount; ++p) cableNs_[i][p] = cableDelay(links_[i][p].cableMetres);
  }
}

void Segment::setCableObserver(std::size_t slave, unsigned port, CableObserver* observer) {
  if (slave >= slaves_.size() || port >= kPortCount) return;
  observers_[slave][port] = observer;
  anyObserver_ = false;
  for (const auto& ports : observers_) {
    for (auto* o : ports) anyObserver_ |= o != nullptr;
  }
}

void Segment::setDelays(std::size_t slave, SimTime processing, SimTime forwarding) {
  delays_[slave] = {processing, forwarding};
  routeValid_ = false;
}

bool Segment::portLink(std::size_t s, unsigned p) const {
  if (masterEnd(s, p)) return linkUp_[s][p];  // a cable to the master
  const PortLink& l = links_[s][p];
  return l.slave != kNoSlave && linkUp_[s][p] && linkUp_[static_cast<std::size_t>(l.slave)][l.port];
}

bool Segment::portOpen(std::size_t s, unsigned p) const {
  // Loop control 0x0101 (section I §3.1): auto (and auto close, modelled as auto) follow the
  // link; "open" is open whatever the link (frames sent into no link are lost), "closed" is
  // closed whatever the link (frames arriving there are not received). A port the ESC does
  // not have is closed.
  const auto& esc = slaves_[s]->esc();
  if (p >= esc.type().maxPorts) return false;
  const std::uint8_t loop =
      reg::dl_control::loopSetting(static_cast<std::uint8_t>(esc.read(reg::kDlControl) >> 8), p);
  if (loop == reg::dl_control::kLoopClosed) return false;
  return loop == reg::dl_control::kLoopOpen || portLink(s, p);
}

void Segment::setLinkUp(std::size_t s, unsigned p, bool up) {
  if (s >= slaves_.size() || p >= kPortCount) return;
  if (linkUp_[s][p] && !up) slaves_[s]->esc().countLostLink(p);
  linkUp_[s][p] = up;
  routeValid_ = false;
  refreshLinkStatus(s);  // this port and its peer's: the link needs both ends up
  if (links_[s][p].slave != kNoSlave) {
    refreshLinkStatus(static_cast<std::size_t>(links_[s][p].slave));
  }
}

void Segment::refreshLinkStatus() {
  for (std::size_t s = 0; s < slaves_.size(); ++s) refreshLinkStatus(s);
}

void Segment::refreshLinkStatus(std::size_t s) {
  routeValid_ = false;  // port states may have changed
  auto& esc = slaves_[s]->esc();
  std::uint8_t open = 0;
  for (unsigned p = 0; p < kPortCount; ++p) {
    if (portOpen(s, p)) open = static_cast<std::uint8_t>(open | (1u << p));
  }
  // Port 0 is open when every other port is closed, whatever its own setting (section I §3.7).
  const std::uint8_t all = static_cast<std::uint8_t>((1u << esc.type().maxPorts) - 1);
  if ((open & all & ~1u) == 0 && portLink(s, 0)) open = static_cast<std::uint8_t>(open | 1u);
  const auto before = esc.read(reg::kDlStatus);
  auto dl = static_cast<std::uint16_t>(before & 0x000F);
  std::uint8_t lost = 0;
  for (unsigned p = 0; p < kPortCount; ++p) {
    const bool link = portLink(s, p);
    const bool isOpen = (open & (1u << p)) != 0;
    if (link) dl |= reg::dl_status::physicalLink(p);
    if (!isOpen) dl |= reg::dl_status::loopPort(p);
    if (isOpen && link) dl |= reg::dl_status::communication(p);
    if (isOpen && !link) lost = static_cast<std::uint8_t>(lost | (1u << p));
  }
  esc.pdiWrite(reg::kDlStatus, dl);
  if (dl != before) esc.dlStatusChanged();  // ECAT event 0x0210 bit 2
  openMask_[s] = open;
  lostMask_[s] = lost;
}

void Segment::noteDlControlWrite(std::size_t s, SimTime now) {
  const auto dl = slaves_[s]->esc().read(reg::kDlControl);
  if ((dl & reg::dl_control::kTemporaryLoop) == 0) {
    loopPermanent_[s] = static_cast<std::uint8_t>(dl >> 8);
    loopRevertAt_[s] = kNoRevert;
    return;
  }
  loopRevertAt_[s] = now + kTemporaryLoopNs;
  nextLoopRevert_ = std::min(nextLoopRevert_, loopRevertAt_[s]);
}

void Segment::revertTemporaryLoops(SimTime now) {
  nextLoopRevert_ = kNoRevert;
  for (std::size_t s = 0; s < slaves_.size(); ++s) {
    if (loopRevertAt_[s] == kNoRevert) continue;
    if (now < loopRevertAt_[s]) {
      nextLoopRevert_ = std::min(nextLoopRevert_, loopRevertAt_[s]);
      continue;
    }
    auto& esc = slaves_[s]->esc();
    const auto dl = esc.read(reg::kDlControl);
    esc.pdiWrite(reg::kDlControl,
                 (dl & ~0x0000FF00u) | (static_cast<std::uint32_t>(loopPermanent_[s]) << 8));
    loopRevertAt_[s] = kNoRevert;
    refreshLinkStatus(s);
  }
}

FrameOutcome Segment::processFrame(Bytes frame, SimTime sendTime, MasterPort from) {
  FrameOutcome outcome;
  outcome.exit = from;
  if (sendTime >= nextLoopRevert_) revertTemporaryLoops(sendTime);
  auto parsed = EtherCatFrame::parse(frame);
  const bool secondary = from == MasterPort::kSecondary;
  // Where the frame enters: slave 0's port 0, or the port wired to the master's second port.
  const std::uint32_t s0 = secondary ? static_cast<std::uint32_t>(redSlave_) : 0;
  const std::uint8_t p0 = secondary ? redPort_ : 0;
  // Nothing is received without the master's link or with the port it arrives at closed.
  if (!parsed.ok() || slaves_.empty() || (secondary && redSlave_ == kNoSlave) || !linkUp_[s0][p0] ||
      (openMask_[s0] & (1u << p0)) == 0) {
    if (!parsed.ok()) ++counters_.framesMalformed;
    return outcome;
  }
  // Each ESC processes a datagram when its first byte passes: preamble and SFD (8 bytes), then
  // the datagram's offset in the frame, after the frame's first bit arrived.
  const SimTime nsPerByte = timing_.nsPerByte;
  std::size_t count = 0;
  std::array<SimTime, 128> leads;
  for (auto it = parsed->begin(); it != parsed->end() && count < datagrams_.size(); ++it) {
    datagrams_[count] = *it;
    leads[count] = static_cast<SimTime>(8 + parsed->datagramsOffset() + it.offset()) * nsPerByte;
    ++count;
  }
  if (count == datagrams_.size()) {  // more datagrams than an EtherCAT frame can hold
    ++counters_.framesMalformed;
    return outcome;
  }
  ++counters_.framesProcessed;
  counters_.datagramsProcessed += count;
  frame[kSourceMacOffset] |= kLocallyAdministeredBit;  // as every ESC does

  latched_.clear();
  const SimTime frameTime =
      static_cast<SimTime>(8 + std::max<std::size_t>(frame.size(), kMinFrameSize) + 4) * nsPerByte;
  // With a second master port the way depends on where the frame enters and on breaks in the
  // ring: every frame walks (rings are short next to the lines the recorded route is for).
  if (routeValid_ && faults_ == nullptr && !anyObserver_ && !redundant()) {
    // The wiring, port states and delays have not changed since the route was recorded: the
    // frame reaches the same ESCs in the same order at the same times relative to sendTime.
    passRoute(count, leads, sendTime);
    for (const std::uint32_t i : latched_) {
      std::array<SimTime, kPortCount> at = routeArrival_[i];
      for (auto& a : at) a += sendTime;
      escs_[i]->completeReceiveTimeLatch(at, routeMask_[i]);
    }
    outcome.firstBitRoundTrip = routeRoundTrip_;
    outcome.delivered = true;
    outcome.returnTime = sendTime + outcome.firstBitRoundTrip + frameTime;
    return outcome;
  }
  // The walk, recording the route for the frames that follow (not with faults: they may delay).
  // A walk with faults keeps the recorded route: clearing it while routeValid_ stays set made
  // the next fault-free frame reach no ESC at all (WKC 0).
  const bool record = faults_ == nullptr && !redundant();
  if (record) {
    routeChanging();
    route_.clear();
  }
  stack_.clear();
  for (auto& m : arrivalMask_) m = 0;
  std::uint32_t s = s0;
  std::uint8_t k = p0;
  notify(s0, p0, frame, sendTime, true);
  const double entryCable = secondary ? redCable_ : masterCable_;
  SimTime t = sendTime + cableDelay(entryCable);
  // Corrupted on the way (fault injection): counted, lost for the master, and processed by
  // the ESCs behind the fault as an invalid frame (Esc::beginFrame).
  bool bad = false;
  bool lost = false;  // lost at a port by its loop setting (never returns to the master)
  if (faults_ != nullptr) arriveWithFaults(s0, p0, t, bad);
  stack_.push_back({s0, p0, p0});
  arrival_[s0][p0] = t;
  arrivalMask_[s0] = static_cast<std::uint8_t>(1u << p0);
  // A passage through an ESC costs its processing delay when it went through the processing
  // unit (entered at port 0) and its forwarding delay otherwise; looping back through a closed
  // port inside the ESC adds nothing (section I §9.1.2, Table 30).
  bool viaEpu = false;
  while (true) {
    if (k == 0) {
      slavesim::Esc& esc = *escs_[s];
      esc.beginFrame(bad);
      if (record) route_.push_back({s, t - sendTime});
      for (std::size_t i = 0; i < count; ++i) {
        esc.processDatagram(datagrams_[i], t + leads[i]);
      }
      // Only a datagram of this frame can arm the latch; it completes once the frame is through.
      if (esc.receiveTimeLatchArmed()) latched_.push_back(s);
      viaEpu = true;
    }
    const std::uint8_t out = kNextPort[k];
    Visit& top = stack_.back();
    const bool upstream = out == top.entryPort;
    if (!upstream && (openMask_[s] & (1u << out)) == 0) {
      k = out;  // closed or unconnected: the ESC loops the frame back internally
      continue;
    }
    const SimTime tOut = t + delays_[s][viaEpu ? 0 : 1];
    viaEpu = false;
    if (!upstream && (lostMask_[s] & (1u << out)) != 0) {
      lost = true;  // forced open without a link: the frame goes nowhere (section I §3.1)
      break;
    }
    if (upstream) {
      const std::uint8_t entry = top.entryPort;
      stack_.pop_back();
      if (stack_.empty()) {  // back out of the port it came in at
        notify(s0, p0, frame, tOut, false);
        outcome.firstBitRoundTrip = tOut + cableDelay(entryCable) - sendTime;
        break;
      }
      Visit& parent = stack_.back();
      notify(s, entry, frame, tOut, false);
      notify(parent.slave, parent.port, frame, tOut, false);
      s = parent.slave;
      k = parent.port;
      t = tOut + cableNs_[s][k];  // the cable just crossed (both ends hold its delay)
    } else if (masterEnd(s, out)) {
      // Out to the master's other port: the frame went round the ring (entering at slave 0's
      // port 0 it leaves at the redundant port, and the other way round).
      notify(s, out, frame, tOut, false);
      outcome.exit = secondary ? MasterPort::kPrimary : MasterPort::kSecondary;
      outcome.firstBitRoundTrip =
          tOut + cableDelay(secondary ? masterCable_ : redCable_) - sendTime;
      break;
    } else {
      const PortLink& l = links_[s][out];
      notify(s, out, frame, tOut, true);
      notify(static_cast<std::size_t>(l.slave), l.port, frame, tOut, true);
      top.port = out;
      stack_.push_back({static_cast<std::uint32_t>(l.slave), l.port, l.port});
      s = static_cast<std::uint32_t>(l.slave);
      k = l.port;
      t = tOut + cableNs_[s][k];  // the cable just crossed (both ends hold its delay)
    }
    if (faults_ != nullptr) arriveWithFaults(s, k, t, bad);
    if ((openMask_[s] & (1u << k)) == 0) {
      lost = true;  // arrived at a closed port: not received (section I §3.1, loop "closed")
      break;
    }
    arrival_[s][k] = t;
    arrivalMask_[s] = static_cast<std::uint8_t>(arrivalMask_[s] | (1u << k));
  }
  for (const std::uint32_t i : latched_) {
    escs_[i]->completeReceiveTimeLatch(arrival_[i], arrivalMask_[i]);
  }
  if (record && !lost) {
    for (std::size_t i = 0; i < slaves_.size(); ++i) {
      for (unsigned p = 0; p < kPortCount; ++p) routeArrival_[i][p] = arrival_[i][p] - sendTime;
    }
    routeMask_ = arrivalMask_;
    routeRoundTrip_ = outcome.firstBitRoundTrip;
    routeValid_ = true;
    routeRecorded();
  }
  // The master has the frame when its last bit is in: wire footprint of the frame itself
  // (preamble + SFD + frame + FCS).
  outcome.delivered = !bad && !lost;
  outcome.returnTime = sendTime + outcome.firstBitRoundTrip + frameTime;
  return outcome;
}

bool Segment::arriveWithFaults(std::size_t s, unsigned port, SimTime& t, bool& bad) {
  t = saturatingAdd(t, std::clamp<SimTime>(faults_->extraDelay(s, port, t), 0, kMaxWireExtraDelay));
  auto& esc = slaves_[s]->esc();
  if (bad) {
    // An ESC forwarding a frame with a bad FCS marks it; the next ESCs count a forwarded
    // error rather than an invalid frame (ESC datasheet section I §7.2, 0x0308-0x030B).
    esc.countForwardedRxError(port);
  } else if (faults_->corrupts(s, port, t)) {
    esc.countRxError(port, true);
    bad = true;
  }
  return !bad;
}

}  // namespace ecsim::topology
