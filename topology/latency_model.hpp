// The modelled timing of one cycle of a real network (`ecsim study latency --topology FILE`):
// the master's cyclic frames, as it sends them, carried back to back through the network's
// segment (each slave's own ESC delays and cables, docs/timing.md), giving
//
//   round trip        first bit of the first frame out -> last bit of the last frame back
//   wire occupancy    every frame's preamble, bytes (padded to 60), FCS and inter-frame gap
//   outputs complete  when the last frame's last bit (its FCS) has passed the processing
//                     unit of every slave: the ESC hands a SyncManager buffer over only after
//                     the frame's FCS was checked (ESC datasheet section I, "SyncManager"), so
//                     no SYNC0 can use this cycle's outputs earlier. The SYNC0 shift a cycle
//                     needs is this plus the master's send jitter.
//
// The segment's slaves keep whatever the frames do to them (the caller's network is used as
// it stands, e.g. after a master brought it to OP).
#pragma once

#include <cstdint>
#include <vector>

#include "protocol/frame.hpp"
#include "protocol/result.hpp"
#include "protocol/time.hpp"
#include "topology/segment.hpp"

namespace ecsim::topology {

struct ModelDatagram {
  Command command{Command::kLrw};
  std::uint32_t address{0};  // logical address, or ADP | ADO << 16
  std::uint16_t length{0};
};
using ModelFrame = std::vector<ModelDatagram>;

struct ModelledCycle {
  std::size_t frames{0};
  std::size_t frameBytes{
      0};  // Ethernet bytes of all frames (header to last datagram, padded, no FCS)
  SimTime wireNs{0};
  SimTime roundTripNs{0};
  SimTime outputsCompleteNs{0};
  // The minimum cycle the wire allows: max(round trip, wire occupancy).
  SimTime minCycleNs() const { return roundTripNs > wireNs ? roundTripNs : wireNs; }
};

// Wire time of one frame of `ethernetBytes` (no FCS): preamble + SFD, the bytes padded to the
// Ethernet minimum, FCS; with `gap` the inter-frame gap too (IEEE 802.3).
SimTime frameWireNs(std::size_t ethernetBytes, const TimingModel& timing, bool gap);

// Sends `frames` back to back from `sendTime` (the first bit of frame k+1 leaves one frame
// and gap after frame k's) through `segment`; `masterCableMetres` is the cable between the
// master and slave 0 (the segment keeps it but does not tell). kInvalidArgument when a frame
// does not fit in 1514 bytes, kState when one is not delivered.
Result<ModelledCycle> modelCycle(Segment& segment, const std::vector<ModelFrame>& frames,
                                 SimTime sendTime, double masterCableMetres);

}  // namespace ecsim::topology
