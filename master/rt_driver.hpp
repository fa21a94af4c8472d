// The real-time driver: the step-driven master on three threads, as a user-space real-time
// master runs on Linux (or Xenomai). Highest priority first:
//
//   send/receive  woken by the cyclic task each period; only I/O: Master::sendCycle() (the
//                 cached frames and whatever datagrams are queued go out), pollCycle() until
//                 the answers are in (sleeping on the link's descriptor, through the Bus, in
//                 between), finishCycle() (inputs, WKC check). Nothing else: no health, no
//                 recovery, no allocation
//   control       after every finished cycle (or at most once per controlPeriod):
//                 Master::control(), i.e. the state machines: AL status reads, lost and
//                 returning slaves, one recovery step; the datagrams it queues go out with the
//                 next cyclic send, as IgH's master thread queues datagrams that the
//                 application's send carries. Then it steps the acyclic tasks posted while
//                 running (an SDO, a register read: post()). Every snapshotPeriod it copies
//                 statistics, health and new events into a snapshot for the non-real-time world (a
//                 UI, a logger), so that nothing outside these threads touches the master while it
//                 runs
//   cyclic task   sleeps with clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME) to the next
//                 period, measures how late it woke, runs the application (outputs from
//                 inputs), then hands the cycle to send/receive and waits for it
//
// One lock, the master lock, guards the Master: its Transport (not thread-safe), cyclic
// frames, health monitor and process image. Every step above runs under it and none blocks;
// send/receive waits for frames outside it. It is a priority-inheritance mutex, so the
// control thread or the cyclic task holding it runs at send/receive's priority while that
// waits for it.
//
// Threads are created SCHED_FIFO at the given priorities and memory is locked (mlockall)
// where the process may (root, CAP_SYS_NICE / CAP_IPC_LOCK, or rtprio/memlock limits);
// otherwise they run as ordinary threads and warnings() says so, once, clearly. With
// RtDriverOptions::cpu all three are pinned to that CPU. The bus given to the Master is used
// by send/receive only (the control thread steps with the time the last cycle finished), so a
// VirtualBus works too; the same Master runs on virtual time in tests without this driver.
#pragma once

#include <pthread.h>

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
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
  // Master::control() after every finished cycle (0) or at most once per this period.
  SimTime controlPeriod{0};
  // How often the control thread copies the snapshot.
  SimTime snapshotPeriod{100 * kNsPerMs};
  // Pins all three threads to this CPU (sched affinity); nullopt: the kernel decides.
  std::optional<int> cpu;
};

// What the control thread last copied out of the master.
struct RtSnapshot {
  std::uint64_t cycles{0};  // run by the driver
  std::uint64_t failedCycles{0};
  std::uint64_t overruns{0};      // the cycle did not finish within its period
  std::uint64_t controlSteps{0};  // Master::control() calls by the control thread
  std::string firstError;
  CyclicStatistics statistics;
  MasterHealth health;
  std::vector<MasterEvent> events;  // all events so far
  LatencyHistogram wakeLatency;     // how late the cyclic task woke, per cycle
};

// One of the driver's threads as the kernel sees it (RtDriver::threads()).
struct RtThreadInfo {
  std::string name;  // "ec-sendrecv", "ec-control", "ec-cyclic"
  int policy{0};     // SCHED_FIFO, SCHED_OTHER, ...
  int priority{0};
  std::vector<int> cpus;  // the CPUs it may run on
};

// A mutex with priority inheritance (PTHREAD_PRIO_INHERIT); BasicLockable, for
// std::lock_guard / std::unique_lock.
class PiMutex {
 public:
  PiMutex();
  ~PiMutex();
  PiMutex(const PiMutex&) = delete;
  PiMutex& operator=(const PiMutex&) = delete;
  void lock();
  void unlock();

 private:
  pthread_mutex_t mutex_;
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
  // Stops after the cycle in progress (whose control step still runs) and joins the threads.
  void stop();
  bool running() const { return running_.load(); }

  // True when all three threads got SCHED_FIFO.
  bool realtime() const { return realtime_; }
  bool memoryLocked() const { return memoryLocked_; }
  // "real-time scheduling not available (Operation not permitted): ..." and the like.
  const std::vector<std::string>& warnings() const { return warnings_; }
  // Send/receive, control, cyclic task, read back from the kernel (empty when not running).
  std::vector<RtThreadInfo> threads() const;

  RtSnapshot snapshot() const;

  // Acyclic work while the driver runs (an SdoTask, a register read): the control thread calls
  // `step` after each control step, under the master lock, until it returns false. It starts
  // and steps its tasks there (on master.transport()); their datagrams go out with the next
  // cycles. `step` is destroyed on the control thread too, under the lock, so that the tasks it
  // owns never touch the transport outside it. Returns at once; kState when the driver is not
  // running. Work still unfinished at stop() is destroyed unfinished.
  //
  //   auto sdo = std::make_shared<SdoTask>(master.transport(), slave, nullptr);
  //   driver.post([sdo, started = false](Master&, SimTime now) mutable {
  //     if (!std::exchange(started, true)) (void)sdo->startUpload(0x1018, 1, false, now);
  //     if (sdo->step(now)) return true;
  //     ... sdo->status(), sdo->data() ...
  //     return false;
  //   });
  using AcyclicStep = std::function<bool(Master& master, SimTime now)>;
  Status post(AcyclicStep step);

 private:
  void sendReceiveLoop();
  void controlLoop();
  void cyclicLoop();
  // One cycle's I/O: send, poll until answered (waiting on the bus unlocked), finish.
  Status exchangeOnce();
  void takeSnapshot();
  void stepPosted();  // the control thread, after a cycle
  // Starts `loop` on `thread`, names it, asks for SCHED_FIFO `priority`: 0 or the error
  // number; a failed pinning is a warning.
  int spawn(std::thread& thread, int priority, void (RtDriver::*loop)(), const char* name);

  Master& master_;
  RtDriverOptions options_;
  Application application_;
  std::atomic<bool> running_{false};
  std::atomic<bool> stopping_{false};
  bool realtime_{false};
  bool memoryLocked_{false};
  std::vector<std::string> warnings_;

  PiMutex masterLock_;     // the master: transport, cyclic frames, health, process image
  SimTime lastFinish_{0};  // when send/receive finished the last cycle (bus clock)
  std::uint64_t controlSteps_{0};
  LatencyHistogram wakeLatency_;
  std::size_t eventsCopied_{0};      // of master_.events(), into snapshot_
  std::vector<AcyclicStep> posted_;  // acyclic work, stepped by the control thread

  std::mutex handoffLock_;  // the hand-offs between the threads
  std::condition_variable handoff_;
  std::uint64_t requested_{0};   // cycles handed to send/receive
  std::uint64_t completed_{0};   // cycles it finished
  bool cyclicDone_{false};       // the cyclic task has ended (no more requests)
  bool sendReceiveDone_{false};  // send/receive has ended (no more cycles to control)

  mutable std::mutex snapshotLock_;
  RtSnapshot snapshot_;
  std::atomic<std::uint64_t> failedCycles_{0};
  std::atomic<std::uint64_t> overruns_{0};
  std::string firstError_;  // under snapshotLock_

  std::thread sendReceive_;
  std::thread control_;
  std::thread cyclic_;
};

}  // namespace ecsim::master
