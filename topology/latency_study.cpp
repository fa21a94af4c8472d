#include "topology/latency_study.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "protocol/frame.hpp"
#include "protocol/registers.hpp"
#include "slavesim/esc_type.hpp"
#include "slavesim/generic_slave.hpp"
#include "topology/segment.hpp"

namespace ecsim::topology {
namespace {

constexpr std::size_t kFrameOverheadOnWire = 8 + 4 + 12;  // preamble+SFD, FCS, gap
constexpr std::size_t kTreeGroup = 8;                     // junction + 7 slaves on its branch

void programFmmus(slavesim::Esc& esc, std::uint32_t logical, std::uint16_t bytes) {
  // FMMU0: outputs to 0x1000, FMMU1: inputs from 0x1000 + bytes, both at the same logical
  // address (inputs and outputs overlap in one LRW, as TwinCAT lays them out).
  for (unsigned n = 0; n < 2; ++n) {
    const std::uint16_t base = reg::fmmuChannel(n);
    esc.pdiWrite32(base + reg::fmmu::kLogicalStart.address, logical);
    esc.pdiWrite16(base + reg::fmmu::kLength.address, bytes);
    esc.pdiWrite8(base + reg::fmmu::kLogicalStopBit.address, 7);
    esc.pdiWrite16(base + reg::fmmu::kPhysicalStart.address,
                   static_cast<std::uint16_t>(reg::kRegisterSpaceEnd + n * bytes));
    esc.pdiWrite8(base + reg::fmmu::kType.address,
                  n == 0 ? reg::fmmu::kTypeWrite : reg::fmmu::kTypeRead);
    esc.pdiWrite8(base + reg::fmmu::kActivate.address, 1);
  }
}

Status wire(Segment& seg, const StudyParameters& p) {
  // A coupler is slave 0 and the slaves with process data follow it on its port 1.
  const std::size_t first = p.coupler ? 1 : 0;
  const std::size_t n = p.slaves;
  if (p.coupler) ECSIM_TRY(seg.connect(0, 1, 1, 0, p.cableMetres));
  if (p.topology == StudyTopology::kLine) {
    for (std::size_t i = 1; i < n; ++i) {
      ECSIM_TRY(seg.connect(first + i - 1, 1, first + i, 0, p.cableMetres));
    }
    return okStatus();
  }
  // Tree: junctions every kTreeGroup slaves along a trunk (port 1 -> port 0); each junction's
  // port 3 carries a branch line of the following slaves.
  for (std::size_t i = 1; i < n; ++i) {
    const std::size_t at = first + i;
    if (i % kTreeGroup == 0) {
      ECSIM_TRY(seg.connect(at - kTreeGroup, 1, at, 0, p.cableMetres));
    } else if (i % kTreeGroup == 1) {
      ECSIM_TRY(seg.connect(at - 1, 3, at, 0, p.cableMetres));
    } else {
      ECSIM_TRY(seg.connect(at - 1, 1, at, 0, p.cableMetres));
    }
  }
  return okStatus();
}

}  // namespace

std::string_view toString(StudyTopology t) {
  return t == StudyTopology::kLine ? "line" : "tree";
}

std::vector<std::size_t> logSpacedCounts(std::size_t max) {
  std::vector<std::size_t> counts;
  for (std::size_t n = 1; n < max; n *= 2) counts.push_back(n);
  if (max > 0) counts.push_back(max);
  return counts;
}

SimTime closedFormLineRoundTrip(const StudyParameters& p, std::size_t frameBytes) {
  const auto n = static_cast<SimTime>(p.slaves);
  const auto cable = [](double m) { return static_cast<SimTime>(m * 5.0 + 0.5); };
  SimTime firstBit = n * p.processingDelayNs + (n - 1) * p.forwardingDelayNs +
                     2 * (n - 1) * cable(p.cableMetres) + 2 * cable(p.masterCableMetres);
  if (p.coupler) {
    firstBit += p.couplerProcessingDelayNs + p.couplerForwardingDelayNs + 2 * cable(p.cableMetres);
  }
  return firstBit +
         static_cast<SimTime>(8 + std::max<std::size_t>(frameBytes, kMinFrameSize) + 4) * 80;
}

Result<StudyPoint> runLatencyPoint(const StudyParameters& p, const Clock& cpuClock) {
  if (p.slaves == 0 || p.bytesPerSlave == 0) {
    return makeError(ErrorCode::kInvalidArgument, "study needs at least one slave and one byte");
  }
  Segment seg;
  if (p.coupler) {
    seg.addSlave(slavesim::makeGenericSlave("coupler", 0));
    seg.setDelays(0, p.couplerProcessingDelayNs, p.couplerForwardingDelayNs);
  }
  for (std::size_t i = 0; i < p.slaves; ++i) {
    const std::size_t at = seg.addSlave(
        slavesim::makeGenericSlave("s" + std::to_string(i), static_cast<std::uint32_t>(i + 1)));
    seg.setDelays(at, p.processingDelayNs, p.forwardingDelayNs);
    programFmmus(seg.slave(at).esc(), static_cast<std::uint32_t>(i * p.bytesPerSlave),
                 p.bytesPerSlave);
  }
  ECSIM_TRY(wire(seg, p));
  seg.setMasterCable(p.masterCableMetres);
  seg.slave(0).esc().pdiWrite16(reg::kConfiguredStationAddress.address, 0x1001);

  // The cyclic frames: LRW pieces of the image, the FRMW 0x0910 in the first frame (the
  // reference clock is the first slave, coupler included, as masters choose it).
  const std::size_t image = p.slaves * p.bytesPerSlave;
  const std::size_t room = kMaxFrameSize - kEthernetHeaderSize - kEtherCatHeaderSize;
  std::vector<std::array<std::uint8_t, kMaxFrameSize>> frames;
  std::vector<std::size_t> lengths;
  std::vector<std::uint16_t> expectedWkc;
  for (std::size_t off = 0; off < image;) {
    const bool withDc = off == 0 && p.distributedClock;
    const std::size_t dc = withDc ? kDatagramOverhead + 8 : 0;
    const std::size_t len = std::min(image - off, room - dc - kDatagramOverhead);
    frames.emplace_back();
    FrameBuilder b(frames.back(), EthernetHeader{});
    ECSIM_TRY(b.add(Command::kLrw, 0x80, static_cast<std::uint32_t>(off),
                    static_cast<std::uint16_t>(len)));
    if (withDc) {
      ECSIM_TRY(b.add(Command::kFrmw, 0x80,
                      DatagramHeader::physical(0x1001, reg::kSystemTime.address), 8));
    }
    ECSIM_ASSIGN_OR_RETURN(std::size_t total, b.finish());
    lengths.push_back(total);
    // Slaves whose bytes lie in this piece answer +3 each (write and read FMMU hit).
    const std::size_t first = off / p.bytesPerSlave;
    const std::size_t last = (off + len - 1) / p.bytesPerSlave;
    expectedWkc.push_back(static_cast<std::uint16_t>(3 * (last - first + 1)));
    off += len;
  }
  std::vector<std::array<std::uint8_t, kMaxFrameSize>> templates = frames;

  StudyPoint point;
  point.parameters = p;
  point.framesPerCycle = frames.size();
  SimTime wireOccupancy = 0;
  for (std::size_t len : lengths) {
    point.frameBytes += len;
    wireOccupancy += static_cast<SimTime>(std::max(len, kMinFrameSize) + kFrameOverheadOnWire) * 80;
  }
  SimTime cycleStart = 0;
  const SimTime cpuStart = cpuClock.now();
  for (int r = 0; r < p.repetitions; ++r) {
    SimTime sendAt = cycleStart;
    SimTime lastBack = cycleStart;
    bool wkcOk = true;
    for (std::size_t k = 0; k < frames.size(); ++k) {
      frames[k] = templates[k];
      Bytes f(frames[k].data(), lengths[k]);
      FrameOutcome out = seg.processFrame(f, sendAt);
      lastBack = std::max(lastBack, out.returnTime);
      auto parsed = EtherCatFrame::parse(f);
      if (!parsed.ok() || (*parsed->begin()).wkc() != expectedWkc[k]) wkcOk = false;
      sendAt +=
          static_cast<SimTime>(std::max(lengths[k], kMinFrameSize) + kFrameOverheadOnWire) * 80;
    }
    if (!wkcOk) ++point.wkcErrors;
    point.roundTripNs = lastBack - cycleStart;
    cycleStart += std::max<SimTime>(point.roundTripNs, wireOccupancy) + 10 * kNsPerUs;
  }
  point.simCpuNsPerCycle = static_cast<double>(cpuClock.now() - cpuStart) / p.repetitions;
  point.minCycleNs = std::max(point.roundTripNs, wireOccupancy);
  return point;
}

namespace {

// EBUS terminals side by side behind an EK1100-like coupler (100BASE-TX in, EBUS out): the
// coupler's processing passage is PHY receive + an EBUS passage, its forwarding passage an
// EBUS passage + PHY transmit (slavesim/esc_type.hpp). No DC datagram: the figures are about
// process data.
StudyParameters terminalsBehindCoupler(std::size_t terminals, std::uint16_t bytes) {
  StudyParameters p;
  p.slaves = terminals;
  p.bytesPerSlave = bytes;
  p.cableMetres = 0.0;
  p.masterCableMetres = 1.0;
  p.processingDelayNs = slavesim::kPassageEbusNs;
  p.forwardingDelayNs = slavesim::kPassageEbusNs;
  p.distributedClock = false;
  p.coupler = true;
  p.couplerProcessingDelayNs = slavesim::kPhyReceiveNs + slavesim::kPassageEbusNs;
  p.couplerForwardingDelayNs = slavesim::kPassageEbusNs + slavesim::kPhyTransmitNs;
  p.repetitions = 2;
  return p;
}

constexpr std::string_view kHighlights =
    "Beckhoff Information System, EtherCAT highlights "
    "(infosys.beckhoff.com/content/1033/b110_ethercat_optioninterface/1979661579.html)";

}  // namespace

std::vector<PublishedFigure> publishedFigures() {
  // One digital I/O is one bit of the image (1486 bytes ~ 12,000 I/O in the same source), so
  // 16-channel digital terminals carry 2 bytes; 4-channel 16-bit analog terminals 8 bytes.
  return {
      {"256 digital I/O", "coupler + 16 x 16-channel digital EBUS terminals (32 B)", kHighlights,
       12 * kNsPerUs, terminalsBehindCoupler(16, 2)},
      {"1000 digital I/O", "coupler + 63 x 16-channel digital EBUS terminals (126 B)", kHighlights,
       30 * kNsPerUs, terminalsBehindCoupler(63, 2)},
      {"200 analog I/O (16 bit)", "coupler + 50 x 4-channel analog EBUS terminals (400 B)",
       kHighlights, 50 * kNsPerUs, terminalsBehindCoupler(50, 8)},
      {"100 servo axes, 8 B in + out each", "coupler + 100 EBUS servo terminals, 8 B each (800 B)",
       kHighlights, 100 * kNsPerUs, terminalsBehindCoupler(100, 8)},
      {"12,000 digital I/O (one full frame)",
       "coupler + 743 x 16-channel digital EBUS terminals (1486 B)", kHighlights, 350 * kNsPerUs,
       terminalsBehindCoupler(743, 2)},
  };
}

}  // namespace ecsim::topology
