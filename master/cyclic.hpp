// Cyclic process-data exchange from cached frames. build() makes the frames of a layout once
// (allocating): its datagrams (LRWs planned by the master, or an ENI's cyclic Cmds of any
// command) that are active in the bus state set by setState(); afterwards a cycle is
//
//   send(image)     abandon any frame of the last cycle still unanswered (it counts as lost),
//                   copy the output bytes of the image into the frames, send each under a
//                   fresh index
//   ...             the transport receives the answers into the frames' receive buffers
//   finish(image)   copy the input bytes of every answered frame into the image, compare each
//                   datagram's WKC with its expected value; a mismatch names the datagram and
//                   the slaves it touches (a view into the layout: nothing is allocated)
//
// Neither send() nor finish() allocates. setState() rebuilds the frames (allocating) when the
// set of datagrams active in the new state differs.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "master/histogram.hpp"
#include "master/process_image.hpp"
#include "master/transport.hpp"

namespace ecsim::master {

struct WkcMismatch {
  std::size_t datagram{0};  // index into the layout's datagrams
  Command command{Command::kLrw};
  std::uint32_t logicalStart{0};  // the address field (LogicalDatagram::logicalStart)
  std::uint16_t length{0};
  std::uint16_t expected{0};
  std::uint16_t actual{0};
  std::span<const std::size_t> slaves;  // positions of the slaves the datagram touches
  int line{0};                          // the ENI line of its Cmd (0: planned by the master)
  // "LRW 0x00000000+16: working counter 4, expected 6; slaves 0 (0x1001 'A'), 2 (...)";
  // "BRD 0x0000:0x0130+2: ..." for a physical or broadcast address (ADP:ADO); an ENI Cmd adds
  // "(ENI line N)" after the address.
  std::string describe(const std::vector<SlaveInfo>& slaveInfos) const;
};

struct CycleResult {
  std::size_t framesAnswered{0};
  std::size_t framesLost{0};  // unanswered when the cycle was finished
  std::size_t wkcErrors{0};   // datagrams answered with a WKC other than expected
  std::size_t framesLate{0};  // answered, but later than the deadline (setTiming)
  std::optional<WkcMismatch> firstMismatch;
  SimTime maxRoundTrip{0};
  bool ok() const { return framesLost == 0 && wkcErrors == 0; }
};

struct CyclicStatistics {
  std::uint64_t cycles{0};
  std::uint64_t framesSent{0};
  std::uint64_t framesLost{0};
  std::uint64_t wkcErrors{0};         // datagrams
  std::uint64_t cyclesWithErrors{0};  // lost frame or WKC error
  std::uint64_t roundTrips{0};
  SimTime roundTripMin{0};
  SimTime roundTripMax{0};
  SimTime roundTripSum{0};
  SimTime roundTripMean() const {
    return roundTrips == 0 ? 0 : roundTripSum / static_cast<SimTime>(roundTrips);
  }
  std::uint64_t framesLate{0};  // answered after the deadline (setTiming)
  // Every answered frame's round trip, and each cycle's start-to-start deviation from the
  // nominal period (setTiming): fixed buckets, filled without allocating.
  LatencyHistogram roundTrip;
  LatencyHistogram jitter;
};

class CyclicExchange {
 public:
  CyclicExchange() = default;
  CyclicExchange(const CyclicExchange&) = delete;
  CyclicExchange& operator=(const CyclicExchange&) = delete;

  // Builds the frames of `layout` (which must outlive this object). Any previous frames are
  // dropped.
  Status build(const ProcessImageLayout& layout, const MacAddress& source);
  bool built() const { return layout_ != nullptr; }
  // Sends from now on the datagrams active in `state` (LogicalDatagram::states); before the
  // first call every datagram is. kState while a frame is in flight.
  Status setState(AlState state);
  // False for a datagram left out in the current state.
  bool active(std::size_t datagram) const { return datagrams_[datagram].active; }
  std::size_t frameCount() const { return frames_.size(); }
  const CachedFrame& frame(std::size_t n) const { return *frames_[n]; }

  // `image` is the whole process image (layout.size() bytes).
  Status send(Transport& transport, ConstBytes image, SimTime now);
  // True while a frame of this cycle is in flight.
  bool pending() const;
  CycleResult finish(Bytes image);

  const CyclicStatistics& statistics() const { return statistics_; }
  void resetStatistics() {
    statistics_ = {};
    lastSend_.reset();
  }
  // The nominal cycle period (for jitter; 0: no jitter recorded) and the deadline after which
  // an answered frame counts as late (0: none).
  void setTiming(SimTime period, SimTime deadline) {
    period_ = period;
    deadline_ = deadline;
    lastSend_.reset();
  }

  // Distributed clocks (master/dc.hpp): with a reference clock's station address, build()
  // appends to the first frame an FRMW of its system time 0x0910 (8 bytes), so every cycle
  // distributes the reference time and drives the slaves' drift control loops. nullopt: none.
  // A layout that has its own FRMW/ARMW of 0x0910 (an ENI's) uses that one instead.
  void setDcReference(std::optional<std::uint16_t> station) { dcReference_ = station; }
  // The reference clock's system time carried back by the last answered frame (nullopt while
  // the distribution is held).
  std::optional<std::uint64_t> dcSystemTime() const;
  // Hold the distribution while the reference clock's time cannot be trusted (it was
  // power-cycled and has not been given its offset back): the FRMW/ARMW is sent as a NOP, which
  // no slave executes, so the others' drift loops are not driven by a clock that started over;
  // they run on with what they learnt. A held datagram's WKC is not checked. Takes effect
  // from the next send().
  void holdDcDistribution(bool hold) { dcHeld_ = hold; }
  bool dcDistributionHeld() const { return dcHeld_; }

  // The WKCs a datagram is accepted with: the layout's expected value, unless widened or
  // lowered (recovery does, while slaves are missing or being reconfigured);
  // resetExpectedWkcs() restores the layout's values.
  std::uint16_t expectedWkc(std::size_t datagram) const { return expectedMin_[datagram]; }
  void setExpectedWkc(std::size_t datagram, std::uint16_t min, std::uint16_t max) {
    expectedMin_[datagram] = min;
    expectedMax_[datagram] = max;
  }
  void resetExpectedWkcs();
  // The WKC datagram `datagram` came back with in the last finished cycle (nullopt: lost).
  std::optional<std::uint16_t> receivedWkc(std::size_t datagram) const;

 private:
  struct Copy {
    std::size_t frame{0};
    std::size_t frameOffset{0};  // of the data in the frame
    std::uint32_t imageOffset{0};
    std::uint32_t length{0};
  };
  struct DatagramRef {
    std::size_t frame{0};
    std::size_t index{0};  // within the frame
    bool active{true};
  };
  Status assemble();
  // The FRMW distributing the reference's system time, appended to `builder`'s frame (the
  // next frame to be kept) as its datagram `k`.
  Status addDcDistribution(FrameBuilder& builder, std::size_t& k);
  bool isActive(const LogicalDatagram& d) const { return !state_ || d.activeIn(*state_); }

  const ProcessImageLayout* layout_{nullptr};
  std::vector<std::unique_ptr<CachedFrame>> frames_;
  std::vector<DatagramRef> datagrams_;  // parallel to layout_->datagrams
  std::vector<Copy> outputs_;
  std::vector<Copy> inputs_;
  std::vector<std::uint16_t> expectedMin_;  // parallel to layout_->datagrams
  std::vector<std::uint16_t> expectedMax_;
  CyclicStatistics statistics_{};
  SimTime period_{0};
  SimTime deadline_{0};
  std::optional<SimTime> lastSend_;
  std::optional<std::uint16_t> dcReference_;
  std::optional<DatagramRef> dcDatagram_;     // the FRMW/ARMW of the reference's system time
  std::uint8_t dcCommand_{0};                 // its command byte (FRMW or ARMW)
  std::optional<std::size_t> dcLayoutIndex_;  // its layout datagram, for an ENI's own
  bool dcHeld_{false};
  MacAddress source_{};
  std::optional<AlState> state_;
};

}  // namespace ecsim::master
