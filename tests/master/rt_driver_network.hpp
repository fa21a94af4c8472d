// The in-process simulator served by its own thread on real time, for the real-time driver's
// tests: a Segment behind a NetworkServer on one end of a MemoryLink, stepped by a thread
// named "sim-server"; the master on the other end with a RealTimeBus that sleeps on the
// link's eventfd. Changes to the network (a pulled cable, a power cycle) run on the server
// thread between two frames (onServer), since the Segment is not thread-safe.
#pragma once

#include <pthread.h>
#include <sched.h>

#include <atomic>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <utility>

#include "link/memory_link.hpp"
#include "master/bus.hpp"
#include "topology/network_server.hpp"
#include "topology/segment.hpp"

namespace ecsim::testing {

class ServedNetwork {
 public:
  static constexpr int kServerPriority = 85;

  ServedNetwork() : links_(MemoryLink::makePair(256)), bus_(links_.first, clock_) {}
  ~ServedNetwork() { stop(); }
  ServedNetwork(const ServedNetwork&) = delete;
  ServedNetwork& operator=(const ServedNetwork&) = delete;

  topology::Segment& segment() { return segment_; }
  // Call after the slaves are added and wired: the server thread starts serving.
  void start() {
    topology::ServerOptions options;
    options.idleWait = std::chrono::microseconds(200);
    server_ = std::make_unique<topology::NetworkServer>(links_.second, segment_, clock_, options);
    thread_ = std::thread([this] { serve(); });
    pthread_setname_np(thread_.native_handle(), "sim-server");
    // The network answers in microseconds whatever else the machine does: where permitted the
    // server runs SCHED_FIFO above the driver's threads (it sleeps on the link between
    // frames), so that a loaded machine does not turn into lost frames.
    sched_param param{};
    param.sched_priority = kServerPriority;
    (void)pthread_setschedparam(thread_.native_handle(), SCHED_FIFO, &param);
  }
  void stop() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }
  // Runs `change` on the server thread and waits until it has run.
  void onServer(std::function<void(topology::Segment&)> change) {
    std::unique_lock<std::mutex> lock(lock_);
    change_ = std::move(change);
    done_.wait(lock, [&] { return !change_; });
  }

  Link& masterLink() { return links_.first; }
  master::Bus& bus() { return bus_; }
  const Clock& clock() const { return clock_; }

 private:
  void serve() {
    while (!stop_.load()) {
      {
        std::lock_guard<std::mutex> lock(lock_);
        if (change_) {
          change_(segment_);
          change_ = nullptr;
          done_.notify_all();
        }
      }
      (void)server_->step();
    }
  }

  RealClock clock_;
  topology::Segment segment_;
  std::pair<MemoryLink, MemoryLink> links_;
  master::RealTimeBus bus_;
  std::unique_ptr<topology::NetworkServer> server_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::mutex lock_;
  std::condition_variable done_;
  std::function<void(topology::Segment&)> change_;
};

}  // namespace ecsim::testing
