#include "topology/latency_model.hpp"

#include <algorithm>
#include <array>
#include <string>

#include "protocol/ethernet.hpp"

namespace ecsim::topology {
namespace {

constexpr std::size_t kPreambleBytes = 8;  // preamble + SFD
constexpr std::size_t kFcsBytes = 4;
constexpr std::size_t kGapBytes = 12;

// The time the first bit of a frame reaches each slave's port 0, from the cable observers
// (an observer sees the moment the first bit enters the cable; the cable's own delay is added
// here).
class PortZeroArrivals final : public CableObserver {
 public:
  PortZeroArrivals(SimTime cableNs, SimTime* arrival) : cableNs_(cableNs), arrival_(arrival) {}
  void onFrame(ConstBytes, SimTime time, bool downstream) override {
    if (downstream) *arrival_ = time + cableNs_;
  }

 private:
  SimTime cableNs_;
  SimTime* arrival_;
};

SimTime cableNs(double metres, const TimingModel& timing) {
  return static_cast<SimTime>(metres * timing.cableNsPerMetre + 0.5);
}

}  // namespace

SimTime frameWireNs(std::size_t ethernetBytes, const TimingModel& timing, bool gap) {
  const std::size_t bytes =
      kPreambleBytes + std::max(ethernetBytes, kMinFrameSize) + kFcsBytes + (gap ? kGapBytes : 0);
  return static_cast<SimTime>(bytes) * timing.nsPerByte;
}

Result<ModelledCycle> modelCycle(Segment& segment, const std::vector<ModelFrame>& frames,
                                 SimTime sendTime, double masterCableMetres) {
  if (segment.size() == 0) return makeError(ErrorCode::kInvalidArgument, "no slaves to model");
  const TimingModel& timing = segment.timing();
  // Port 0 of every slave: its upstream cable's length (the master cable for slave 0).
  std::vector<SimTime> arrival(segment.size(), -1);
  std::vector<PortZeroArrivals> observers;
  observers.reserve(segment.size());
  for (std::size_t s = 0; s < segment.size(); ++s) {
    const double metres = s == 0 ? masterCableMetres : segment.ports(s)[0].cableMetres;
    observers.emplace_back(cableNs(metres, timing), &arrival[s]);
  }
  for (std::size_t s = 0; s < segment.size(); ++s) segment.setCableObserver(s, 0, &observers[s]);

  ModelledCycle cycle;
  cycle.frames = frames.size();
  SimTime at = sendTime;
  Status status = okStatus();
  for (std::size_t k = 0; k < frames.size() && status.ok(); ++k) {
    std::array<std::uint8_t, kMaxFrameSize> buffer{};
    FrameBuilder builder(buffer, EthernetHeader{});
    for (const auto& d : frames[k]) {
      if (auto v = builder.add(d.command, 0, d.address, d.length); !v.ok()) {
        status = makeError(ErrorCode::kInvalidArgument,
                           "cyclic frame " + std::to_string(k + 1) + ": " + v.error().message());
        break;
      }
    }
    if (!status.ok()) break;
    auto length = builder.finish();
    if (!length.ok()) {
      status = length.takeError();
      break;
    }
    std::fill(arrival.begin(), arrival.end(), -1);
    const FrameOutcome out = segment.processFrame(Bytes(buffer.data(), *length), at);
    if (!out.delivered) {
      status = makeError(ErrorCode::kState,
                         "cyclic frame " + std::to_string(k + 1) + " was not delivered");
      break;
    }
    const SimTime ownWire = frameWireNs(*length, timing, false);
    for (SimTime a : arrival) {
      if (a >= 0)
        cycle.outputsCompleteNs = std::max(cycle.outputsCompleteNs, a + ownWire - sendTime);
    }
    cycle.roundTripNs = std::max(cycle.roundTripNs, out.returnTime - sendTime);
    cycle.frameBytes += *length;
    const SimTime footprint = frameWireNs(*length, timing, true);
    cycle.wireNs += footprint;
    at += footprint;
  }
  for (std::size_t s = 0; s < segment.size(); ++s) segment.setCableObserver(s, 0, nullptr);
  if (!status.ok()) return status.error();
  return cycle;
}

}  // namespace ecsim::topology
