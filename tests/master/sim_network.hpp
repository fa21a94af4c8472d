// The master against the in-process simulator, on virtual time: a Segment of simulated slaves
// behind a NetworkServer on one end of a MemoryLink, the master's Transport on the other end
// (optionally through a fault-injecting decorator), and a VirtualBus whose waits step the
// server. The master code under test sees only frames on its Link.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "link/memory_link.hpp"
#include "master/bus.hpp"
#include "master/transport.hpp"
#include "topology/network_server.hpp"
#include "topology/segment.hpp"

namespace ecsim::testing {

// A Link decorator that drops chosen frames: the n-th frame sent (1-based) and/or the n-th
// frame received, and records the size of every frame sent.
class FaultLink final : public Link {
 public:
  explicit FaultLink(Link& inner) : inner_(inner) {}

  Status send(ConstBytes frame) override {
    ++sent_;
    sentSizes.push_back(frame.size());
    if (dropSend.count(sent_) != 0 || dropAllSends) {
      ++droppedSends;
      return okStatus();  // lost on the wire: the sender cannot tell
    }
    return inner_.send(frame);
  }
  Result<std::size_t> receive(Bytes buffer, std::chrono::nanoseconds timeout) override {
    for (;;) {
      auto r = inner_.receive(buffer, timeout);
      if (!r.ok() || *r == 0) return r;
      ++received_;
      const bool drop = dropReceive.count(received_) != 0 ||
                        (dropReceiveIf && dropReceiveIf(ConstBytes(buffer.data(), *r)));
      if (!drop) return r;
      ++droppedReceives;
    }
  }
  int pollFd() const override { return inner_.pollFd(); }
  std::string describe() const override { return "fault(" + inner_.describe() + ")"; }

  std::uint64_t sentCount() const { return sent_; }
  std::uint64_t receivedCount() const { return received_; }

  std::set<std::uint64_t> dropSend;
  std::set<std::uint64_t> dropReceive;
  // Drops a received frame when it returns true (e.g. the first answer to a mailbox read).
  std::function<bool(ConstBytes)> dropReceiveIf;
  bool dropAllSends{false};
  std::uint64_t droppedSends{0};
  std::uint64_t droppedReceives{0};
  std::vector<std::size_t> sentSizes;

 private:
  Link& inner_;
  std::uint64_t sent_{0};
  std::uint64_t received_{0};
};

class SimNetwork {
 public:
  SimNetwork() : links_(MemoryLink::makePair(256)), fault_(links_.first) {
    bus_ = std::make_unique<master::VirtualBus>(clock_, [this](SimTime) { return serveOne(); });
  }

  topology::Segment& segment() { return segment_; }
  // Call after the slaves are added and wired. `secondPort`: cable redundancy, the segment's
  // redundant port (Segment::setRedundantPort) served on a second pair of links, whose master
  // end is secondPort().
  void start(bool secondPort = false) {
    topology::ServerOptions options;
    options.idleWait = std::chrono::nanoseconds(0);
    server_ = std::make_unique<topology::NetworkServer>(links_.second, segment_, clock_, options);
    if (secondPort) {
      second_.emplace(MemoryLink::makePair(256));
      server_->setRedundantLink(&second_->second);
    }
  }

  Link& masterLink() { return fault_; }
  Link& secondPort() { return second_->first; }
  FaultLink& fault() { return fault_; }
  MemoryLink& simulatorEnd() { return links_.second; }
  VirtualClock& clock() { return clock_; }
  master::Bus& bus() { return *bus_; }
  topology::NetworkServer& server() { return *server_; }

 private:
  std::optional<SimTime> serveOne() {
    if (!server_) return std::nullopt;
    const bool waiting = links_.second.pending() + (second_ ? second_->second.pending() : 0) > 0;
    const auto before = server_->counters().framesAnswered;
    EXPECT_TRUE(server_->step().ok());
    if (waiting && server_->counters().framesAnswered != before) {
      return server_->counters().lastRoundTrip;
    }
    return std::nullopt;
  }

  VirtualClock clock_;
  topology::Segment segment_;
  std::pair<MemoryLink, MemoryLink> links_;
  FaultLink fault_;
  std::optional<std::pair<MemoryLink, MemoryLink>> second_;
  std::unique_ptr<topology::NetworkServer> server_;
  std::unique_ptr<master::VirtualBus> bus_;
};

// A task that runs until every given datagram is answered or given up.
class WaitTask final : public master::Task {
 public:
  explicit WaitTask(std::vector<master::Datagram*> datagrams) : datagrams_(std::move(datagrams)) {}
  bool step(SimTime) override {
    for (auto* d : datagrams_) {
      if (d->pending()) return true;
    }
    return false;
  }

 private:
  std::vector<master::Datagram*> datagrams_;
};

}  // namespace ecsim::testing
