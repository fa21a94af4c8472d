#include "master/transport.hpp"

#include <algorithm>
#include <cstring>

#include "protocol/registers.hpp"
#include "protocol/source_mac.hpp"

namespace ecsim::master {
namespace {

constexpr std::size_t kIndexByte = 1;  // offset of the index within a datagram header
constexpr std::size_t kMaxReceivesPerPoll = 1024;

// Where the index of the first datagram lies in an untagged frame.
constexpr std::size_t kFirstIndexAt = kEthernetHeaderSize + kEtherCatHeaderSize + kIndexByte;

// The source address as sent: ESCs set the locally administered bit of the first byte of
// every frame they pass, so that bit is not compared.
bool sameSource(ConstBytes frame, const MacAddress& source) {
  if (frame.size() < kSourceMacOffset + source.size()) return false;
  for (std::size_t i = 0; i < source.size(); ++i) {
    const std::uint8_t mask = i == 0 ? static_cast<std::uint8_t>(~kLocallyAdministeredBit) : 0xFF;
    if ((frame[kSourceMacOffset + i] & mask) != (source[i] & mask)) return false;
  }
  return true;
}

}  // namespace

std::string_view toString(RingState state) {
  switch (state) {
    case RingState::kNone:
      return "none";
    case RingState::kWhole:
      return "whole";
    case RingState::kBroken:
      return "broken";
  }
  return "?";
}

// ---- CachedFrame ------------------------------------------------------------------------------

CachedFrame::~CachedFrame() {
  if (owner_ != nullptr) owner_->detachCached(*this);
}

Status CachedFrame::commit(std::size_t length) {
  if (state_ == DatagramState::kSent) {
    return makeError(ErrorCode::kState, "cached frame: cannot rebuild while in flight");
  }
  if (length > tx_.size()) {
    return makeError(ErrorCode::kTooLarge, "cached frame: length " + std::to_string(length) +
                                               " exceeds " + std::to_string(tx_.size()));
  }
  auto frame = EtherCatFrame::parse(Bytes(tx_.data(), length));
  if (!frame.ok()) return frame.takeError();
  datagramOffsets_.clear();
  for (auto it = frame->begin(); it != frame->end(); ++it) {
    datagramOffsets_.push_back(frame->datagramsOffset() + it.offset());
  }
  length_ = length;
  state_ = DatagramState::kIdle;
  return okStatus();
}

std::uint16_t CachedFrame::rxWkc(std::size_t k) const {
  const std::size_t at = datagramOffsets_[k];
  const std::size_t len = readLe16(rx_, at + 6) & kMaxDatagramLength;
  return readLe16(rx_, at + kDatagramHeaderSize + len);
}

ConstBytes CachedFrame::rxData(std::size_t k) const {
  const std::size_t at = datagramOffsets_[k];
  const std::size_t len = readLe16(rx_, at + 6) & kMaxDatagramLength;
  return ConstBytes(rx_.data() + at + kDatagramHeaderSize, len);
}

// ---- Transport --------------------------------------------------------------------------------

Transport::Transport(Link& link, TransportOptions options)
    : link_(link),
      options_(options),
      slots_(std::clamp<std::size_t>(options.maxFramesInFlight, 1, kMaxFramesInFlight)) {
  ethernet_.destination = kBroadcastMac;
  ethernet_.source = options_.source;
  ethernet_.etherType = kEtherTypeEtherCat;
  indexSlot_.fill(-1);
}

Transport::~Transport() {
  // Detach everything that still points at us.
  for (Datagram* d = queueHead_; d != nullptr;) {
    Datagram* next = d->next_;
    d->owner_ = nullptr;
    d->prev_ = nullptr;
    d->next_ = nullptr;
    d->state_ = DatagramState::kIdle;
    d = next;
  }
  for (auto& slot : slots_) {
    if (!slot.busy) continue;
    for (std::size_t i = 0; i < slot.datagramCount; ++i) {
      if (Datagram* d = slot.datagrams[i]) {
        d->owner_ = nullptr;
        d->state_ = DatagramState::kIdle;
      }
    }
    if (slot.cached != nullptr) {
      slot.cached->owner_ = nullptr;
      slot.cached->state_ = DatagramState::kIdle;
    }
  }
}

void Transport::queue(Datagram& datagram) {
  if (datagram.owner_ != nullptr) datagram.owner_->cancel(datagram);
  datagram.owner_ = this;
  datagram.prev_ = queueTail_;
  datagram.next_ = nullptr;
  datagram.state_ = DatagramState::kQueued;
  datagram.wkc_ = 0;
  if (queueTail_ == nullptr) {
    queueHead_ = queueTail_ = &datagram;
  } else {
    queueTail_->next_ = &datagram;
    queueTail_ = &datagram;
  }
}

void Transport::unlinkQueued(Datagram& datagram) {
  (datagram.prev_ == nullptr ? queueHead_ : datagram.prev_->next_) = datagram.next_;
  (datagram.next_ == nullptr ? queueTail_ : datagram.next_->prev_) = datagram.prev_;
  datagram.prev_ = nullptr;
  datagram.next_ = nullptr;
}

void Transport::cancel(Datagram& datagram) {
  if (datagram.owner_ != this) return;
  if (datagram.state_ == DatagramState::kQueued) {
    unlinkQueued(datagram);
  } else if (datagram.state_ == DatagramState::kSent) {
    for (auto& slot : slots_) {
      if (!slot.busy) continue;
      for (std::size_t i = 0; i < slot.datagramCount; ++i) {
        if (slot.datagrams[i] == &datagram) slot.datagrams[i] = nullptr;
      }
    }
  }
  datagram.owner_ = nullptr;
  datagram.state_ = DatagramState::kIdle;
}

void Transport::detachCached(CachedFrame& frame) {
  for (auto& slot : slots_) {
    if (slot.busy && slot.cached == &frame) {
      indexState_[slot.index] = IndexState::kClosed;
      indexSlot_[slot.index] = -1;
      slot.busy = false;
      slot.cached = nullptr;
      --inFlight_;
    }
  }
  frame.owner_ = nullptr;
  frame.state_ = DatagramState::kIdle;
}

void Transport::allowFramesInFlight(std::size_t frames) {
  frames = std::min<std::size_t>(frames, kMaxFramesInFlight);
  if (frames <= slots_.size()) return;
  slots_.resize(frames);  // slots are found by position (indexSlot_), never by address
  options_.maxFramesInFlight = frames;
}

std::optional<std::uint8_t> Transport::takeIndex() {
  for (int tries = 0; tries < 256; ++tries) {
    const std::uint8_t index = nextIndex_++;
    if (indexState_[index] != IndexState::kInFlight) return index;
  }
  return std::nullopt;
}

Transport::Slot* Transport::freeSlot() {
  for (auto& slot : slots_) {
    if (!slot.busy) return &slot;
  }
  return nullptr;
}

ConstBytes Transport::slotTx(const Slot& slot) const {
  if (slot.cached != nullptr) return slot.cached->tx();
  return ConstBytes(slot.buffer.data(), slot.length);
}

Status Transport::send(CachedFrame& frame, SimTime now) {
  if (frame.length_ == 0) return makeError(ErrorCode::kState, "cached frame not built");
  if (frame.state_ == DatagramState::kSent) {
    return makeError(ErrorCode::kState, "cached frame still in flight");
  }
  Slot* slot = freeSlot();
  auto index = takeIndex();
  if (slot == nullptr || !index) {
    return makeError(ErrorCode::kTooLarge,
                     "no frame slot free (" + std::to_string(slots_.size()) + " in flight)");
  }
  for (std::size_t offset : frame.datagramOffsets_) frame.tx_[offset + kIndexByte] = *index;
  slot->busy = true;
  slot->index = *index;
  slot->cached = &frame;
  slot->datagramCount = 0;
  slot->length = frame.length_;
  slot->triesLeft = 0;
  slot->deadline = now + options_.timeout;
  ++inFlight_;
  indexState_[*index] = IndexState::kInFlight;
  indexSlot_[*index] = static_cast<std::int16_t>(slot - slots_.data());
  frame.owner_ = this;
  frame.state_ = DatagramState::kSent;
  frame.sentAt_ = now;
  ++counters_.framesSent;
  counters_.datagramsSent += frame.datagramOffsets_.size();
  transmit(frame.tx(), *index);
  return okStatus();
}

void Transport::setRedundantLink(Link* link) {
  redundant_ = link;
  if (link == nullptr) return;
  EthernetHeader ethernet = ethernet_;
  ethernet.source = options_.secondarySource;
  FrameBuilder builder(Bytes(brd_.data(), brd_.size()), ethernet);
  (void)builder.add(Command::kBrd, 0, DatagramHeader::physical(0, reg::kType.address),
                    reg::kType.width);
  brdLength_ = builder.finish().valueOr(0);
}

void Transport::transmit(ConstBytes frame, std::uint8_t index) {
  if (auto sent = link_.send(frame); !sent.ok()) ++counters_.sendErrors;
  if (redundant_ == nullptr || brdLength_ == 0) return;
  brd_[kFirstIndexAt] = index;
  if (auto sent = redundant_->send(ConstBytes(brd_.data(), brdLength_)); !sent.ok()) {
    ++counters_.sendErrors;
  }
}

void Transport::abandon(CachedFrame& frame) {
  if (frame.owner_ != this || frame.state_ != DatagramState::kSent) return;
  for (auto& slot : slots_) {
    if (slot.busy && slot.cached == &frame) {
      ++counters_.framesLost;
      release(slot, DatagramState::kTimedOut);
      return;
    }
  }
}

void Transport::release(Slot& slot, DatagramState datagramState) {
  for (std::size_t i = 0; i < slot.datagramCount; ++i) {
    if (Datagram* d = slot.datagrams[i]) {
      d->state_ = datagramState;
      d->owner_ = nullptr;
      if (datagramState == DatagramState::kTimedOut) ++counters_.datagramsTimedOut;
    }
    slot.datagrams[i] = nullptr;
  }
  if (slot.cached != nullptr) {
    slot.cached->state_ = datagramState;
    slot.cached->owner_ = nullptr;
    if (datagramState == DatagramState::kTimedOut) {
      counters_.datagramsTimedOut += slot.cached->datagramOffsets_.size();
    }
    slot.cached = nullptr;
  }
  slot.datagramCount = 0;
  slot.passedOn = false;
  slot.brdAtSecondary = false;
  indexState_[slot.index] =
      datagramState == DatagramState::kTimedOut ? IndexState::kGivenUp : IndexState::kClosed;
  indexSlot_[slot.index] = -1;
  slot.busy = false;
  --inFlight_;
}

std::optional<SimTime> Transport::nextDeadline() const {
  std::optional<SimTime> earliest;
  for (const auto& slot : slots_) {
    if (slot.busy && (!earliest || slot.deadline < *earliest)) earliest = slot.deadline;
  }
  return earliest;
}

void Transport::poll(SimTime now) {
  receiveAll(now);
  checkTimeouts(now);
  sendQueued(now);
}

void Transport::receiveAll(SimTime now) {
  receiveFrom(link_, Port::kPrimary, now);
  if (redundant_ != nullptr) receiveFrom(*redundant_, Port::kSecondary, now);
}

void Transport::receiveFrom(Link& link, Port port, SimTime now) {
  for (std::size_t n = 0; n < kMaxReceivesPerPoll; ++n) {
    auto received = link.receive(rx_, std::chrono::nanoseconds(0));
    if (!received.ok()) {
      ++counters_.receiveErrors;
      continue;
    }
    if (*received == 0) return;
    ++counters_.framesReceived;
    if (port == Port::kSecondary) secondaryDelivers_ = true;
    handleFrame(*received, now, port);
  }
}

bool Transport::takeSecondaryBrd(std::size_t length, Port port, SimTime now) {
  const ConstBytes frame(rx_.data(), length);
  if (!sameSource(frame, options_.secondarySource)) return false;
  auto parsed = ConstEtherCatFrame::parse(frame);
  if (!parsed.ok() || parsed->datagramCount() != 1) return true;
  const auto brd = *parsed->begin();
  slavesBehindBreak_ = port == Port::kSecondary ? brd.wkc() : 0;
  if (port != Port::kSecondary || indexState_[brd.index()] != IndexState::kInFlight) return true;
  Slot& slot = slots_[static_cast<std::size_t>(indexSlot_[brd.index()])];
  slot.brdAtSecondary = true;
  // Every slave of the ring answered from the second port: the primary port reaches none, so
  // the frame sent there is not coming back.
  if (ringSlaves_ > 0 && brd.wkc() >= ringSlaves_ && !slot.passedOn) {
    (void)sendFromSecond(slot, now);
  }
  return true;
}

void Transport::markBroken() {
  if (ring_ == RingState::kWhole) ++counters_.ringBreaks;
  ring_ = RingState::kBroken;
}

bool Transport::sendFromSecond(Slot& slot, SimTime now) {
  markBroken();
  if (auto sent = redundant_->send(slotTx(slot)); !sent.ok()) {
    ++counters_.sendErrors;
    return false;
  }
  slot.passedOn = true;
  slot.cameBackLength = 0;
  slot.deadline = now + options_.timeout;
  ++counters_.framesSentFromSecond;
  return true;
}

bool Transport::passOn(Slot& slot, std::size_t length, SimTime now) {
  markBroken();
  if (!secondaryDelivers_ || slot.passedOn) return false;
  std::memcpy(slot.cameBack.data(), rx_.data(), length);
  slot.cameBackLength = length;
  if (auto sent = redundant_->send(ConstBytes(rx_.data(), length)); !sent.ok()) {
    ++counters_.sendErrors;
    return false;
  }
  slot.passedOn = true;
  slot.deadline = now + options_.timeout;
  ++counters_.framesPassedOn;
  return true;
}

bool Transport::answerMatches(const Slot& slot, ConstBytes tx, ConstEtherCatFrame& answer) const {
  auto sent = ConstEtherCatFrame::parse(tx);
  if (!sent.ok() || sent->datagramCount() != answer.datagramCount()) return false;
  auto a = answer.begin();
  for (auto s = sent->begin(); s != sent->end(); ++s, ++a) {
    const auto sv = *s;
    const auto av = *a;
    if (av.rawCommand() != sv.rawCommand() || av.length() != sv.length() ||
        av.index() != slot.index) {
      return false;
    }
    // Auto-increment and broadcast datagrams come back with ADP incremented by every slave;
    // their ADO, and every other address, come back as sent.
    const AddressMode mode = addressMode(sv.command());
    const bool adpCounts = mode == AddressMode::kAutoIncrement || mode == AddressMode::kBroadcast;
    if (adpCounts ? av.ado() != sv.ado() : av.address() != sv.address()) return false;
  }
  return true;
}

void Transport::handleFrame(std::size_t length, SimTime now, Port port) {
  if (redundant_ != nullptr && takeSecondaryBrd(length, port, now)) return;
  auto answer = ConstEtherCatFrame::parse(ConstBytes(rx_.data(), length));
  if (!answer.ok() || answer->datagramCount() == 0) {
    ++counters_.framesUnexpected;
    return;
  }
  const std::uint8_t index = (*answer->begin()).index();
  if (indexState_[index] != IndexState::kInFlight) {
    if (indexState_[index] == IndexState::kGivenUp) {
      // It was not lost after all: the network returned it, after we had stopped waiting.
      --counters_.framesLost;
      ++counters_.framesLate;
      indexState_[index] = IndexState::kClosed;
    } else if (indexState_[index] == IndexState::kClosed) {
      ++counters_.framesLate;
    } else {
      ++counters_.framesUnexpected;
    }
    return;
  }
  Slot& slot = slots_[static_cast<std::size_t>(indexSlot_[index])];
  const ConstBytes tx = slotTx(slot);
  if (!answerMatches(slot, tx, *answer)) {
    ++counters_.framesUnexpected;
    return;
  }
  if (redundant_ != nullptr) {
    if (port == Port::kPrimary && slot.passedOn && slot.cameBackLength == 0) {
      // Sent from the second port after its timeout, yet the primary side answered after
      // all: the answer to come at the second port is the one of the frame as sent.
      ++counters_.framesLate;
      return;
    }
    if (port == Port::kPrimary && passOn(slot, length, now)) return;
    if (port == Port::kSecondary && !slot.passedOn) ring_ = RingState::kWhole;
  }
  deliver(slot, ConstBytes(rx_.data(), length), now);
}

void Transport::deliver(Slot& slot, ConstBytes frame, SimTime now) {
  ++counters_.framesAnswered;
  if (slot.cached != nullptr) {
    CachedFrame& cached = *slot.cached;
    std::memcpy(cached.rx_.data(), frame.data(), std::min(frame.size(), cached.length_));
    cached.receivedAt_ = now;
    release(slot, DatagramState::kReceived);
    return;
  }
  auto answer = ConstEtherCatFrame::parse(frame);  // it parsed when it came in
  if (!answer.ok()) {
    release(slot, DatagramState::kError);
    return;
  }
  std::size_t k = 0;
  for (auto it = answer->begin(); it != answer->end(); ++it, ++k) {
    Datagram* d = slot.datagrams[k];
    if (d == nullptr) continue;  // cancelled while in flight
    const auto view = *it;
    std::memcpy(d->data_.data(), view.data().data(), d->length_);
    d->wkc_ = view.wkc();
    d->receivedAt_ = now;
  }
  release(slot, DatagramState::kReceived);
}

void Transport::checkTimeouts(SimTime now) {
  for (auto& slot : slots_) {
    if (!slot.busy || now < slot.deadline) continue;
    if (slot.passedOn && slot.cameBackLength > 0) {
      // Nothing came back at the second port: the primary side's answer is all there is.
      ++counters_.passOnsUnanswered;
      secondaryDelivers_ = false;
      deliver(slot, ConstBytes(slot.cameBack.data(), slot.cameBackLength), now);
      continue;
    }
    if (!slot.passedOn && slot.brdAtSecondary && sendFromSecond(slot, now)) {
      // Nothing back at the primary port, the BRD back at the second: as SOEM's
      // ecx_waitinframe_red, the frame goes out of the second port (not a retry).
      continue;
    }
    slot.passedOn = false;  // a frame sent from the second port and not back: tried anew
    slot.brdAtSecondary = false;
    if (slot.triesLeft > 0) {
      --slot.triesLeft;
      slot.deadline = now + options_.timeout;
      ++counters_.framesResent;
      transmit(slotTx(slot), slot.index);
      continue;
    }
    ++counters_.framesLost;
    release(slot, DatagramState::kTimedOut);
  }
}

void Transport::sendQueued(SimTime now) {
  while (queueHead_ != nullptr) {
    Slot* slot = freeSlot();
    if (slot == nullptr) return;
    // false: only refused datagrams were taken off the queue; go on with the rest.
    (void)packFrame(*slot, now);
  }
}

bool Transport::packFrame(Slot& slot, SimTime now) {
  auto index = takeIndex();
  if (!index) return false;
  FrameBuilder builder(Bytes(slot.buffer.data(), slot.buffer.size()), ethernet_);
  slot.datagramCount = 0;
  while (queueHead_ != nullptr && slot.datagramCount < kMaxDatagramsPerFrame) {
    Datagram& d = *queueHead_;
    if (d.length_ > kMaxDatagramData || d.length_ > kMaxDatagramLength) {
      // Could never fit: refuse rather than truncate.
      unlinkQueued(d);
      d.owner_ = nullptr;
      d.state_ = DatagramState::kError;
      ++counters_.datagramsRefused;
      continue;
    }
    if (builder.remainingDataCapacity() < d.length_) break;
    auto view = builder.add(d.command_, *index, d.address_, d.data());
    if (!view.ok()) break;
    unlinkQueued(d);
    d.state_ = DatagramState::kSent;
    d.sentAt_ = now;
    slot.datagrams[slot.datagramCount++] = &d;
  }
  if (slot.datagramCount == 0) return false;
  auto length = builder.finish();
  if (!length.ok()) {  // cannot happen with at least one datagram in a full-size buffer
    for (std::size_t i = 0; i < slot.datagramCount; ++i) {
      slot.datagrams[i]->state_ = DatagramState::kError;
      slot.datagrams[i]->owner_ = nullptr;
      slot.datagrams[i] = nullptr;
    }
    slot.datagramCount = 0;
    return false;
  }
  slot.busy = true;
  slot.index = *index;
  slot.cached = nullptr;
  slot.length = *length;
  slot.triesLeft = options_.retries;
  slot.deadline = now + options_.timeout;
  ++inFlight_;
  indexState_[*index] = IndexState::kInFlight;
  indexSlot_[*index] = static_cast<std::int16_t>(&slot - slots_.data());
  ++counters_.framesSent;
  counters_.datagramsSent += slot.datagramCount;
  transmit(ConstBytes(slot.buffer.data(), slot.length), *index);  // a send error: retried
  return true;
}

}  // namespace ecsim::master
