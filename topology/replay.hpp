// Capture replay: the master's frames of a recorded capture (real hardware or ours) are fed
// to a simulated network at their recorded times, and each answer is compared with the
// answer the capture holds, datagram by datagram (working counter, data bytes). The report
// classifies differences so a fidelity study can tell model gaps from expected ones (times
// read from DC registers differ because clocks differ).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "link/pcap.hpp"
#include "protocol/result.hpp"
#include "topology/segment.hpp"

namespace ecsim::topology {

struct ReplayDifference {
  std::size_t frameNumber{0};  // 1-based, in the capture (the master's frame)
  std::size_t datagram{0};     // 0-based within the frame
  std::string command;         // "FPRD"...
  std::uint32_t address{0};
  std::uint16_t recordedWkc{0};
  std::uint16_t simulatedWkc{0};
  std::vector<std::size_t> differingBytes;  // offsets within the datagram data
  bool timeRegisters{false};                // every differing byte lies in 0x0900-0x09FF (DC times)
  std::string describe() const;
};

struct ReplayReport {
  std::size_t framesInCapture{0};
  std::size_t otherFrames{0};  // not EtherCAT (e.g. IP traffic of the capturing host)
  std::size_t masterFrames{0};
  std::size_t unanswered{0};  // master frames with no recorded answer (lost on the wire)
  std::size_t datagrams{0};
  std::size_t wkcMismatches{0};
  std::size_t dataMismatches{0};      // outside the DC time registers
  std::size_t timeDataMismatches{0};  // only in DC time registers
  std::vector<ReplayDifference> differences;
  bool identical() const {
    return wkcMismatches == 0 && dataMismatches == 0 && timeDataMismatches == 0;
  }
};

// Pairs each master frame with the next frame of the same shape (first datagram index,
// commands and lengths): the answer the capture holds for it. Each master frame enters
// the network at simulation time (capture timestamp - timeOrigin); by default timeOrigin is
// the first frame's timestamp. Give the capture's own origin to reproduce DC times exactly
// (for captures made by ecsim, stamped with model time).
Result<ReplayReport> replayCapture(const std::vector<PcapRecord>& capture, Segment& segment,
                                   std::optional<SimTime> timeOrigin = std::nullopt);

}  // namespace ecsim::topology
