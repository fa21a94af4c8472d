// A Link carries whole Ethernet frames (without FCS) between a master and a network. The same
// interface is implemented by a raw socket on a real or veth interface, a TAP device, an
// in-process pair, and decorators (pcap capture, fault injection).
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

#include "protocol/bytes.hpp"
#include "protocol/result.hpp"

namespace ecsim {

class Link {
 public:
  virtual ~Link() = default;

  // Sends one frame. Frames longer than the link accepts are an error, never truncated.
  virtual Status send(ConstBytes frame) = 0;

  // Receives one frame into buffer. Waits at most timeout (zero: do not wait). Returns the
  // frame length, or 0 when nothing arrived in time (or a signal ended the wait early, so a
  // loop can look at its SignalFlag). A frame longer than buffer is dropped and reported as
  // an error.
  virtual Result<std::size_t> receive(Bytes buffer, std::chrono::nanoseconds timeout) = 0;

  // A file descriptor that becomes readable when a frame is waiting, or -1.
  virtual int pollFd() const { return -1; }

  virtual std::string describe() const = 0;
};

}  // namespace ecsim
