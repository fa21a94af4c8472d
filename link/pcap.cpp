#include "link/pcap.hpp"

#include <fcntl.h>
#include <pcap/pcap.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdio>
#include <limits>
#include <mutex>
#include <optional>

#include "link/fd.hpp"

namespace ecsim {
namespace {

// Classic pcap, nanosecond variant (libpcap's file format): a 24-byte file header, then per
// frame a 16-byte record header (seconds, nanoseconds, captured length, original length).
constexpr std::uint32_t kPcapMagicNanoseconds = 0xa1b23c4d;
constexpr std::size_t kPcapFileHeaderSize = 24;
constexpr std::size_t kPcapRecordHeaderSize = 16;
// Whole records wait here and go to the file in one write(2): a crash never leaves a record
// cut at a buffer boundary. Sized for many frames, and always for one record of the largest.
constexpr std::size_t kWriteBufferSize = 128 * 1024;
static_assert(kWriteBufferSize >= kPcapRecordHeaderSize + kPcapSnapLength);

}  // namespace

struct PcapWriter::Impl {
  std::mutex mutex;
  UniqueFd fd;
  std::string path;
  std::uint64_t frames{0};
  std::vector<std::uint8_t> buffer;  // whole records not yet written; capacity kWriteBufferSize
  std::uint64_t bufferedFrames{0};
  std::optional<SimTime> lastFlush;  // by the caller's clock (flushIfDue)
  Status failed;                     // the first write error: every later call reports it

  ~Impl() { (void)closeLocked(); }

  Status flushLocked() {
    if (!failed.ok()) return failed;
    if (buffer.empty() || !fd.valid()) return okStatus();
    Status written = writeAll(
        fd.get(), buffer,
        "writing capture file " + path + " (" + std::to_string(bufferedFrames) + " frame(s) lost)");
    buffer.clear();
    bufferedFrames = 0;
    if (!written.ok()) failed = written;
    return written;
  }

  Status closeLocked() {
    if (!fd.valid()) return okStatus();
    Status status = flushLocked();
    fd.reset();
    return status;
  }
};

PcapWriter::PcapWriter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
PcapWriter::PcapWriter(PcapWriter&&) noexcept = default;
PcapWriter& PcapWriter::operator=(PcapWriter&&) noexcept = default;
PcapWriter::~PcapWriter() = default;

Result<PcapWriter> PcapWriter::open(const std::string& path, int linkType) {
  if (linkType < 0) {
    return makeError(ErrorCode::kUnsupported,
                     "link type " + std::to_string(linkType) + " for capture file " + path);
  }
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  // O_NONBLOCK only for the open: a FIFO nobody reads fails at once instead of blocking.
  impl->fd.reset(::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_NONBLOCK, 0644));
  if (!impl->fd.valid()) {
    return makeError(ErrorCode::kIo, "creating capture file " + path + ": " + errnoText(errno));
  }
  const int flags = ::fcntl(impl->fd.get(), F_GETFL);
  if (flags < 0 || ::fcntl(impl->fd.get(), F_SETFL, flags & ~O_NONBLOCK) != 0) {
    return makeError(ErrorCode::kIo, "capture file " + path + ": fcntl: " + errnoText(errno));
  }
  // The header goes to the file now: a capture killed before its first flush is still valid.
  std::array<std::uint8_t, kPcapFileHeaderSize> header{};
  writeLe32(header, 0, kPcapMagicNanoseconds);
  writeLe16(header, 4, 2);  // version 2.4
  writeLe16(header, 6, 4);
  writeLe32(header, 16, static_cast<std::uint32_t>(kPcapSnapLength));
  writeLe32(header, 20, static_cast<std::uint32_t>(linkType));
  ECSIM_TRY(writeAll(impl->fd.get(), header, "writing the header of capture file " + path));
  impl->buffer.reserve(kWriteBufferSize);
  return PcapWriter(std::move(impl));
}

Status PcapWriter::write(ConstBytes frame, SimTime timestampNs) {
  std::lock_guard lock(impl_->mutex);
  if (!impl_->fd.valid()) {
    return makeError(ErrorCode::kState, "capture file " + impl_->path + " is closed");
  }
  if (!impl_->failed.ok()) return impl_->failed;
  constexpr SimTime kMaxSeconds = SimTime{1} << 32;
  if (timestampNs < 0 || timestampNs / kNsPerSecond >= kMaxSeconds) {
    return makeError(ErrorCode::kInvalidArgument, "capture file " + impl_->path + ": timestamp " +
                                                      std::to_string(timestampNs) +
                                                      " ns is outside the pcap range");
  }
  const std::size_t captured =
      frame.size() < static_cast<std::size_t>(kPcapSnapLength) ? frame.size() : kPcapSnapLength;
  auto& buffer = impl_->buffer;
  if (buffer.size() + kPcapRecordHeaderSize + captured > kWriteBufferSize) {
    ECSIM_TRY(impl_->flushLocked());
  }
  // Within the reserved capacity: no allocation.
  const std::size_t at = buffer.size();
  buffer.resize(at + kPcapRecordHeaderSize + captured);
  writeLe32(buffer, at, static_cast<std::uint32_t>(timestampNs / kNsPerSecond));
  writeLe32(buffer, at + 4, static_cast<std::uint32_t>(timestampNs % kNsPerSecond));
  writeLe32(buffer, at + 8, static_cast<std::uint32_t>(captured));
  writeLe32(buffer, at + 12, static_cast<std::uint32_t>(frame.size()));
  std::copy_n(frame.begin(), captured,
              buffer.begin() + static_cast<long>(at + kPcapRecordHeaderSize));
  ++impl_->bufferedFrames;
  ++impl_->frames;
  return okStatus();
}

Status PcapWriter::flush() {
  std::lock_guard lock(impl_->mutex);
  return impl_->flushLocked();
}

Status PcapWriter::flushIfDue(SimTime now) {
  std::lock_guard lock(impl_->mutex);
  if (impl_->buffer.empty() || !impl_->lastFlush) {
    impl_->lastFlush = now;  // records buffered from here on wait at most the interval
    return impl_->failed;
  }
  if (now - *impl_->lastFlush < kCaptureFlushInterval) return okStatus();
  impl_->lastFlush = now;
  return impl_->flushLocked();
}

Status PcapWriter::close() {
  std::lock_guard lock(impl_->mutex);
  return impl_->closeLocked();
}

bool PcapWriter::isOpen() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->fd.valid();
}

const std::string& PcapWriter::path() const {
  return impl_->path;
}

std::uint64_t PcapWriter::framesWritten() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->frames;
}

struct PcapReader::Impl {
  pcap_t* handle{nullptr};
  std::string path;
  std::uint64_t frames{0};

  ~Impl() {
    if (handle != nullptr) pcap_close(handle);
  }
};

PcapReader::PcapReader(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
PcapReader::PcapReader(PcapReader&&) noexcept = default;
PcapReader& PcapReader::operator=(PcapReader&&) noexcept = default;
PcapReader::~PcapReader() = default;

Result<PcapReader> PcapReader::open(const std::string& path) {
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  char errorText[PCAP_ERRBUF_SIZE] = {};
  impl->handle =
      pcap_open_offline_with_tstamp_precision(path.c_str(), PCAP_TSTAMP_PRECISION_NANO, errorText);
  if (impl->handle == nullptr) {
    return makeError(ErrorCode::kIo, "opening capture file " + path + ": " + errorText);
  }
  return PcapReader(std::move(impl));
}

int PcapReader::linkType() const {
  return pcap_datalink(impl_->handle);
}

std::uint64_t PcapReader::frameCount() const {
  return impl_->frames;
}

Result<std::optional<PcapFrame>> PcapReader::next() {
  pcap_pkthdr* header = nullptr;
  const u_char* data = nullptr;
  const int rc = pcap_next_ex(impl_->handle, &header, &data);
  if (rc == PCAP_ERROR_BREAK) return std::optional<PcapFrame>{};  // end of file
  if (rc != 1) {
    return makeError(ErrorCode::kParse, impl_->path + ": frame " +
                                            std::to_string(impl_->frames + 1) + ": " +
                                            pcap_geterr(impl_->handle));
  }
  ++impl_->frames;
  // pcapng timestamps are 64-bit: seconds past SimTime's range (year 2262) are refused rather
  // than wrapped. tv_usec holds nanoseconds (the reader was opened with nanosecond precision).
  constexpr auto kMaxSeconds = std::numeric_limits<SimTime>::max() / kNsPerSecond - 1;
  if (header->ts.tv_sec < -kMaxSeconds || header->ts.tv_sec > kMaxSeconds) {
    return makeError(ErrorCode::kParse, impl_->path + ": frame " + std::to_string(impl_->frames) +
                                            ": timestamp " + std::to_string(header->ts.tv_sec) +
                                            " s is outside -" + std::to_string(kMaxSeconds) + ".." +
                                            std::to_string(kMaxSeconds) + " s");
  }
  PcapFrame frame;
  frame.timestampNs = static_cast<SimTime>(header->ts.tv_sec) * kNsPerSecond +
                      static_cast<SimTime>(header->ts.tv_usec);
  frame.originalLength = header->len;
  frame.data = ConstBytes(data, header->caplen);
  return std::optional<PcapFrame>(frame);
}

Result<std::vector<PcapRecord>> PcapReader::readAll(const std::string& path) {
  ECSIM_ASSIGN_OR_RETURN(PcapReader reader, open(path));
  std::vector<PcapRecord> records;
  for (;;) {
    ECSIM_ASSIGN_OR_RETURN(std::optional<PcapFrame> frame, reader.next());
    if (!frame) return records;
    records.push_back(
        PcapRecord{frame->timestampNs, frame->originalLength,
                   std::vector<std::uint8_t>(frame->data.begin(), frame->data.end())});
  }
}

}  // namespace ecsim
