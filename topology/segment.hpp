// A network segment: slaves wired port to port, reached by the master at slave 0's port 0.
// processFrame() carries one frame through the wiring exactly as EtherCAT does: entering a
// slave at port 0 it passes the processing unit, then leaves through the next open port in the
// order 0->3->1->2 (closed or unconnected ports loop back inside the ESC), and comes back out
// of port 0 towards the master. Each hop's timing (wire time, cable, ESC delay) is modelled so
// DC receive-time latches and the frame's return time follow the topology.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "protocol/bytes.hpp"
#include "protocol/frame.hpp"
#include "protocol/result.hpp"
#include "protocol/time.hpp"
#include "slavesim/slave.hpp"

namespace ecsim::topology {

constexpr unsigned kPortCount = 4;
constexpr int kNoSlave = -1;

struct PortLink {
  int slave{kNoSlave};   // neighbour slave index, or kNoSlave
  std::uint8_t port{0};  // neighbour's port
  double cableMetres{1.0};
};

// Timing parameters (see docs/timing.md for sources).
struct TimingModel {
  // 100BASE-TX: 80 ns per byte (section I §9.3); a frame's wire footprint includes preamble +
  // SFD (8 B), FCS (4 B) and the inter-frame gap (12 B).
  SimTime nsPerByte{80};
  double cableNsPerMetre{5.0};
};

// Sees every frame that crosses a cable, as a tap on that cable would: the bytes as they are
// at that point (processed by the slaves the frame has already passed) and the model time at
// which the frame's first bit enters the cable.
class CableObserver {
 public:
  virtual ~CableObserver() = default;
  virtual void onFrame(ConstBytes frame, SimTime time, bool downstream) = 0;
};

// Faults on the wire (topology/faults.hpp), consulted while installed with setWireFaults().
// A frame arriving at `slave`'s port `port` (it has just crossed the cable ending there, in
// either direction) may be corrupted there: that ESC counts an invalid frame, every later ESC
// a forwarded error, no datagram is executed from then on and the master gets nothing.
class WireFaults {
 public:
  virtual ~WireFaults() = default;
  virtual bool corrupts(std::size_t slave, unsigned port, SimTime time) = 0;
  // Extra time the cable ending at (slave, port) takes now (delay spikes). The segment takes
  // at most kMaxWireExtraDelay of it per crossing (and nothing below 0), so a frame's times
  // stay far inside SimTime's range whatever an implementation returns.
  virtual SimTime extraDelay(std::size_t slave, unsigned port, SimTime time) = 0;
};
constexpr SimTime kMaxWireExtraDelay = 3600 * kNsPerSecond;

// The master's ports: the primary one at slave 0's port 0 and, with cable redundancy, the
// second one wired to a free port at the far end of the line (setRedundantPort).
enum class MasterPort : std::uint8_t { kPrimary, kSecondary };

struct FrameOutcome {
  bool delivered{false};  // false: dropped (malformed or lost)
  // The master port the frame comes back at: the one it was sent from, or on a whole
  // redundant ring the other one (it went round the ring).
  MasterPort exit{MasterPort::kPrimary};
  SimTime returnTime{0};  // when the last bit is back at the master
  SimTime firstBitRoundTrip{0};
};

struct SegmentCounters {
  std::uint64_t framesProcessed{0};
  std::uint64_t framesMalformed{0};
  std::uint64_t datagramsProcessed{0};
  std::uint64_t framesAddressedPass{0};  // passed visiting only the ESCs concerned
};

// The slaves and their wiring. A frame passes the ESCs it concerns: with the route recorded
// and no faults, a frame of configured-address and auto-increment datagrams visits only the
// ESCs they address (and those following SM events for the IRQ field), found through an index of
// station addresses and route positions (segment_index.cpp); the firmware runs for the slaves with
// a device or mailbox server and those whose ESC raised events (pollSlaves). Both keep the cost of
// a frame independent of the number of slaves it passes, so bring-up is linear in the network size
// (issue #18).
class Segment final : private slavesim::FirmwarePoller {
 public:
  Segment() = default;
  ~Segment();
  Segment(const Segment&) = delete;
  Segment& operator=(const Segment&) = delete;

  // Adds a slave; returns its index (position in processing order is set by the wiring).
  std::size_t addSlave(std::unique_ptr<slavesim::Slave> slave);
  // Connects a's port pa to b's port pb with a cable of the given length.
  Status connect(std::size_t a, unsigned pa, std::size_t b, unsigned pb, double metres = 1.0);
  // Wires slaves 0..n-1 as a line (port 1 of each to port 0 of the next).
  void wireLine(double metres = 1.0);
  void setMasterCable(double metres) {
    masterCable_ = metres;
    routeValid_ = false;
  }
  // Cable redundancy: `slave`'s free port `port` is wired to the master's second port (the
  // ring closed back to the master, ETG.1000.4 §4.4 "line redundancy"). A frame the master
  // sends there enters that ESC at that port; frames leave the network at whichever master
  // port their way through the ESCs' forwarding ends at (FrameOutcome::exit). Its link is
  // setLinkUp(slave, port, ...), as the master's own cable is (0, 0); `linked` is its state now.
  Status setRedundantPort(std::size_t slave, unsigned port, double metres = 1.0,
                          bool linked = true);
  bool redundant() const { return redSlave_ != kNoSlave; }
  std::size_t redundantSlave() const { return static_cast<std::size_t>(redSlave_); }
  unsigned redundantPortNumber() const { return redPort_; }
  // Observes the cable at `slave`'s port `port` (both directions); nullptr removes it. The
  // cable between the master and slave 0 is (0, 0).
  void setCableObserver(std::size_t slave, unsigned port, CableObserver* observer);
  // A slave's oscillator: local time at simulation time 0 and drift in ppm (+ runs fast).
  void setClock(std::size_t slave, SimTime offset, double driftPpm) {
    slaves_[slave]->esc().dcClock().configure(offset, driftPpm);
  }
  // ESC delays in ns: through the processing unit (port 0 -> next port) and forwarding
  // (any other port -> next port). Defaults come from the slave's ESC type.
  void setDelays(std::size_t slave, SimTime processing, SimTime forwarding);

  std::size_t size() const { return slaves_.size(); }
  slavesim::Slave& slave(std::size_t i) { return *slaves_[i]; }
  const slavesim::Slave& slave(std::size_t i) const { return *slaves_[i]; }
  const std::array<PortLink, kPortCount>& ports(std::size_t i) const { return links_[i]; }

  // Processes a frame in place. sendTime is when its first bit leaves the master (from its
  // port `entry`). A frame that is not a valid EtherCAT frame is left untouched, counted and
  // reported as dropped; so is one sent from the second port of a master without redundancy.
  FrameOutcome processFrame(Bytes frame, SimTime sendTime, MasterPort entry = MasterPort::kPrimary);
  // For a server with time to spare before the next frame: asks the cache for the state of up
  // to `count` ESCs from `first` on (Esc::prefetchForNextFrame, with the last frame's first
  // physical ADO) and returns where the next call goes on. On this project's virtual machines
  // a system call leaves the next frame's pass 40-60 % slower at 100-1000 slaves until it has
  // touched every ESC once more; a pass of this before the frame arrives makes up for it
  // (docs/served-path.md).
  std::size_t prefetchForNextFrame(std::size_t first, std::size_t count) const;
  // Runs every slave's firmware (call after frames and on the device tick).
  void pollSlaves(SimTime now);

  // Updates each slave's DL status (0x0110) from the wiring and port states.
  void refreshLinkStatus();
  // The same for one slave (its ports' states depend on its neighbours' link flags only).
  void refreshLinkStatus(std::size_t slave);
  // Opens or closes a port (a pulled cable closes both ends' links).
  void setLinkUp(std::size_t slave, unsigned port, bool up);

  // Installs (nullptr: removes) the wire faults; the caller keeps them alive.
  void setWireFaults(WireFaults* faults) { faults_ = faults; }

  const SegmentCounters& counters() const { return counters_; }
  // Frames slave i's ESC has seen (EscCounters::framesSeen plus the frames that passed it on
  // the recorded route without a visit).
  std::uint64_t framesSeen(std::size_t i) const;
  // Off: every frame visits every ESC on its way, as before the index (for tests comparing
  // the two; the results are the same).
  void setIndexedPasses(bool on) { indexedPasses_ = on; }
  const TimingModel& timing() const { return timing_; }
  void setTiming(const TimingModel& t) {
    timing_ = t;
    updateCableDelays();
  }

 private:
  bool portOpen(std::size_t slave, unsigned port) const;
  bool portLink(std::size_t slave, unsigned port) const;
  // The port is wired to one of the master's ports: (0, 0), or the redundant one.
  bool masterEnd(std::size_t slave, unsigned port) const {
    return (slave == 0 && port == 0) || (static_cast<int>(slave) == redSlave_ && port == redPort_);
  }
  int redSlave_{kNoSlave};
  std::uint8_t redPort_{0};
  double redCable_{1.0};
  // Loop control (issue #15 item 6): a DL control write seen after a frame at time `now`
  // (bit 1 set: the loop setting is temporary and reverts kTemporaryLoopNs later), and the
  // revert of temporary settings that are due.
  void noteDlControlWrite(std::size_t slave, SimTime now);
  void revertTemporaryLoops(SimTime now);
  static constexpr SimTime kNoRevert = std::numeric_limits<SimTime>::max();
  std::vector<std::uint8_t> lostMask_;       // open ports without a link: frames are lost there
  std::vector<std::uint8_t> loopPermanent_;  // last loop byte written without bit 1
  std::vector<SimTime> loopRevertAt_;        // kNoRevert, or when the temporary setting ends
  SimTime nextLoopRevert_{kNoRevert};
  SimTime cableDelay(double metres) const {
    return static_cast<SimTime>(metres * timing_.cableNsPerMetre + 0.5);
  }

  std::vector<std::unique_ptr<slavesim::Slave>> slaves_;
  std::vector<std::array<PortLink, kPortCount>> links_;
  std::vector<std::array<SimTime, kPortCount>> cableNs_;  // cableDelay() of links_, both ends
  void updateCableDelays();
  std::vector<std::array<bool, kPortCount>> linkUp_;
  std::vector<std::array<SimTime, 2>> delays_;  // processing, forwarding
  std::vector<int> parent_;                     // union-find for the tree check
  std::vector<std::array<SimTime, kPortCount>> arrival_;
  std::vector<std::uint8_t> arrivalMask_;
  std::vector<std::uint8_t> openMask_;
  std::vector<std::array<CableObserver*, kPortCount>> observers_;
  bool anyObserver_{false};
  void notify(std::size_t slave, unsigned port, Bytes frame, SimTime time, bool downstream) {
    if (anyObserver_ && observers_[slave][port] != nullptr) {
      observers_[slave][port]->onFrame(frame, time, downstream);
    }
  }  // ports a frame leaves through, from refreshLinkStatus
  int findRoot(int i);
  double masterCable_{1.0};
  TimingModel timing_{};
  SegmentCounters counters_{};
  WireFaults* faults_{nullptr};
  // With faults installed: the frame has arrived at (s, port) at time t (adds any extra delay
  // to t); returns false once it is corrupted (counted in the ESCs' error counters).
  bool arriveWithFaults(std::size_t s, unsigned port, SimTime& t, bool& bad);
  // Scratch for the datagram views of the frame in flight (no allocation per frame).
  std::array<DatagramView, 128> datagrams_{};
  struct Visit {
    std::uint32_t slave;
    std::uint8_t entryPort;
    std::uint8_t port;  // port at which the frame currently is (received on)
  };
  std::vector<Visit> stack_;
  std::vector<slavesim::Esc*> escs_;    // slaves_[i]->esc(), one indirection less per visit
  std::uint32_t lastPhysicalAdo_{0};    // the last frame's first physical ADO (passRoute)
  std::vector<std::uint32_t> latched_;  // slaves whose receive-time latch this frame armed
  // The path of the last frame without faults, relative to its send time: the ESCs in the
  // order the frame passed their processing units, the first bit's arrival at every port, the
  // first-bit round trip. Valid until the wiring, a port, a delay or the timing changes.
  struct RouteStop {
    std::uint32_t slave;
    SimTime at;  // arrival at port 0
  };
  std::vector<RouteStop> route_;
  // The recorded route with a frame of `count` datagrams (segment_route.cpp). Each ESC
  // processes the datagrams that concern it; a configured-address datagram (FPRD/FPWR/FPRW)
  // is processed only at the ESC it addresses, while the others' event requests still go into
  // its IRQ field: the same frame and ESC state as processing every datagram at every ESC,
  // without a cost per datagram and ESC.
  void passRoute(std::size_t count, const std::array<SimTime, 128>& leads, SimTime sendTime);
  void passRouteIndexed(std::size_t count, const std::array<SimTime, 128>& leads, SimTime sendTime);
  // Scratch of passRouteIndexed, per frame: datagrams every ESC processes, configured-address
  // datagrams by (ADP, index), and per IRQ bit the ESCs asking for it from datagram k on.
  std::array<std::uint8_t, 128> everywhere_{};
  std::array<std::uint32_t, 128> byAddress_{};
  std::array<std::array<std::int32_t, 129>, 16> irqRuns_{};
  // The IRQ bits the ESCs asked for (irqRuns_) go into the datagrams' IRQ fields.
  void applyIrqRuns(std::size_t count);

  // ---- the index of the passes that visit only the ESCs concerned (segment_index.cpp) ----
  // A frame of configured-address (FPRD/FPWR/FPRW), auto-increment (APRD/APWR/APRW) and
  // header-only datagrams along the recorded route, visiting the ESCs addressed and those
  // following SM events; the IRQ bits of the others go into every header. false (nothing done) when
  // a configured address belongs to several ESCs: the caller takes the indexed pass then.
  bool passRouteAddressed(std::size_t count, const std::array<SimTime, 128>& leads,
                          SimTime sendTime);
  // One ESC of that pass at route position `pos`: the datagrams addressed to it, judged with
  // its addressing as it is when each comes (a write may change it).
  void visitAddressed(std::size_t pos, std::size_t count, const std::array<SimTime, 128>& leads,
                      SimTime sendTime);
  // FirmwarePoller: what the slaves tell the segment.
  void escEventsRaised(std::uint32_t id) override;
  void escAddressingChanged(std::uint32_t id) override;
  void escIrqChanged(std::uint32_t id, std::uint16_t irq, bool followsSm) override;
  void firmwareChanged(std::uint32_t /*id*/) override { firmwareDirty_ = true; }
  void indexNewSlave(std::size_t i);  // from addSlave
  // The recorded route changes: the frames it owes its ESCs are counted in, positions renewed.
  void routeChanging();
  void routeRecorded();
  // Brings the address tables up to date (the addressing changes queued since).
  void updateAddressTables();
  void tableAdd(std::uint32_t slave);
  void tableRemove(std::uint32_t slave);
  // Route position + 1 of the single ESC answering `address` (0: none or unknown).
  std::uint32_t ownerOf(std::uint16_t address);
  static constexpr std::uint32_t kOffRoute = 0xFFFFFFFF;
  bool indexedPasses_{true};
  std::vector<std::uint32_t> routePos_;  // per slave: its position in route_, or kOffRoute
  std::uint64_t framesOwed_{0};          // frames that passed route_ by passRouteAddressed
  // Per configured address (65536 entries, made with the first route): how many ESCs on the
  // route answer it, and the route position + 1 of the one that does (0: none or not known).
  std::vector<std::uint32_t> addrCount_;
  std::vector<std::uint32_t> addrOwner_;
  struct Answering {
    std::uint16_t station{0};
    std::uint16_t alias{0};
    bool aliasOn{false};
    bool listed{false};  // counted in the tables
  };
  std::vector<Answering> answering_;  // per slave: what the tables hold for it
  bool tablesValid_{false};
  std::vector<std::uint32_t> addressingQueue_;  // slaves whose addressing changed since
  std::vector<std::uint8_t> addressingQueued_;
  std::uint64_t addressingEpoch_{0};  // counts addressing changes (a pass notices one)
  // IRQ bits: the ESCs following their SyncManagers (visited by every pass), what each of the
  // others ORs into a passing header, and per bit how many ESCs on the route set it.
  std::vector<std::uint32_t> irqSet_;   // slaves following their SMs
  std::vector<std::uint32_t> irqSlot_;  // per slave: index + 1 in irqSet_, 0: not in it
  std::vector<std::uint16_t> irqKnown_;
  std::array<std::uint32_t, 16> irqCount_{};
  void countIrq(std::uint16_t irq, int delta);
  std::vector<std::uint32_t> visits_;         // scratch: route position << 8 | datagram
  std::array<std::uint16_t, 128> adpSent_{};  // scratch: ADP of auto-increment datagrams
  // Firmware polls: the slaves with a device or mailbox server (every poll) and those whose
  // ESC raised events since the last poll.
  std::vector<std::uint32_t> firmwareSlaves_;
  bool firmwareDirty_{true};
  std::vector<std::uint32_t> eventful_;
  std::vector<std::uint32_t> polling_;
  std::vector<std::uint8_t> eventQueued_;
  std::vector<std::array<SimTime, kPortCount>> routeArrival_;
  std::vector<std::uint8_t> routeMask_;
  SimTime routeRoundTrip_{0};
  bool routeValid_{false};
};

}  // namespace ecsim::topology
