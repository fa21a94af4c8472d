// What floor_bench sends, and the same frames' cost in this process (issue 18).
//
// - `brd`: one 64-byte BRD (60 bytes + FCS, 32 data bytes from 0x0000): every ESC reads its
//   first registers into it.
// - `cycle`: the cyclic frames of sim_bench's BM_CyclicFrame, so that the served figure can be
//   set beside sim_bench's own: an LRW of 8 bytes of process data per slave (one FMMU writing
//   to 0x1000, one reading from 0x1100 in each), the FRMW of the DC system time in the first
//   frame, frames of up to 1486 bytes (six at 1000 slaves). Before them the set-up frames give
//   each slave its station address and FMMUs, one datagram per frame, as sim_bench does.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "protocol/bytes.hpp"

namespace ecsim::bench {

using FrameBytes = std::vector<std::uint8_t>;

struct Workload {
  std::vector<FrameBytes> setup;  // sent once, in order, before the measurement
  std::vector<FrameBytes> cycle;  // sent in turn, one per round trip
  // The last datagram's working counter of each cycle frame as the simulator answers it,
  // found by passing the frames through a Segment in this process (the set-up's are 1 each).
  std::vector<std::uint16_t> servedWkc;
};

// "brd" or "cycle" for a line of `slaves` generic slaves; an unknown kind gives no frames.
Workload makeWorkload(const std::string& kind, unsigned slaves);

// The workload's cost in this process (Segment::processFrame on a line of generic slaves that
// had the set-up frames): ns per frame, with warm caches and after the caches were filled with
// other data, and ns per Segment::pollSlaves (the firmware the server runs between frames).
struct InProcess {
  double frameNs{0};
  double coldFrameNs{0};
  double pollNs{0};
  double frames{0};  // cycle frames per cycle
};
InProcess measureInProcess(const std::string& kind, unsigned slaves);

// The median of `v` (0 when empty).
double median(std::vector<double> v);

// Byte offset of the first datagram's index in every frame of a workload.
std::size_t indexOffset();
// The working counter of the frame's last datagram (a frame padded to 60 bytes has it before
// the padding); nullopt for what is no EtherCAT frame.
std::optional<std::uint16_t> lastWkc(ConstBytes frame);

}  // namespace ecsim::bench
