#include "link/memory_link.hpp"

#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <vector>

#include "link/fd.hpp"
#include "protocol/ethernet.hpp"

namespace ecsim {

// One direction: a ring of fixed-size slots guarded by a mutex. The eventfd (semaphore mode)
// mirrors the number of queued frames for pollFd(); it is updated under the same mutex.
class MemoryLink::Queue {
 public:
  explicit Queue(std::size_t capacity)
      : slots_(capacity * kMaxFrameSize),
        lengths_(capacity),
        capacity_(capacity),
        event_(::eventfd(0, EFD_SEMAPHORE | EFD_NONBLOCK | EFD_CLOEXEC)) {}

  Status push(ConstBytes frame) {
    std::lock_guard lock(mutex_);
    if (count_ == capacity_) {
      return makeError(ErrorCode::kTooLarge, "memory link queue full (" +
                                                 std::to_string(capacity_) +
                                                 " frames waiting), frame dropped");
    }
    const std::size_t slot = (head_ + count_) % capacity_;
    std::memcpy(slots_.data() + slot * kMaxFrameSize, frame.data(), frame.size());
    lengths_[slot] = frame.size();
    ++count_;
    if (event_.valid()) {
      const std::uint64_t one = 1;
      [[maybe_unused]] auto n = ::write(event_.get(), &one, sizeof one);
    }
    ready_.notify_one();
    return okStatus();
  }

  Result<std::size_t> pop(Bytes buffer, std::chrono::nanoseconds timeout) {
    std::unique_lock lock(mutex_);
    if (count_ == 0 && timeout.count() > 0) {
      ready_.wait_for(lock, timeout, [this] { return count_ > 0; });
    }
    if (count_ == 0) return std::size_t{0};
    const std::size_t slot = head_;
    const std::size_t length = lengths_[slot];
    head_ = (head_ + 1) % capacity_;
    --count_;
    if (event_.valid()) {
      std::uint64_t one = 0;
      [[maybe_unused]] auto n = ::read(event_.get(), &one, sizeof one);
    }
    if (length > buffer.size()) {
      return makeError(ErrorCode::kTooLarge, "memory link: frame of " + std::to_string(length) +
                                                 " bytes exceeds receive buffer of " +
                                                 std::to_string(buffer.size()) +
                                                 " bytes, frame dropped");
    }
    std::memcpy(buffer.data(), slots_.data() + slot * kMaxFrameSize, length);
    return length;
  }

  std::size_t size() const {
    std::lock_guard lock(mutex_);
    return count_;
  }
  std::size_t capacity() const { return capacity_; }
  int fd() const { return event_.get(); }

 private:
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::vector<std::uint8_t> slots_;
  std::vector<std::size_t> lengths_;
  std::size_t capacity_;
  std::size_t head_{0};
  std::size_t count_{0};
  UniqueFd event_;
};

std::pair<MemoryLink, MemoryLink> MemoryLink::makePair(std::size_t capacity) {
  capacity = std::max<std::size_t>(capacity, 1);
  auto aToB = std::make_shared<Queue>(capacity);
  auto bToA = std::make_shared<Queue>(capacity);
  return {MemoryLink(aToB, bToA, 'A'), MemoryLink(bToA, aToB, 'B')};
}

MemoryLink::MemoryLink(std::shared_ptr<Queue> tx, std::shared_ptr<Queue> rx, char end)
    : tx_(std::move(tx)), rx_(std::move(rx)), end_(end) {}

Status MemoryLink::send(ConstBytes frame) {
  if (frame.empty()) return makeError(ErrorCode::kInvalidArgument, describe() + ": empty frame");
  if (frame.size() > kMaxFrameSize) {
    return makeError(ErrorCode::kTooLarge, describe() + ": frame of " +
                                               std::to_string(frame.size()) + " bytes exceeds " +
                                               std::to_string(kMaxFrameSize));
  }
  return tx_->push(frame);
}

Result<std::size_t> MemoryLink::receive(Bytes buffer, std::chrono::nanoseconds timeout) {
  return rx_->pop(buffer, timeout);
}

int MemoryLink::pollFd() const {
  return rx_->fd();
}

std::string MemoryLink::describe() const {
  return std::string("memory link end ") + end_;
}

std::size_t MemoryLink::pending() const {
  return rx_->size();
}

std::size_t MemoryLink::capacity() const {
  return rx_->capacity();
}

}  // namespace ecsim
