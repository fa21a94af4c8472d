// PcapTap: a Link decorator that records every frame sent and received through it into a
// PcapWriter, stamped with the time of the Clock it is given (WallClock for live captures,
// the simulator's model clock for virtual time). Records reach the file when a receive finds
// nothing waiting and at least every kCaptureFlushInterval of that clock.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

#include "link/link.hpp"
#include "link/pcap.hpp"
#include "protocol/time.hpp"

namespace ecsim {

class PcapTap final : public Link {
 public:
  // inner, writer and clock must outlive the tap.
  PcapTap(Link& inner, PcapWriter& writer, const Clock& clock);
  PcapTap(const PcapTap&) = delete;
  PcapTap& operator=(const PcapTap&) = delete;

  // A frame is recorded only when the inner link sent or delivered it. A failed capture
  // write does not fail the link: the first such error is kept in captureStatus().
  Status send(ConstBytes frame) override;
  Result<std::size_t> receive(Bytes buffer, std::chrono::nanoseconds timeout) override;
  int pollFd() const override { return inner_.pollFd(); }
  std::string describe() const override;

  Status captureStatus() const;
  std::uint64_t framesCaptured() const { return captured_.load(std::memory_order_relaxed); }

 private:
  void record(ConstBytes frame);
  void keep(Status status);  // remembers the first capture error

  Link& inner_;
  PcapWriter& writer_;
  const Clock& clock_;
  std::atomic<std::uint64_t> captured_{0};
  mutable std::mutex errorMutex_;
  Status firstError_;
};

}  // namespace ecsim
