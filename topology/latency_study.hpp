// The latency study behind `ecsim study latency`: for a topology kind, a slave count and a
// process-data size per slave, build the network, the cyclic frames a master would send
// (LRW of all process data, split at the frame limit, with the DC FRMW in the first frame),
// and measure the modelled round trip, the minimum cycle time and the simulator's CPU cost.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/result.hpp"
#include "protocol/time.hpp"

namespace ecsim::topology {

enum class StudyTopology : std::uint8_t { kLine, kTree };
std::string_view toString(StudyTopology t);

struct StudyParameters {
  StudyTopology topology{StudyTopology::kLine};
  std::size_t slaves{1};           // slaves with process data (a coupler is not counted)
  std::uint16_t bytesPerSlave{8};  // inputs and outputs overlap in the logical image (LRW)
  double cableMetres{1.0};         // between slaves (0 for EBUS terminals side by side)
  double masterCableMetres{1.0};
  SimTime processingDelayNs{1000};
  SimTime forwardingDelayNs{1000};
  // The DC FRMW of 0x0910 in the first frame (a master running distributed clocks).
  bool distributedClock{true};
  // A coupler without process data ahead of the slaves (an EK1100 in front of EBUS terminals):
  // port 0 is 100BASE-TX, its other side EBUS, so its two passages differ.
  bool coupler{false};
  SimTime couplerProcessingDelayNs{0};
  SimTime couplerForwardingDelayNs{0};
  int repetitions{20};  // cycles simulated to measure CPU time
};

struct StudyPoint {
  StudyParameters parameters;
  std::size_t frameBytes{0};  // Ethernet bytes of all frames of one cycle (no FCS)
  std::size_t framesPerCycle{0};
  SimTime roundTripNs{0};  // first bit out -> last bit of the last frame back
  SimTime minCycleNs{0};   // max(round trip, wire occupancy incl. gaps)
  double simCpuNsPerCycle{0};
  std::uint64_t wkcErrors{0};  // cycles whose working counters were not as expected
};

// Runs one point; `cpuClock` measures the simulator's time (a RealClock in the tool).
Result<StudyPoint> runLatencyPoint(const StudyParameters& p, const Clock& cpuClock);

// Round trip of one frame of `frameBytes` Ethernet bytes through a line of identical slaves,
// from the timing model's formula: N processing delays, N-1 forwarding delays, each cable
// twice, then the frame's own wire time (preamble + frame + FCS at 80 ns/byte). A coupler adds
// both its delays and one more cable, crossed twice.
SimTime closedFormLineRoundTrip(const StudyParameters& p, std::size_t frameBytes);

// A published EtherCAT performance figure and the network we reproduce it with
// (docs/timing.md, "Published figures").
struct PublishedFigure {
  std::string_view name;     // e.g. "1000 digital I/O"
  std::string_view network;  // the modelled network, in words
  std::string_view source;
  SimTime publishedNs{0};
  StudyParameters parameters;
};
std::vector<PublishedFigure> publishedFigures();

// Slave counts 1, 2, 4, ... up to max (max included).
std::vector<std::size_t> logSpacedCounts(std::size_t max);

}  // namespace ecsim::topology
