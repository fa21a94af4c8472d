#include "link/pcap_tap.hpp"

namespace ecsim {

PcapTap::PcapTap(Link& inner, PcapWriter& writer, const Clock& clock)
    : inner_(inner), writer_(writer), clock_(clock) {}

Status PcapTap::send(ConstBytes frame) {
  Status status = inner_.send(frame);
  if (status.ok()) record(frame);
  return status;
}

Result<std::size_t> PcapTap::receive(Bytes buffer, std::chrono::nanoseconds timeout) {
  Result<std::size_t> length = inner_.receive(buffer, timeout);
  if (length.ok() && *length > 0) {
    record(ConstBytes(buffer.data(), *length));
  } else if (length.ok()) {
    keep(writer_.flush());  // idle: what was captured goes to the file now
  }
  return length;
}

std::string PcapTap::describe() const {
  return inner_.describe() + " (captured to " + writer_.path() + ")";
}

Status PcapTap::captureStatus() const {
  std::lock_guard lock(errorMutex_);
  return firstError_;
}

void PcapTap::record(ConstBytes frame) {
  const SimTime now = clock_.now();
  Status status = writer_.write(frame, now);
  if (status.ok()) {
    captured_.fetch_add(1, std::memory_order_relaxed);
    status = writer_.flushIfDue(now);
  }
  keep(std::move(status));
}

void PcapTap::keep(Status status) {
  if (status.ok()) return;
  std::lock_guard lock(errorMutex_);
  if (firstError_.ok()) firstError_ = std::move(status);
}

}  // namespace ecsim
