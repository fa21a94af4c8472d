#include "master/rt_driver.hpp"

#include <sched.h>
#include <sys/mman.h>
#include <time.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>

namespace ecsim::master {
namespace {

timespec toTimespec(SimTime t) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(t / kNsPerSecond);
  ts.tv_nsec = static_cast<long>(t % kNsPerSecond);
  return ts;
}

SimTime monotonicNow() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<SimTime>(ts.tv_sec) * kNsPerSecond + ts.tv_nsec;
}

void sleepUntil(SimTime t) {
  const timespec ts = toTimespec(t);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

// std::condition_variable waits on steady_clock, which is CLOCK_MONOTONIC on Linux.
std::chrono::steady_clock::time_point steadyAt(SimTime t) {
  return std::chrono::steady_clock::time_point(std::chrono::nanoseconds(t));
}

}  // namespace

PiMutex::PiMutex() {
  pthread_mutexattr_t attr;
  pthread_mutexattr_init(&attr);
  pthread_mutexattr_setprotocol(&attr, PTHREAD_PRIO_INHERIT);
  pthread_mutex_init(&mutex_, &attr);
  pthread_mutexattr_destroy(&attr);
}

PiMutex::~PiMutex() {
  pthread_mutex_destroy(&mutex_);
}

void PiMutex::lock() {
  pthread_mutex_lock(&mutex_);
}

void PiMutex::unlock() {
  pthread_mutex_unlock(&mutex_);
}

RtDriver::RtDriver(Master& master, RtDriverOptions options) : master_(master), options_(options) {}

RtDriver::~RtDriver() {
  stop();
}

int RtDriver::spawn(std::thread& thread, int priority, void (RtDriver::*loop)(), const char* name) {
  thread = std::thread([this, loop] { (this->*loop)(); });
  pthread_setname_np(thread.native_handle(), name);
  if (options_.cpu) {
    cpu_set_t set;
    CPU_ZERO(&set);
    const int cpu = *options_.cpu;
    int rc = EINVAL;
    if (cpu >= 0 && cpu < CPU_SETSIZE) {
      CPU_SET(static_cast<std::size_t>(cpu), &set);
      rc = pthread_setaffinity_np(thread.native_handle(), sizeof(set), &set);
    }
    if (rc != 0) {
      warnings_.push_back(std::string(name) + " not pinned to CPU " + std::to_string(cpu) + " (" +
                          std::strerror(rc) + ")");
    }
  }
  sched_param param{};
  param.sched_priority = priority;
  return pthread_setschedparam(thread.native_handle(), SCHED_FIFO, &param);
}

Status RtDriver::start(Application application) {
  if (running_.load()) return makeError(ErrorCode::kState, "the real-time driver is running");
  application_ = std::move(application);
  warnings_.clear();
  stopping_ = false;
  requested_ = completed_ = 0;
  cyclicDone_ = sendReceiveDone_ = false;
  failedCycles_ = 0;
  overruns_ = 0;
  controlSteps_ = 0;
  firstError_.clear();
  wakeLatency_.clear();
  eventsCopied_ = 0;
  {
    std::lock_guard<std::mutex> lock(snapshotLock_);
    snapshot_ = {};
  }
  lastFinish_ = master_.bus().now();
  memoryLocked_ = false;
  if (options_.lockMemory) {
    if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
      memoryLocked_ = true;
    } else {
      warnings_.push_back(std::string("mlockall failed (") + std::strerror(errno) +
                          "): pages may be swapped out in the cyclic path");
    }
  }
  master_.setCycleTime(options_.period);
  running_ = true;
  // Highest first, so each thread is ready before the one that wakes it.
  const int rc[] = {
      spawn(sendReceive_, options_.sendReceivePriority, &RtDriver::sendReceiveLoop, "ec-sendrecv"),
      spawn(control_, options_.controlPriority, &RtDriver::controlLoop, "ec-control"),
      spawn(cyclic_, options_.cyclicPriority, &RtDriver::cyclicLoop, "ec-cyclic")};
  realtime_ = rc[0] == 0 && rc[1] == 0 && rc[2] == 0;
  if (!realtime_) {
    const int err = rc[0] != 0 ? rc[0] : (rc[1] != 0 ? rc[1] : rc[2]);
    warnings_.insert(warnings_.begin(),
                     std::string("real-time scheduling not available (SCHED_FIFO: ") +
                         std::strerror(err) +
                         "): the send/receive, control and cyclic threads run as ordinary "
                         "threads and cycle jitter will be larger; run as root, grant "
                         "CAP_SYS_NICE, or raise the rtprio limit");
  }
  return okStatus();
}

void RtDriver::stop() {
  if (!running_.load()) return;
  stopping_ = true;  // the cyclic task ends after its cycle, then send/receive, then control
  for (std::thread* t : {&cyclic_, &sendReceive_, &control_}) {
    if (t->joinable()) t->join();
  }
  takeSnapshot();
  {
    std::lock_guard<PiMutex> lock(masterLock_);
    posted_.clear();  // their datagrams are withdrawn from the transport
  }
  running_ = false;
  if (memoryLocked_) munlockall();
}

std::vector<RtThreadInfo> RtDriver::threads() const {
  std::vector<RtThreadInfo> out;
  if (!running_.load()) return out;
  for (const std::thread* t : {&sendReceive_, &control_, &cyclic_}) {
    // native_handle() is not const; the handle itself is only read.
    const pthread_t handle = const_cast<std::thread*>(t)->native_handle();
    RtThreadInfo info;
    char name[16] = {};
    if (pthread_getname_np(handle, name, sizeof(name)) == 0) info.name = name;
    sched_param param{};
    if (pthread_getschedparam(handle, &info.policy, &param) == 0) {
      info.priority = param.sched_priority;
    }
    cpu_set_t set;
    CPU_ZERO(&set);
    if (pthread_getaffinity_np(handle, sizeof(set), &set) == 0) {
      for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
        if (CPU_ISSET(static_cast<std::size_t>(cpu), &set)) info.cpus.push_back(cpu);
      }
    }
    out.push_back(std::move(info));
  }
  return out;
}

void RtDriver::cyclicLoop() {
  SimTime next = monotonicNow() + options_.period;
  std::uint64_t cycle = 0;
  while (true) {
    sleepUntil(next);
    if (stopping_.load()) break;
    const SimTime woke = monotonicNow();
    ++cycle;
    {
      std::lock_guard<PiMutex> lock(masterLock_);
      wakeLatency_.record(woke - next);
      if (application_) application_(master_, cycle);
    }
    {
      std::unique_lock<std::mutex> lock(handoffLock_);
      ++requested_;
      handoff_.notify_all();
      handoff_.wait(lock, [&] { return completed_ == requested_; });
    }
    next += options_.period;
    const SimTime now = monotonicNow();
    if (now > next) {  // overran: skip the periods already gone, keep the phase
      ++overruns_;
      next += ((now - next) / options_.period + 1) * options_.period;
    }
  }
  std::lock_guard<std::mutex> lock(handoffLock_);
  cyclicDone_ = true;
  handoff_.notify_all();
}

Status RtDriver::exchangeOnce() {
  Bus& bus = master_.bus();
  SimTime now = bus.now();
  // As long as Master::exchange() waits for a cycle.
  const SimTime deadline = now + 4 * master_.transport().options().timeout;
  bool pending = false;
  {
    std::lock_guard<PiMutex> lock(masterLock_);
    if (Status s = master_.sendCycle(now); !s.ok()) return s;
    now = bus.now();  // an answer's round trip is measured from the send to this poll's time
    pending = master_.pollCycle(now);
  }
  while (pending && now < deadline) {
    SimTime next = deadline;
    {
      std::lock_guard<PiMutex> lock(masterLock_);
      if (auto t = master_.transport().nextDeadline()) next = std::min(next, *t);
    }
    bus.wait(std::max(next, now));  // the link's descriptor, unlocked
    now = bus.now();
    std::lock_guard<PiMutex> lock(masterLock_);
    pending = master_.pollCycle(now);
  }
  std::lock_guard<PiMutex> lock(masterLock_);
  lastFinish_ = now;
  return master_.finishCycle();  // a frame still out counts as lost
}

void RtDriver::sendReceiveLoop() {
  std::uint64_t done = 0;
  while (true) {
    {
      std::unique_lock<std::mutex> lock(handoffLock_);
      handoff_.wait(lock, [&] { return requested_ > done || cyclicDone_; });
      if (requested_ == done) break;  // the cyclic task has ended
    }
    const Status status = exchangeOnce();
    if (!status.ok()) {
      ++failedCycles_;
      std::lock_guard<std::mutex> lock(snapshotLock_);
      if (firstError_.empty()) firstError_ = status.error().message();
    }
    ++done;
    {
      std::lock_guard<std::mutex> lock(handoffLock_);
      completed_ = done;
    }
    handoff_.notify_all();  // the cyclic task and the control thread
  }
  std::lock_guard<std::mutex> lock(handoffLock_);
  sendReceiveDone_ = true;
  handoff_.notify_all();
}

void RtDriver::controlLoop() {
  std::uint64_t seen = 0;
  SimTime nextControl = 0;
  SimTime nextSnapshot = monotonicNow() + options_.snapshotPeriod;
  while (true) {
    bool newCycle = false;
    {
      std::unique_lock<std::mutex> lock(handoffLock_);
      handoff_.wait_until(lock, steadyAt(nextSnapshot),
                          [&] { return completed_ > seen || sendReceiveDone_; });
      if (completed_ > seen) {
        seen = completed_;
        newCycle = true;
      } else if (sendReceiveDone_) {
        break;  // every cycle has had its control step
      }
    }
    const SimTime now = monotonicNow();
    if (newCycle && now >= nextControl) {
      std::lock_guard<PiMutex> lock(masterLock_);
      master_.control(lastFinish_);
      ++controlSteps_;
      nextControl = now + options_.controlPeriod;
    }
    if (newCycle) stepPosted();
    if (now >= nextSnapshot) {
      takeSnapshot();
      nextSnapshot +=
          ((now - nextSnapshot) / options_.snapshotPeriod + 1) * options_.snapshotPeriod;
    }
  }
}

Status RtDriver::post(AcyclicStep step) {
  if (!running_.load() || stopping_.load()) {
    return makeError(ErrorCode::kState, "the real-time driver is not running");
  }
  std::lock_guard<PiMutex> lock(masterLock_);
  posted_.push_back(std::move(step));
  return okStatus();
}

void RtDriver::stepPosted() {
  std::lock_guard<PiMutex> lock(masterLock_);
  for (std::size_t i = 0; i < posted_.size();) {
    if (posted_[i](master_, lastFinish_)) {
      ++i;
    } else {
      posted_.erase(posted_.begin() + static_cast<std::ptrdiff_t>(i));
    }
  }
}

void RtDriver::takeSnapshot() {
  // Copied under the master lock: what changed since the last snapshot, nothing more.
  CyclicStatistics statistics;
  MasterHealth health;
  LatencyHistogram wakeLatency;
  std::vector<MasterEvent> events;
  std::uint64_t controlSteps = 0;
  bool eventsCleared = false;
  {
    std::lock_guard<PiMutex> lock(masterLock_);
    statistics = master_.statistics();
    health = master_.health();
    wakeLatency = wakeLatency_;
    controlSteps = controlSteps_;
    const auto& all = master_.events();
    if (all.size() < eventsCopied_) {  // clearEvents() by someone
      eventsCleared = true;
      eventsCopied_ = 0;
    }
    events.assign(all.begin() + static_cast<std::ptrdiff_t>(eventsCopied_), all.end());
    eventsCopied_ = all.size();
  }
  std::uint64_t cycles = 0;
  {
    std::lock_guard<std::mutex> lock(handoffLock_);
    cycles = completed_;
  }
  std::lock_guard<std::mutex> lock(snapshotLock_);
  RtSnapshot& s = snapshot_;
  s.cycles = cycles;
  s.failedCycles = failedCycles_;
  s.overruns = overruns_;
  s.controlSteps = controlSteps;
  s.firstError = firstError_;
  s.statistics = std::move(statistics);
  s.health = std::move(health);
  s.wakeLatency = std::move(wakeLatency);
  if (eventsCleared) s.events.clear();
  s.events.insert(s.events.end(), std::make_move_iterator(events.begin()),
                  std::make_move_iterator(events.end()));
}

RtSnapshot RtDriver::snapshot() const {
  std::lock_guard<std::mutex> lock(snapshotLock_);
  return snapshot_;
}

}  // namespace ecsim::master
