#include "master/cyclic.hpp"

#include <algorithm>
#include <cstdio>
#include <cstring>

namespace ecsim::master {

std::string WkcMismatch::describe(const std::vector<SlaveInfo>& slaveInfos) const {
  char buf[128];
  const std::string name(toString(command));
  if (isLogical(command)) {
    std::snprintf(buf, sizeof buf, "%s 0x%08X+%u", name.c_str(), logicalStart,
                  static_cast<unsigned>(length));
  } else {
    std::snprintf(buf, sizeof buf, "%s 0x%04X:0x%04X+%u", name.c_str(),
                  static_cast<unsigned>(logicalStart & 0xFFFFu),
                  static_cast<unsigned>(logicalStart >> 16), static_cast<unsigned>(length));
  }
  std::string s = buf;
  if (line > 0) s += " (ENI line " + std::to_string(line) + ")";
  std::snprintf(buf, sizeof buf, ": working counter %u, expected %u", static_cast<unsigned>(actual),
                static_cast<unsigned>(expected));
  s += buf;
  s += "; slaves concerned: ";
  for (std::size_t i = 0; i < slaves.size(); ++i) {
    if (i > 0) s += ", ";
    s += slaves[i] < slaveInfos.size() ? slaveInfos[slaves[i]].label()
                                       : "slave " + std::to_string(slaves[i]);
  }
  return s;
}

Status CyclicExchange::build(const ProcessImageLayout& layout, const MacAddress& source) {
  layout_ = nullptr;
  statistics_ = {};
  lastSend_.reset();
  source_ = source;
  layout_ = &layout;
  auto status = assemble();
  if (!status.ok()) {
    layout_ = nullptr;
    frames_.clear();
    return status;
  }
  resetExpectedWkcs();
  return okStatus();
}

Status CyclicExchange::setState(AlState state) {
  const std::optional<AlState> before = state_;
  state_ = state;
  if (layout_ == nullptr) return okStatus();
  bool changed = false;
  for (std::size_t i = 0; i < layout_->datagrams.size(); ++i) {
    if (isActive(layout_->datagrams[i]) != datagrams_[i].active) changed = true;
  }
  if (!changed) return okStatus();
  if (pending()) {
    state_ = before;
    return makeError(ErrorCode::kState, "cyclic frames in flight: cannot change their datagrams");
  }
  return assemble();
}

Status CyclicExchange::assemble() {
  const ProcessImageLayout& layout = *layout_;
  frames_.clear();
  datagrams_.assign(layout.datagrams.size(), DatagramRef{});
  outputs_.clear();
  inputs_.clear();
  dcDatagram_.reset();
  dcLayoutIndex_.reset();
  EthernetHeader ethernet;
  ethernet.destination = kBroadcastMac;
  ethernet.source = source_;
  for (std::size_t f = 0; f < layout.frameCount; ++f) {
    auto frame = std::make_unique<CachedFrame>();
    FrameBuilder builder(frame->buildBuffer(), ethernet);
    std::size_t k = 0;
    for (std::size_t i = 0; i < layout.datagrams.size(); ++i) {
      const LogicalDatagram& d = layout.datagrams[i];
      if (d.frame != f) continue;
      if (!isActive(d)) {
        datagrams_[i].active = false;
        continue;
      }
      auto view = builder.add(d.command, 0, d.logicalStart, d.length);
      if (!view.ok()) return view.takeError();
      datagrams_[i] = {frames_.size(), k++, true};
      const bool systemTime = (d.command == Command::kFrmw || d.command == Command::kArmw) &&
                              (d.logicalStart >> 16) == reg::kSystemTime.address;
      if (systemTime && !dcDatagram_) {
        dcDatagram_ = datagrams_[i];
        dcCommand_ = static_cast<std::uint8_t>(d.command);
        dcLayoutIndex_ = i;
      }
    }
    if (frames_.empty() && dcReference_ && !dcDatagram_) {
      // The first frame, unless the process data fills it (an image of more than one frame):
      // then the FRMW goes in a frame of its own after the process data's (below).
      auto added = addDcDistribution(builder, k);
      if (!added.ok() && added.error().code != ErrorCode::kTooLarge) return added;
    }
    if (k == 0) continue;  // nothing of this frame is sent in this state
    auto length = builder.finish();
    if (!length.ok()) return length.takeError();
    ECSIM_TRY(frame->commit(*length));
    frames_.push_back(std::move(frame));
  }
  if (dcReference_ && !dcDatagram_) {
    auto frame = std::make_unique<CachedFrame>();
    FrameBuilder builder(frame->buildBuffer(), ethernet);
    std::size_t k = 0;
    ECSIM_TRY(addDcDistribution(builder, k));
    auto length = builder.finish();
    if (!length.ok()) return length.takeError();
    ECSIM_TRY(frame->commit(*length));
    frames_.push_back(std::move(frame));
  }
  // Copies: the part of each logical datagram over outputs (image -> frame: LWR, LRW) and over
  // inputs (frame -> image: LRD, LRW).
  for (std::size_t i = 0; i < layout.datagrams.size(); ++i) {
    const LogicalDatagram& d = layout.datagrams[i];
    const DatagramRef& ref = datagrams_[i];
    if (!ref.active || !isLogical(d.command)) continue;
    const CommandAccess access = commandAccess(d.command);
    const std::uint32_t start = d.logicalStart - layout.logicalBase;
    const std::uint32_t end = start + d.length;
    const std::size_t dataOffset =
        frames_[ref.frame]->datagramOffset(ref.index) + kDatagramHeaderSize;
    auto add = [&](std::vector<Copy>& list, std::uint32_t from, std::uint32_t to) {
      const std::uint32_t a = std::max(start, from);
      const std::uint32_t b = std::min(end, to);
      if (a < b) list.push_back({ref.frame, dataOffset + (a - start), a, b - a});
    };
    if (access.write) add(outputs_, 0, layout.outputBytes);
    if (access.read) add(inputs_, layout.outputBytes, layout.size());
  }
  return okStatus();
}

Status CyclicExchange::addDcDistribution(FrameBuilder& builder, std::size_t& k) {
  auto view = builder.add(Command::kFrmw, 0,
                          DatagramHeader::physical(*dcReference_, reg::kSystemTime.address),
                          std::uint16_t{8});
  if (!view.ok()) return view.takeError();
  dcDatagram_ = DatagramRef{frames_.size(), k++, true};
  dcCommand_ = static_cast<std::uint8_t>(Command::kFrmw);
  return okStatus();
}

void CyclicExchange::resetExpectedWkcs() {
  expectedMin_.clear();
  expectedMax_.clear();
  if (layout_ == nullptr) return;
  for (const auto& d : layout_->datagrams) {
    expectedMin_.push_back(d.checkWkc ? d.expectedWkc : std::uint16_t{0});
    expectedMax_.push_back(d.checkWkc ? d.expectedWkc : std::uint16_t{0xFFFF});
  }
}

std::optional<std::uint16_t> CyclicExchange::receivedWkc(std::size_t datagram) const {
  if (datagram >= datagrams_.size() || !datagrams_[datagram].active) return std::nullopt;
  const CachedFrame& frame = *frames_[datagrams_[datagram].frame];
  if (frame.state() != DatagramState::kReceived) return std::nullopt;
  return frame.rxWkc(datagrams_[datagram].index);
}

Status CyclicExchange::send(Transport& transport, ConstBytes image, SimTime now) {
  if (layout_ == nullptr) return makeError(ErrorCode::kState, "cyclic frames not built");
  if (image.size() < layout_->size()) {
    return makeError(ErrorCode::kInvalidArgument, "process image smaller than the layout");
  }
  for (auto& frame : frames_) {
    if (frame->pending()) transport.abandon(*frame);  // last cycle's answer never came
  }
  for (const Copy& c : outputs_) {
    std::memcpy(frames_[c.frame]->tx().data() + c.frameOffset, image.data() + c.imageOffset,
                c.length);
  }
  if (dcDatagram_) {
    CachedFrame& frame = *frames_[dcDatagram_->frame];
    frame.tx()[frame.datagramOffset(dcDatagram_->index)] =
        dcHeld_ ? static_cast<std::uint8_t>(Command::kNop) : dcCommand_;
  }
  ++statistics_.cycles;
  if (period_ > 0 && lastSend_) {
    const SimTime deviation = (now - *lastSend_) - period_;
    statistics_.jitter.record(deviation < 0 ? -deviation : deviation);
  }
  lastSend_ = now;
  for (auto& frame : frames_) {
    ECSIM_TRY(transport.send(*frame, now));
    ++statistics_.framesSent;
  }
  return okStatus();
}

bool CyclicExchange::pending() const {
  for (const auto& frame : frames_) {
    if (frame->pending()) return true;
  }
  return false;
}

std::optional<std::uint64_t> CyclicExchange::dcSystemTime() const {
  if (!dcDatagram_ || dcHeld_ || dcDatagram_->frame >= frames_.size()) return std::nullopt;
  const CachedFrame& frame = *frames_[dcDatagram_->frame];
  if (frame.state() != DatagramState::kReceived) return std::nullopt;
  const std::size_t at = frame.datagramOffset(dcDatagram_->index) + kDatagramHeaderSize;
  if (frame.rxData(dcDatagram_->index).size() < 8) return readLe32(frame.rx(), at);
  return readLe64(frame.rx(), at);
}

CycleResult CyclicExchange::finish(Bytes image) {
  CycleResult result;
  if (layout_ == nullptr || image.size() < layout_->size()) return result;
  for (const auto& frame : frames_) {
    if (frame->state() == DatagramState::kReceived) {
      ++result.framesAnswered;
      const SimTime rtt = frame->receivedAt() - frame->sentAt();
      result.maxRoundTrip = std::max(result.maxRoundTrip, rtt);
      if (statistics_.roundTrips == 0 || rtt < statistics_.roundTripMin) {
        statistics_.roundTripMin = rtt;
      }
      statistics_.roundTripMax = std::max(statistics_.roundTripMax, rtt);
      statistics_.roundTripSum += rtt;
      ++statistics_.roundTrips;
      statistics_.roundTrip.record(rtt);
      if (deadline_ > 0 && rtt > deadline_) ++result.framesLate;
    } else {
      ++result.framesLost;
    }
  }
  for (const Copy& c : inputs_) {
    const CachedFrame& frame = *frames_[c.frame];
    if (frame.state() != DatagramState::kReceived) continue;
    std::memcpy(image.data() + c.imageOffset, frame.rx().data() + c.frameOffset, c.length);
  }
  for (std::size_t i = 0; i < datagrams_.size(); ++i) {
    if (!datagrams_[i].active || (dcHeld_ && dcLayoutIndex_ == i)) continue;
    const CachedFrame& frame = *frames_[datagrams_[i].frame];
    if (frame.state() != DatagramState::kReceived) continue;
    const std::uint16_t wkc = frame.rxWkc(datagrams_[i].index);
    const LogicalDatagram& d = layout_->datagrams[i];
    if (wkc >= expectedMin_[i] && wkc <= expectedMax_[i]) continue;
    ++result.wkcErrors;
    if (!result.firstMismatch) {
      result.firstMismatch = WkcMismatch{i,
                                         d.command,
                                         d.logicalStart,
                                         d.length,
                                         expectedMin_[i],
                                         wkc,
                                         std::span<const std::size_t>(d.slaves),
                                         d.line};
    }
  }
  statistics_.framesLost += result.framesLost;
  statistics_.wkcErrors += result.wkcErrors;
  statistics_.framesLate += result.framesLate;
  if (!result.ok()) ++statistics_.cyclesWithErrors;
  return result;
}

}  // namespace ecsim::master
