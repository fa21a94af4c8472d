#include "master/cyclic.hpp"

#include <algorithm>
#include <cstdio>
#include <cstring>

namespace ecsim::master {

std::string WkcMismatch::describe(const std::vector<SlaveInfo>& slaveInfos) const {
  char buf[96];
  std::snprintf(buf, sizeof buf, "LRW 0x%08X+%u: working counter %u, expected %u", logicalStart,
                static_cast<unsigned>(length), static_cast<unsigned>(actual),
                static_cast<unsigned>(expected));
  std::string s = buf;
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
  frames_.clear();
  datagrams_.clear();
  outputs_.clear();
  inputs_.clear();
  expectedMin_.clear();
  expectedMax_.clear();
  statistics_ = {};
  lastSend_.reset();
  dcDatagram_.reset();
  EthernetHeader ethernet;
  ethernet.destination = kBroadcastMac;
  ethernet.source = source;
  for (std::size_t f = 0; f < layout.frameCount; ++f) {
    auto frame = std::make_unique<CachedFrame>();
    FrameBuilder builder(frame->buildBuffer(), ethernet);
    std::size_t k = 0;
    for (const auto& d : layout.datagrams) {
      if (d.frame != f) continue;
      auto view = builder.add(Command::kLrw, 0, d.logicalStart, d.length);
      if (!view.ok()) return view.takeError();
      datagrams_.push_back({f, k++});
    }
    if (f == 0 && dcReference_) {
      auto view = builder.add(Command::kFrmw, 0, DatagramHeader::physical(*dcReference_, 0x0910),
                              std::uint16_t{8});
      if (!view.ok()) return view.takeError();
      dcDatagram_ = k++;
    }
    auto length = builder.finish();
    if (!length.ok()) return length.takeError();
    ECSIM_TRY(frame->commit(*length));
    frames_.push_back(std::move(frame));
  }
  // Copies: the part of each datagram over outputs (image -> frame) and over inputs.
  for (std::size_t i = 0; i < layout.datagrams.size(); ++i) {
    const LogicalDatagram& d = layout.datagrams[i];
    const DatagramRef& ref = datagrams_[i];
    const std::uint32_t start = d.logicalStart - layout.logicalBase;
    const std::uint32_t end = start + d.length;
    const std::size_t dataOffset =
        frames_[ref.frame]->datagramOffset(ref.index) + kDatagramHeaderSize;
    auto add = [&](std::vector<Copy>& list, std::uint32_t from, std::uint32_t to) {
      const std::uint32_t a = std::max(start, from);
      const std::uint32_t b = std::min(end, to);
      if (a < b) list.push_back({ref.frame, dataOffset + (a - start), a, b - a});
    };
    add(outputs_, 0, layout.outputBytes);
    add(inputs_, layout.outputBytes, layout.size());
  }
  layout_ = &layout;
  resetExpectedWkcs();
  return okStatus();
}

void CyclicExchange::resetExpectedWkcs() {
  expectedMin_.clear();
  expectedMax_.clear();
  if (layout_ == nullptr) return;
  for (const auto& d : layout_->datagrams) {
    expectedMin_.push_back(d.expectedWkc);
    expectedMax_.push_back(d.expectedWkc);
  }
}

std::optional<std::uint16_t> CyclicExchange::receivedWkc(std::size_t datagram) const {
  if (datagram >= datagrams_.size()) return std::nullopt;
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
  if (!dcDatagram_ || frames_.empty() || frames_[0]->state() != DatagramState::kReceived) {
    return std::nullopt;
  }
  const std::size_t at = frames_[0]->datagramOffset(*dcDatagram_) + kDatagramHeaderSize;
  return readLe64(frames_[0]->rx(), at);
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
    const CachedFrame& frame = *frames_[datagrams_[i].frame];
    if (frame.state() != DatagramState::kReceived) continue;
    const std::uint16_t wkc = frame.rxWkc(datagrams_[i].index);
    const LogicalDatagram& d = layout_->datagrams[i];
    if (wkc >= expectedMin_[i] && wkc <= expectedMax_[i]) continue;
    ++result.wkcErrors;
    if (!result.firstMismatch) {
      result.firstMismatch = WkcMismatch{i,        d.logicalStart,
                                         d.length, expectedMin_[i],
                                         wkc,      std::span<const std::size_t>(d.slaves)};
    }
  }
  statistics_.framesLost += result.framesLost;
  statistics_.wkcErrors += result.wkcErrors;
  statistics_.framesLate += result.framesLate;
  if (!result.ok()) ++statistics_.cyclesWithErrors;
  return result;
}

}  // namespace ecsim::master
