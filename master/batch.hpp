// A group of datagrams sent together (the transport packs them into as few frames as fit) and
// checked together: the register writes of one configuration step, the AL status reads of all
// slaves. Datagrams live in a deque so their addresses stay fixed while queued.
//
// pending() is asked on every pass of a task's loop, and a batch of all slaves' datagrams is
// answered a few frames at a time: it remembers the first datagram still pending instead of
// looking at the answered ones again (which made a bring-up quadratic in the number of
// slaves). A datagram once answered is queued again only through queueAll() or queue(i),
// which move the memo back; Transport::queue() on a batch's datagram would leave pending()
// false while it flies (the health monitor did so and took its status reads before their
// answers came back over a real link).
#pragma once

#include <algorithm>
#include <cstddef>
#include <deque>
#include <string>

#include "master/bus.hpp"
#include "master/datagram.hpp"
#include "master/transport.hpp"
#include "protocol/result.hpp"

namespace ecsim::master {

class DatagramBatch {
 public:
  Datagram& add() {
    firstPending_ = 0;
    return datagrams_.emplace_back();
  }
  void clear() {
    datagrams_.clear();
    firstPending_ = 0;
  }
  std::size_t size() const { return datagrams_.size(); }
  bool empty() const { return datagrams_.empty(); }
  Datagram& operator[](std::size_t i) { return datagrams_[i]; }
  const Datagram& operator[](std::size_t i) const { return datagrams_[i]; }

  void queueAll(Transport& transport) {
    firstPending_ = 0;
    for (auto& d : datagrams_) transport.queue(d);
  }
  // Queues datagram i alone (a task sending a part of its batch again).
  void queue(std::size_t i, Transport& transport) {
    firstPending_ = std::min(firstPending_, i);
    transport.queue(datagrams_[i]);
  }
  bool pending() const {
    while (firstPending_ < datagrams_.size() && !datagrams_[firstPending_].pending()) {
      ++firstPending_;
    }
    return firstPending_ < datagrams_.size();
  }
  // Ok when every datagram came back with its expected WKC; otherwise the first failure's
  // code and every failure's context (up to a handful), joined by "; ".
  Status check() const {
    std::string context;
    std::size_t failures = 0;
    ErrorCode code = ErrorCode::kWorkingCounter;
    for (const auto& d : datagrams_) {
      auto s = d.check();
      if (s.ok()) continue;
      if (failures == 0) code = s.error().code;
      if (failures < kMaxListed) context += (failures == 0 ? "" : "; ") + s.error().context;
      ++failures;
    }
    if (failures == 0) return okStatus();
    if (failures > kMaxListed) {
      context += "; and " + std::to_string(failures - kMaxListed) + " more";
    }
    return makeError(code, context);
  }

 private:
  static constexpr std::size_t kMaxListed = 4;
  std::deque<Datagram> datagrams_;
  mutable std::size_t firstPending_{0};  // every datagram before it is answered or given up
};

// A task that runs until every datagram of a batch is answered or given up.
class BatchWait final : public Task {
 public:
  explicit BatchWait(const DatagramBatch& batch) : batch_(batch) {}
  bool step(SimTime /*now*/) override { return batch_.pending(); }

 private:
  const DatagramBatch& batch_;
};

}  // namespace ecsim::master
