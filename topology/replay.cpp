#include "topology/replay.hpp"

#include <algorithm>
#include <array>
#include <sstream>

#include "protocol/frame.hpp"

namespace ecsim::topology {
namespace {

// Same first datagram index and the same sequence of commands and lengths.
bool sameShape(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
  auto fa = ConstEtherCatFrame::parse(ConstBytes(a));
  auto fb = ConstEtherCatFrame::parse(ConstBytes(b));
  if (!fa.ok() || !fb.ok() || fa->datagramCount() != fb->datagramCount()) return false;
  for (auto x = fa->begin(), y = fb->begin(); x != fa->end() && y != fb->end(); ++x, ++y) {
    if ((*x).rawCommand() != (*y).rawCommand() || (*x).index() != (*y).index() ||
        (*x).length() != (*y).length()) {
      return false;
    }
  }
  return true;
}

bool isEtherCat(const PcapRecord& r) {
  auto eth = EthernetHeader::parse(r.data);
  return eth.ok() && eth->etherType == kEtherTypeEtherCat;
}

bool inTimeRegisters(const DatagramHeader& h, std::size_t offset) {
  if (addressMode(h.command) == AddressMode::kLogical) return false;
  const std::uint32_t a = static_cast<std::uint32_t>(h.ado()) + static_cast<std::uint32_t>(offset);
  return a >= 0x0900 && a < 0x0A00;
}

}  // namespace

std::string ReplayDifference::describe() const {
  std::ostringstream s;
  s << "frame " << frameNumber << " datagram " << datagram << " " << command << " 0x" << std::hex
    << address << std::dec;
  if (recordedWkc != simulatedWkc) {
    s << ": WKC recorded " << recordedWkc << ", simulated " << simulatedWkc;
  }
  if (!differingBytes.empty()) {
    s << (recordedWkc != simulatedWkc ? "; " : ": ") << differingBytes.size()
      << " data byte(s) differ (first at +" << differingBytes.front() << ")"
      << (timeRegisters ? " [DC time registers]" : "");
  }
  return s.str();
}

Result<ReplayReport> replayCapture(const std::vector<PcapRecord>& capture, Segment& segment,
                                   std::optional<SimTime> timeOrigin) {
  ReplayReport report;
  report.framesInCapture = capture.size();
  SimTime start = timeOrigin.value_or(capture.empty() ? 0 : capture.front().timestampNs);
  std::array<std::uint8_t, kMaxFrameSize> buffer{};
  std::vector<bool> isAnswer(capture.size(), false);
  for (std::size_t i = 0; i < capture.size(); ++i) {
    const PcapRecord& rec = capture[i];
    if (!isEtherCat(rec)) {
      ++report.otherFrames;
      continue;
    }
    if (isAnswer[i]) continue;
    ++report.masterFrames;
    // The recorded answer: the next frame with the same first index and the same datagram
    // commands (a master's own source MAC may carry the locally administered bit too, so
    // the ESCs' marking alone cannot tell requests from answers).
    const PcapRecord* answer = nullptr;
    for (std::size_t j = i + 1; j < capture.size() && j < i + 64; ++j) {
      if (!isAnswer[j] && isEtherCat(capture[j]) && sameShape(rec.data, capture[j].data)) {
        answer = &capture[j];
        isAnswer[j] = true;
        break;
      }
    }
    if (rec.data.size() > buffer.size()) {
      return makeError(ErrorCode::kTooLarge,
                       "frame " + std::to_string(i + 1) + " is longer than 1514 bytes");
    }
    std::copy(rec.data.begin(), rec.data.end(), buffer.begin());
    Bytes sim(buffer.data(), rec.data.size());
    const SimTime now = rec.timestampNs - start;
    FrameOutcome out = segment.processFrame(sim, now);
    segment.pollSlaves(now);
    if (answer == nullptr) {
      ++report.unanswered;
      continue;
    }
    if (!out.delivered) {
      return makeError(ErrorCode::kMalformed,
                       "frame " + std::to_string(i + 1) + " is not a valid EtherCAT frame");
    }
    auto simFrame = ConstEtherCatFrame::parse(ConstBytes(sim));
    auto recFrame = ConstEtherCatFrame::parse(ConstBytes(answer->data));
    if (!simFrame.ok() || !recFrame.ok()) continue;
    auto a = simFrame->begin();
    auto b = recFrame->begin();
    for (std::size_t d = 0; a != simFrame->end() && b != recFrame->end(); ++a, ++b, ++d) {
      ++report.datagrams;
      auto sd = *a;
      auto rd = *b;
      ReplayDifference diff;
      diff.frameNumber = i + 1;
      diff.datagram = d;
      diff.command = std::string(toString(rd.command()));
      diff.address = rd.address();
      diff.recordedWkc = rd.wkc();
      diff.simulatedWkc = sd.wkc();
      const auto header = sd.header();
      bool allTime = true;
      for (std::size_t k = 0; k < std::min(sd.data().size(), rd.data().size()); ++k) {
        if (sd.data()[k] != rd.data()[k]) {
          diff.differingBytes.push_back(k);
          allTime &= inTimeRegisters(header, k);
        }
      }
      diff.timeRegisters = !diff.differingBytes.empty() && allTime;
      if (diff.recordedWkc != diff.simulatedWkc) ++report.wkcMismatches;
      if (!diff.differingBytes.empty()) {
        ++(diff.timeRegisters ? report.timeDataMismatches : report.dataMismatches);
      }
      if (diff.recordedWkc != diff.simulatedWkc || !diff.differingBytes.empty()) {
        report.differences.push_back(std::move(diff));
      }
    }
  }
  return report;
}

}  // namespace ecsim::topology
