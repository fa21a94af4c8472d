// The master's datagram transport over a Link, advanced only by poll(now): no thread, no
// blocking, no clock of its own (the time is handed in).
//
//  - queue(Datagram&): the datagram waits in a FIFO; poll() packs waiting datagrams, in order,
//    into frames of at most 1514 bytes (a datagram that cannot fit any frame is refused with
//    kError, never truncated) and sends them, up to maxFramesInFlight at a time;
//  - every frame in flight has its own index (all its datagrams carry it); an answer is
//    matched by that index and checked against what was sent (length, commands, data
//    lengths) before its data and WKC are copied back into the datagrams;
//  - a frame unanswered after `timeout` is sent again with the same index (as SOEM and IgH
//    do), `retries` times; then its datagrams become kTimedOut and the frame counts as lost;
//  - an answer to a frame already answered or given up counts as late; a frame given up whose
//    answer still arrives (before its index is used again) moves from lost to late: lost means
//    the network never returned it, late that it came back after we stopped waiting. A frame
//    that matches nothing of ours (unknown index, other content, not EtherCAT) is unexpected.
//
// Cable redundancy (setRedundantLink): the far end of the line is wired back to a second
// port. Every frame leaves by the primary link, and beside it a 2-byte BRD of the Type register
// under the same index leaves by the second port, with `secondarySource` as its source address
// (as SOEM does, ecx_outframe_red). A frame entering at an ESC's port 1 passes it unprocessed
// (ESC datasheet section I §3.2), so:
//  - ring whole: our frame comes back at the second port, processed by every slave, and is the
//    answer; the BRD comes back at the primary port with WKC 0 and is dropped;
//  - ring broken: our frame comes back at the primary port, processed by the slaves before the
//    break; it is sent on as it came out of the second port, where the slaves behind the break
//    process it in their order and it comes back, the answer of the whole ring; the BRD comes
//    back at the second port, its WKC the number of slaves reachable from that side;
//  - a frame sent on that is not back by its deadline (nothing behind the second port: its
//    cable pulled, or the break after the last slave) is answered with what came back at the
//    primary port, and frames come back unpassed from then on until the second port delivers
//    a frame again;
//  - the primary port's own cable pulled: the frame is lost on the dead link, and the BRD
//    comes back at the second port having passed every slave (the first slave's port 0 loops
//    it back, and it is processed on its way out again). The frame itself is then sent from
//    the second port, as built, and its answer comes back there: at once when the BRD counted
//    the ring's every slave (setRingSlaveCount: the primary side reaches none), otherwise when
//    the frame's timeout expires with nothing back at the primary port but its BRD back at the
//    second (as SOEM's ecx_waitinframe_red resends the frame there).
// ring() says which of the two the last frame saw.
//
// CachedFrame is the cyclic path: a frame built once by its owner, sent as it is each cycle
// (only its index bytes are rewritten), answered into the frame's own receive buffer. It is
// never retried: a cyclic frame still unanswered when the next cycle starts is abandoned and
// counts as lost. Neither poll() nor send(CachedFrame&) allocates.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "link/link.hpp"
#include "master/datagram.hpp"
#include "protocol/ethernet.hpp"
#include "protocol/frame.hpp"
#include "protocol/time.hpp"

namespace ecsim::master {

struct TransportOptions {
  // Per try; SOEM's EC_TIMEOUTRET is 2 ms (notes/soem-interop.md §3.8).
  SimTime timeout{2 * kNsPerMs};
  // Resends of an unanswered frame (same index); 2 gives SOEM's 3 tries of EC_TIMEOUTRET3.
  unsigned retries{2};
  std::size_t maxFramesInFlight{16};
  // Source address of our frames: locally administered, unicast.
  MacAddress source{0x02, 0x00, 0x00, 0x00, 0xEC, 0x01};
  // Source address of the BRD sent beside every frame from the second port (redundancy).
  MacAddress secondarySource{0x02, 0x00, 0x00, 0x00, 0xEC, 0x02};
};

// What the frames of a redundant master (Transport::setRedundantLink) saw last.
enum class RingState : std::uint8_t {
  kNone,    // no second port, or no frame back yet
  kWhole,   // the last frame came back at the second port: the ring is closed
  kBroken,  // the last frame came back at the primary port: the ring is open somewhere
};
std::string_view toString(RingState state);

struct TransportCounters {
  std::uint64_t framesSent{0};        // first transmissions (acyclic and cyclic)
  std::uint64_t framesResent{0};      // retries with the same index
  std::uint64_t framesReceived{0};    // every frame the link delivered to us
  std::uint64_t framesAnswered{0};    // matched to a frame in flight
  std::uint64_t framesLost{0};        // given up after every try, or abandoned (cyclic), and no
                                      // answer since
  std::uint64_t framesLate{0};        // an answer to a frame already answered or given up
  std::uint64_t framesUnexpected{0};  // not one of ours (index unknown, content differs, ...)
  std::uint64_t datagramsSent{0};
  std::uint64_t datagramsTimedOut{0};
  std::uint64_t datagramsRefused{0};  // too large for any frame
  std::uint64_t sendErrors{0};
  std::uint64_t receiveErrors{0};
  // Redundancy: frames back at the primary port sent on from the second port; of those, the
  // ones not back by their deadline and answered with what came back at the primary port.
  std::uint64_t framesPassedOn{0};
  std::uint64_t passOnsUnanswered{0};
  // Frames sent as built from the second port: the primary port reached no slave.
  std::uint64_t framesSentFromSecond{0};
  std::uint64_t ringBreaks{0};  // RingState turned from whole to broken
};

class Transport;

// A frame built once and sent repeatedly (cyclic process data).
class CachedFrame {
 public:
  CachedFrame() = default;
  CachedFrame(const CachedFrame&) = delete;
  CachedFrame& operator=(const CachedFrame&) = delete;
  ~CachedFrame();

  // The whole transmit buffer, for a FrameBuilder; then commit(length) with what finish()
  // returned. commit() checks the frame and records where its datagrams lie.
  Bytes buildBuffer() { return Bytes(tx_.data(), tx_.size()); }
  Status commit(std::size_t length);

  std::size_t length() const { return length_; }
  std::size_t datagramCount() const { return datagramOffsets_.size(); }
  // Offset of datagram k's header within the frame (its data starts 10 bytes later).
  std::size_t datagramOffset(std::size_t k) const { return datagramOffsets_[k]; }
  Bytes tx() { return Bytes(tx_.data(), length_); }
  ConstBytes tx() const { return ConstBytes(tx_.data(), length_); }
  // The answer (valid when state() == kReceived).
  ConstBytes rx() const { return ConstBytes(rx_.data(), length_); }
  std::uint16_t rxWkc(std::size_t k) const;
  ConstBytes rxData(std::size_t k) const;

  DatagramState state() const { return state_; }
  bool pending() const { return state_ == DatagramState::kSent; }
  SimTime sentAt() const { return sentAt_; }
  SimTime receivedAt() const { return receivedAt_; }

 private:
  friend class Transport;
  std::array<std::uint8_t, kMaxFrameSize> tx_{};
  std::array<std::uint8_t, kMaxFrameSize> rx_{};
  std::size_t length_{0};
  std::vector<std::size_t> datagramOffsets_;
  DatagramState state_{DatagramState::kIdle};
  SimTime sentAt_{0};
  SimTime receivedAt_{0};
  Transport* owner_{nullptr};
};

class Transport {
 public:
  // Most datagrams one frame can hold (empty datagrams of 12 bytes in 1498 bytes).
  static constexpr std::size_t kMaxDatagramsPerFrame = 128;
  // At most 255 frames in flight, so a free index always exists.
  static constexpr std::size_t kMaxFramesInFlight = 255;
  // Most data one datagram can carry in an untagged frame.
  static constexpr std::size_t kMaxDatagramData =
      kMaxFrameSize - kEthernetHeaderSize - kEtherCatHeaderSize - kDatagramOverhead;

  explicit Transport(Link& link, TransportOptions options = {});
  ~Transport();
  Transport(const Transport&) = delete;
  Transport& operator=(const Transport&) = delete;

  // Appends to the send queue (state kQueued). A datagram already queued or in flight is
  // withdrawn first. The datagram must stay alive until it is answered, timed out or cancelled.
  void queue(Datagram& datagram);
  // Withdraws a queued or sent datagram (state back to kIdle); an answer is then ignored.
  void cancel(Datagram& datagram);

  // Sends a cached frame now under a fresh index. kState if it is still in flight, kTooLarge
  // when every frame slot is busy.
  Status send(CachedFrame& frame, SimTime now);
  // Gives up waiting for a cached frame in flight: it counts as lost (an answer still coming
  // counts as late).
  void abandon(CachedFrame& frame);

  // Receives every waiting frame, handles timeouts and retries, sends queued datagrams.
  void poll(SimTime now);
  // Sends queued datagrams only (receives nothing): after a step queued new datagrams, so an
  // answer that arrives meanwhile stays on the link for the next poll() (and wakes a wait on
  // the link's file descriptor).
  void flush(SimTime now) { sendQueued(now); }

  // Nothing queued and nothing in flight.
  bool idle() const { return queueHead_ == nullptr && inFlight_ == 0; }
  std::size_t framesInFlight() const { return inFlight_; }
  // Earliest time a frame in flight times out, if any is in flight.
  std::optional<SimTime> nextDeadline() const;

  const TransportCounters& counters() const { return counters_; }
  const TransportOptions& options() const { return options_; }
  // The per-try timeout of frames sent from now on (the scan raises it for a long network).
  void setTimeout(SimTime timeout) { options_.timeout = timeout; }
  // Raises the number of frames in flight at once to `frames` (at most 255, one index each);
  // never lowers it. The scan raises it for a long network, whose wire holds more frames.
  void allowFramesInFlight(std::size_t frames);
  Link& link() { return link_; }

  // Cable redundancy (see above): `link` is the second port; null: none. Set it before any
  // frame is sent; it must outlive the transport.
  void setRedundantLink(Link* link);
  RingState ring() const { return ring_; }
  // Slaves that answered the last BRD back at the second port: those behind the break, seen
  // from that side (0 while the ring is whole); every slave of the ring when the primary
  // port reaches none.
  std::uint16_t slavesBehindBreak() const { return slavesBehindBreak_; }
  // How many slaves the ring has (the master sets it after its scan; 0: unknown). A BRD back
  // at the second port counting that many means the primary port reaches no slave, and the
  // frame goes out of the second port without waiting for its timeout.
  void setRingSlaveCount(std::uint16_t slaves) { ringSlaves_ = slaves; }

 private:
  friend class CachedFrame;
  enum class IndexState : std::uint8_t { kUnused, kInFlight, kClosed, kGivenUp };
  struct Slot {
    bool busy{false};
    std::uint8_t index{0};
    std::array<std::uint8_t, kMaxFrameSize> buffer{};
    std::size_t length{0};
    SimTime deadline{0};
    unsigned triesLeft{0};
    std::array<Datagram*, kMaxDatagramsPerFrame> datagrams{};
    std::size_t datagramCount{0};
    CachedFrame* cached{nullptr};
    // Redundancy: the frame came back at the primary port and was sent on; what came back
    // (length 0: sent as built from the second port, the primary port reaching no slave).
    bool passedOn{false};
    bool brdAtSecondary{false};  // its BRD came back at the second port
    std::array<std::uint8_t, kMaxFrameSize> cameBack{};
    std::size_t cameBackLength{0};
  };
  enum class Port : std::uint8_t { kPrimary, kSecondary };

  void receiveAll(SimTime now);
  void receiveFrom(Link& link, Port port, SimTime now);
  void handleFrame(std::size_t length, SimTime now, Port port);
  // Redundancy: a frame of ours (not the BRD) back at the primary port. True when it was sent
  // on from the second port (the answer is still to come).
  bool passOn(Slot& slot, std::size_t length, SimTime now);
  // Redundancy: sends the slot's frame as built from the second port (the primary port
  // reaches no slave). True when sent.
  bool sendFromSecond(Slot& slot, SimTime now);
  void markBroken();
  // The BRD beside a frame; true when `length` bytes in rx_ are one (taken care of).
  bool takeSecondaryBrd(std::size_t length, Port port, SimTime now);
  // Sends a frame (first time or again) out of the primary link, and the BRD beside it.
  void transmit(ConstBytes frame, std::uint8_t index);
  // Copies an answer in rx_ (`length` bytes) into the slot's datagrams or cached frame and
  // frees the slot.
  void deliver(Slot& slot, ConstBytes answer, SimTime now);
  bool answerMatches(const Slot& slot, ConstBytes tx, ConstEtherCatFrame& answer) const;
  void checkTimeouts(SimTime now);
  void sendQueued(SimTime now);
  bool packFrame(Slot& slot, SimTime now);
  std::optional<std::uint8_t> takeIndex();
  Slot* freeSlot();
  void release(Slot& slot, DatagramState datagramState);
  void unlinkQueued(Datagram& datagram);
  void detachCached(CachedFrame& frame);
  ConstBytes slotTx(const Slot& slot) const;

  Link& link_;
  TransportOptions options_;
  TransportCounters counters_{};
  EthernetHeader ethernet_{};
  std::vector<Slot> slots_;
  std::size_t inFlight_{0};
  std::array<IndexState, 256> indexState_{};
  std::array<std::int16_t, 256> indexSlot_{};
  std::uint8_t nextIndex_{0};
  Datagram* queueHead_{nullptr};
  Datagram* queueTail_{nullptr};
  std::array<std::uint8_t, kMaxFrameSize> rx_{};
  Link* redundant_{nullptr};
  std::array<std::uint8_t, kMaxFrameSize> brd_{};  // the BRD sent from the second port
  std::size_t brdLength_{0};
  bool secondaryDelivers_{false};  // a frame came in by the second port since the last miss
  RingState ring_{RingState::kNone};
  std::uint16_t slavesBehindBreak_{0};
  std::uint16_t ringSlaves_{0};
};

}  // namespace ecsim::master
