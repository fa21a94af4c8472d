// The bus scan as a non-blocking state machine (the sequence of notes/soem-interop.md §3.3,
// stepped IgH-style):
//
//   count       BRD 0x0000; the WKC is the number of slaves
//   defaults    BWR: AL control INIT + acknowledge, DL control loop bytes, event mask, error
//               counters, FMMU0-2 and SM0-3 cleared, DC activation / system time / filters
//               reset, EEPROM handed to the EtherCAT side (0x0500 = 2 then 0)
//   addresses   APWR 0x0010 = firstStation + position, one per slave
//   registers   FPRD per slave: ESC information 0x0000-0x0009, alias 0x0012, DL status
//               0x0110, AL status and code 0x0130-0x0135, AL event request 0x0220, EEPROM
//               control 0x0502
//   identify    the reset asked for every Explicit Device ID (AL control bit 5): AL status
//               and 0x0220 read again for the slaves whose firmware has not yet read AL
//               control, until it has (bit 0 of 0x0220 clear) and shows the ID or not, at
//               most ScanOptions::identifyWait
//   SII         every slave's EEPROM at once (one SiiReader each; their datagrams share
//               frames), then parsed: identity, name, mailbox, categories. A pass steps only
//               the readers whose datagram came back or whose poll interval is over, in
//               slave order (as stepping every reader would, but without looking at the
//               thousands still waiting: that made the scan quadratic in the slaves)
//
// The topology (each slave's parent) follows from the DL status of every slave in processing
// order: a port counts when its loop is open and it has communication.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <queue>
#include <utility>
#include <vector>

#include "master/batch.hpp"
#include "master/bus.hpp"
#include "master/sii_reader.hpp"
#include "master/slave_info.hpp"
#include "master/transport.hpp"

namespace ecsim::master {

struct ScanOptions {
  std::uint16_t firstStation{0x1001};
  bool resetToDefaults{true};
  bool readSii{true};
  SiiReaderOptions sii;
  // The frame timeout this network needs, known once the slaves are counted: timeoutMargin
  // times the count frame's measured round trip plus the wire time a full-size frame takes
  // beyond the count frame (ESCs forward as the bits arrive, so only the frame's length adds;
  // docs/timing.md). With adaptTimeout the transport's timeout is raised to it when shorter
  // (before the scan's own per-slave frames); ScanTask::timeoutAdvice() says it either way.
  bool adaptTimeout{true};
  double timeoutMargin{2.0};
  // Likewise the frames in flight: a line whose round trip is T holds T / (a full frame's wire
  // time) frames at once, and fewer in flight leave it idle for most of each round trip (a
  // 65,535-slave line, 131 ms, holds over 1,000; SOEM's 16 would make its scan take minutes of
  // bus time). With adaptFramesInFlight the transport may keep that many (at most 255) in
  // flight. The scan's own timeout (the caller's, through runTask) grows by the factor the
  // needed frame timeout exceeds the default one: it is meant for a network whose frames fit
  // the default.
  bool adaptFramesInFlight{true};
  // How long the scan waits for firmware to take the ID request (a slave whose firmware does
  // not read AL control in that time is recorded without an ID).
  SimTime identifyWait{100 * kNsPerMs};
};

// What the count told about the frame timeout (ScanOptions::adaptTimeout).
struct TimeoutAdvice {
  std::size_t slaves{0};
  SimTime roundTrip{0};          // of the count frame, measured
  SimTime needed{0};             // timeoutMargin x (roundTrip + a full frame's extra wire time)
  SimTime before{0};             // the transport's timeout when the count came back
  bool raised{false};            // the transport's timeout was set to `needed`
  std::size_t framesFitting{0};  // full-size frames the line holds during one round trip
  std::size_t framesBefore{0};   // the transport's frames in flight when the count came back
  bool framesRaised{false};      // the transport may now keep min(framesFitting, 255) in flight
};

class ScanTask final : public Task {
 public:
  ScanTask(Transport& transport, std::vector<SlaveInfo>& slaves, ScanOptions options = {});

  void start(SimTime now);
  bool step(SimTime now) override;
  std::optional<SimTime> wakeAt() const override;
  double timeoutScale() const override;
  const Status& status() const { return status_; }
  // Set once the slaves are counted.
  const std::optional<TimeoutAdvice>& timeoutAdvice() const { return advice_; }

 private:
  enum class State {
    kIdle,
    kCount,
    kDefaults,
    kAddresses,
    kRegisters,
    kIdentify,
    kSii,
    kDone,
    kFailed
  };

  void adviseTimeout();
  void queueDefaults();
  void queueAddresses();
  void queueRegisters();
  void takeRegisters(SimTime now);
  void queueIdentify();
  bool takeIdentify(SimTime now);
  void startSii(SimTime now);
  bool stepSii(SimTime now);
  void afterStep(std::uint32_t reader);
  void finishSii();
  bool fail(Status status);

  Transport& transport_;
  std::vector<SlaveInfo>& slaves_;
  ScanOptions options_;
  State state_{State::kIdle};
  Status status_;
  Datagram count_;
  DatagramBatch batch_;
  std::deque<SiiReader> readers_;
  // Readers waiting for their datagram, in the order they queued it (the transport sends in
  // that order, so those still waiting for room in a frame are at the end).
  std::deque<std::uint32_t> awaiting_;
  // Readers waiting for their poll interval, earliest first.
  using Timer = std::pair<SimTime, std::uint32_t>;
  std::priority_queue<Timer, std::vector<Timer>, std::greater<>> timers_;
  std::vector<std::uint32_t> ready_;     // scratch: the readers a pass steps
  std::vector<std::uint32_t> inFlight_;  // scratch: readers whose frame is on the wire
  std::size_t siiRunning_{0};
  std::optional<TimeoutAdvice> advice_;
  // Slaves whose firmware has not yet taken the ID request of the reset, and until when the
  // scan waits for them.
  std::vector<std::size_t> identifying_;
  SimTime identifyUntil_{0};
};

// Each slave's active ports from its DL status, and its parent from the active ports of all
// slaves in processing order (ports are visited 0 -> 3 -> 1 -> 2, depth first).
void computeTopology(std::vector<SlaveInfo>& slaves);
// Fills name, mailbox and contents from slave.sii (lenient parse; damage is kept).
void applySii(SlaveInfo& slave);

}  // namespace ecsim::master
