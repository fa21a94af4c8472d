// MemoryLink: two in-process ends joined back to back, for tests and for running the master
// and the simulator in one process. What one end sends, the other receives, in order.
//
// Each direction is a bounded ring of kMaxFrameSize slots allocated once by makePair(); send
// and receive copy into and out of it and never allocate. A full ring refuses the frame
// (kTooLarge), like a NIC whose queue overflows, instead of blocking the sender. Each
// direction is safe for one sending thread and one receiving thread at the same time.
// pollFd() is an eventfd whose counter equals the number of frames waiting, so it can sit in
// a poll() set with real sockets.
#pragma once

#include <chrono>
#include <cstddef>
#include <memory>
#include <string>
#include <utility>

#include "link/link.hpp"

namespace ecsim {

class MemoryLink final : public Link {
 public:
  static constexpr std::size_t kDefaultCapacity = 64;

  // Two joined ends, each able to hold `capacity` frames (at least 1) in flight towards it.
  static std::pair<MemoryLink, MemoryLink> makePair(std::size_t capacity = kDefaultCapacity);

  MemoryLink(MemoryLink&&) noexcept = default;
  MemoryLink& operator=(MemoryLink&&) noexcept = default;
  MemoryLink(const MemoryLink&) = delete;
  MemoryLink& operator=(const MemoryLink&) = delete;
  ~MemoryLink() override = default;

  // Refuses empty frames (kInvalidArgument: receive() uses 0 for "nothing"), frames over
  // kMaxFrameSize and frames that find the peer's ring full (both kTooLarge).
  Status send(ConstBytes frame) override;
  Result<std::size_t> receive(Bytes buffer, std::chrono::nanoseconds timeout) override;
  int pollFd() const override;
  std::string describe() const override;

  // Frames waiting to be received on this end.
  std::size_t pending() const;
  std::size_t capacity() const;

 private:
  class Queue;  // one direction; defined in memory_link.cpp

  MemoryLink(std::shared_ptr<Queue> tx, std::shared_ptr<Queue> rx, char end);

  std::shared_ptr<Queue> tx_;
  std::shared_ptr<Queue> rx_;
  char end_;
};

}  // namespace ecsim
