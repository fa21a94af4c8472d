#include "master/rt_driver.hpp"

#include <pthread.h>
#include <sys/mman.h>
#include <time.h>

#include <cerrno>
#include <cstring>

namespace ecsim::master {
namespace {

constexpr SimTime kNsPerSecondLocal = kNsPerSecond;

timespec toTimespec(SimTime t) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(t / kNsPerSecondLocal);
  ts.tv_nsec = static_cast<long>(t % kNsPerSecondLocal);
  return ts;
}

SimTime monotonicNow() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<SimTime>(ts.tv_sec) * kNsPerSecondLocal + ts.tv_nsec;
}

void sleepUntil(SimTime t) {
  const timespec ts = toTimespec(t);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

}  // namespace

RtDriver::RtDriver(Master& master, RtDriverOptions options) : master_(master), options_(options) {}

RtDriver::~RtDriver() {
  stop();
}

int RtDriver::spawn(std::thread& thread, int priority, void (RtDriver::*loop)(), const char* name) {
  thread = std::thread([this, loop] { (this->*loop)(); });
  pthread_setname_np(thread.native_handle(), name);
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
  cyclicDone_ = false;
  failedCycles_ = 0;
  overruns_ = 0;
  firstError_.clear();
  wakeLatency_.clear();
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
  stopping_ = true;  // the cyclic task ends after its cycle, then send/receive
  for (std::thread* t : {&cyclic_, &control_, &sendReceive_}) {
    if (t->joinable()) t->join();
  }
  takeSnapshot();
  running_ = false;
  if (memoryLocked_) munlockall();
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
      std::lock_guard<std::mutex> lock(masterLock_);
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

void RtDriver::sendReceiveLoop() {
  std::uint64_t done = 0;
  while (true) {
    {
      std::unique_lock<std::mutex> lock(handoffLock_);
      handoff_.wait(lock, [&] { return requested_ > done || cyclicDone_; });
      if (requested_ == done) return;  // the cyclic task has ended
    }
    Status status;
    {
      std::lock_guard<std::mutex> lock(masterLock_);
      status = master_.cycle();
    }
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
    handoff_.notify_all();
  }
}

void RtDriver::controlLoop() {
  SimTime next = monotonicNow();
  while (!stopping_.load()) {
    next += options_.controlPeriod;
    sleepUntil(next);
    takeSnapshot();
  }
}

void RtDriver::takeSnapshot() {
  RtSnapshot s;
  {
    std::lock_guard<std::mutex> lock(masterLock_);
    s.statistics = master_.statistics();
    s.health = master_.health();
    s.events = master_.events();
    s.wakeLatency = wakeLatency_;
  }
  {
    std::lock_guard<std::mutex> lock(handoffLock_);
    s.cycles = completed_;
  }
  s.failedCycles = failedCycles_;
  s.overruns = overruns_;
  std::lock_guard<std::mutex> lock(snapshotLock_);
  s.firstError = firstError_;
  snapshot_ = std::move(s);
}

RtSnapshot RtDriver::snapshot() const {
  std::lock_guard<std::mutex> lock(snapshotLock_);
  return snapshot_;
}

}  // namespace ecsim::master
