// Capture files. PcapWriter writes classic pcap with nanosecond timestamps (magic 0xa1b23c4d)
// itself and takes the timestamp from the caller, so the simulator can stamp frames with model
// time. It is built to be trusted after a crash: the file header is written at open, records
// are buffered whole and written in one write(2) (never a record cut in two), flushIfDue()
// and flush() put them on disk, and the first write error sticks. PcapReader reads pcap and
// pcapng through libpcap and hands out nanosecond timestamps; libpcap's types stay inside
// pcap.cpp.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "protocol/bytes.hpp"
#include "protocol/result.hpp"
#include "protocol/time.hpp"

namespace ecsim {

constexpr int kLinkTypeEthernet = 1;  // LINKTYPE_ETHERNET / DLT_EN10MB
constexpr int kPcapSnapLength = 65535;
// Buffered records reach the file at least this often (by the caller's clock, flushIfDue).
constexpr SimTime kCaptureFlushInterval = 100 * kNsPerMs;

// Writes one capture file. Safe to share between threads (a sender and a receiver thread
// recording through PcapTaps): each call holds an internal lock. Frames longer than the
// snap length are cut, keeping their original length in the record. write() only buffers:
// call flushIfDue(now) regularly and flush() when idle, or records wait until close().
class PcapWriter {
 public:
  // kIo naming the path when the file cannot be made or its header not written (a full disk
  // fails here). A FIFO nobody reads fails at once instead of blocking.
  static Result<PcapWriter> open(const std::string& path, int linkType = kLinkTypeEthernet);

  PcapWriter(PcapWriter&&) noexcept;
  PcapWriter& operator=(PcapWriter&&) noexcept;
  ~PcapWriter();  // closes the file (flushing it)

  // timestampNs: nanoseconds since the Unix epoch, or model time; must be >= 0 and below
  // 2^32 seconds (the classic pcap range).
  Status write(ConstBytes frame, SimTime timestampNs);
  Status flush();
  // Flushes when records have waited kCaptureFlushInterval since the last flush, by the
  // caller's clock (`now`); the writer never reads a clock itself.
  Status flushIfDue(SimTime now);
  // Flushes and closes; later writes fail with kState. Closing twice is fine.
  Status close();

  bool isOpen() const;
  const std::string& path() const;
  std::uint64_t framesWritten() const;

 private:
  struct Impl;
  explicit PcapWriter(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// One frame as read; data stays valid until the next call to next() on the same reader.
struct PcapFrame {
  SimTime timestampNs{0};
  std::uint32_t originalLength{0};  // on the wire; data may be shorter if the capture cut it
  ConstBytes data;
};

// An owned copy of a frame, for readAll().
struct PcapRecord {
  SimTime timestampNs{0};
  std::uint32_t originalLength{0};
  std::vector<std::uint8_t> data;
};

class PcapReader {
 public:
  // Reads pcap (micro- or nanosecond) and pcapng; timestamps are scaled to nanoseconds.
  static Result<PcapReader> open(const std::string& path);

  PcapReader(PcapReader&&) noexcept;
  PcapReader& operator=(PcapReader&&) noexcept;
  ~PcapReader();

  // The file's link type (kLinkTypeEthernet for EtherCAT captures).
  int linkType() const;
  // The next frame, or nullopt at the end of the file. Errors name the file and frame number.
  Result<std::optional<PcapFrame>> next();
  // Frames read so far.
  std::uint64_t frameCount() const;

  // Reads a whole file into memory.
  static Result<std::vector<PcapRecord>> readAll(const std::string& path);

 private:
  struct Impl;
  explicit PcapReader(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace ecsim
