// The real-time driver: the step-driven master on three threads, as a user-space real-time
// master runs on Linux (or Xenomai). Highest priority first:
//
//   send/receive  woken by the cyclic task each period; runs Master::cycle(): the cached
//                 frames out, the answers in (sleeping on the link's descriptor), WKC check,
//                 health, one recovery step
//   control       every controlPeriod: copies statistics, health and new events into a
//                 snapshot for the non-real-time world (a UI, a logger), so that nothing
//                 outside these threads ever touches the master while it runs
//   cyclic task   sleeps with clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME) to the next
//                 period, measures how late it woke, runs the application (outputs from
//                 inputs, under the master lock), then hands the cycle to send/receive and
//                 waits for it
//
// Threads are created SCHED_FIFO at the given priorities and memory is locked (mlockall)
// where the process may (root, CAP_SYS_NICE / CAP_IPC_LOCK, or rtprio/memlock limits);
// otherwise they run as ordinary threads and warnings() says so, once, clearly. The master
// core stays what it is: the same Master runs on virtual time in tests without this driver.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "master/health.hpp"
#include "master/histogram.hpp"
#include "master/master.hpp"

namespace ecsim::master {

struct RtDriverOptions {
  SimTime period{kNsPerMs};
  int sendReceivePriority{80};  // SCHED_FIFO 1..99
  int controlPriority{70};
  int cyclicPriority{60};
  bool lockMemory{true};
  SimTime controlPeriod{100 * kNsPerMs};
};

// What the control thread last copied out of the master.
struct RtSnapshot {
  std::uint64_t cycles{0};  // run by the driver
  std::uint64_t failedCycles{0};
  std::uint64_t overruns{0};  // the cycle did not finish within its period
  std::string firstError;
  CyclicStatistics statistics;
  MasterHealth health;
  std::vector<MasterEvent> events;  // all events so far
  LatencyHistogram wakeLatency;     // how late the cyclic task woke, per cycle
};

class RtDriver {
 public:
  // Runs every cycle in the cyclic task, with the master locked: write outputs, read inputs.
  using Application = std::function<void(Master& master, std::uint64_t cycle)>;

  RtDriver(Master& master, RtDriverOptions options = {});
  ~RtDriver();
  RtDriver(const RtDriver&) = delete;
  RtDriver& operator=(const RtDriver&) = delete;

  // Starts the three threads (the master must be in OP: start() first). kState when running.
  Status start(Application application = {});
  // Stops after the cycle in progress and joins the threads.
  void stop();
  bool running() const { return running_.load(); }

  // True when all three threads got SCHED_FIFO.
  bool realtime() const { return realtime_; }
  bool memoryLocked() const { return memoryLocked_; }
  // "real-time scheduling not available (Operation not permitted): ..." and the like.
  const std::vector<std::string>& warnings() const { return warnings_; }

  RtSnapshot snapshot() const;

 private:
  void sendReceiveLoop();
  void controlLoop();
  void cyclicLoop();
  void takeSnapshot();
  // Starts `loop` on `thread` and asks for SCHED_FIFO `priority`: 0 or the error number.
  int spawn(std::thread& thread, int priority, void (RtDriver::*loop)(), const char* name);

  Master& master_;
  RtDriverOptions options_;
  Application application_;
  std::atomic<bool> running_{false};
  std::atomic<bool> stopping_{false};
  bool realtime_{false};
  bool memoryLocked_{false};
  std::vector<std::string> warnings_;

  std::mutex masterLock_;  // the master and its process image
  std::mutex handoffLock_;
  std::condition_variable handoff_;
  std::uint64_t requested_{0};  // cycles handed to send/receive
  std::uint64_t completed_{0};  // cycles it finished
  bool cyclicDone_{false};      // the cyclic task has ended (no more requests)

  mutable std::mutex snapshotLock_;
  RtSnapshot snapshot_;
  std::atomic<std::uint64_t> failedCycles_{0};
  std::atomic<std::uint64_t> overruns_{0};
  std::string firstError_;        // under snapshotLock_
  LatencyHistogram wakeLatency_;  // under masterLock_

  std::thread sendReceive_;
  std::thread control_;
  std::thread cyclic_;
};

}  // namespace ecsim::master
