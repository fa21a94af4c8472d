#include "link/pcap.hpp"

#include <pcap/pcap.h>

#include <cstdio>
#include <limits>
#include <mutex>

namespace ecsim {

struct PcapWriter::Impl {
  std::mutex mutex;
  pcap_t* handle{nullptr};
  pcap_dumper_t* dumper{nullptr};
  std::string path;
  std::uint64_t frames{0};

  ~Impl() { (void)closeLocked(); }

  Status closeLocked() {
    Status status;
    if (dumper != nullptr) {
      if (pcap_dump_flush(dumper) != 0) {
        status = makeError(ErrorCode::kIo, "flushing capture file " + path);
      }
      pcap_dump_close(dumper);
      dumper = nullptr;
    }
    if (handle != nullptr) {
      pcap_close(handle);
      handle = nullptr;
    }
    return status;
  }
};

PcapWriter::PcapWriter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
PcapWriter::PcapWriter(PcapWriter&&) noexcept = default;
PcapWriter& PcapWriter::operator=(PcapWriter&&) noexcept = default;
PcapWriter::~PcapWriter() = default;

Result<PcapWriter> PcapWriter::open(const std::string& path, int linkType) {
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  impl->handle =
      pcap_open_dead_with_tstamp_precision(linkType, kPcapSnapLength, PCAP_TSTAMP_PRECISION_NANO);
  if (impl->handle == nullptr) {
    return makeError(ErrorCode::kUnsupported,
                     "libpcap refused link type " + std::to_string(linkType) + " for " + path);
  }
  impl->dumper = pcap_dump_open(impl->handle, path.c_str());
  if (impl->dumper == nullptr) {
    return makeError(ErrorCode::kIo,
                     "creating capture file " + path + ": " + pcap_geterr(impl->handle));
  }
  return PcapWriter(std::move(impl));
}

Status PcapWriter::write(ConstBytes frame, SimTime timestampNs) {
  std::lock_guard lock(impl_->mutex);
  if (impl_->dumper == nullptr) {
    return makeError(ErrorCode::kState, "capture file " + impl_->path + " is closed");
  }
  constexpr SimTime kMaxSeconds = SimTime{1} << 32;
  if (timestampNs < 0 || timestampNs / kNsPerSecond >= kMaxSeconds) {
    return makeError(ErrorCode::kInvalidArgument, "capture file " + impl_->path + ": timestamp " +
                                                      std::to_string(timestampNs) +
                                                      " ns is outside the pcap range");
  }
  pcap_pkthdr header{};
  header.ts.tv_sec = static_cast<time_t>(timestampNs / kNsPerSecond);
  // With nanosecond precision libpcap stores the sub-second field as nanoseconds.
  header.ts.tv_usec = static_cast<suseconds_t>(timestampNs % kNsPerSecond);
  header.len = static_cast<bpf_u_int32>(frame.size());
  header.caplen = static_cast<bpf_u_int32>(
      frame.size() < static_cast<std::size_t>(kPcapSnapLength) ? frame.size() : kPcapSnapLength);
  pcap_dump(reinterpret_cast<u_char*>(impl_->dumper), &header, frame.data());
  if (std::ferror(pcap_dump_file(impl_->dumper)) != 0) {
    return makeError(ErrorCode::kIo, "writing frame " + std::to_string(impl_->frames + 1) +
                                         " to capture file " + impl_->path);
  }
  ++impl_->frames;
  return okStatus();
}

Status PcapWriter::flush() {
  std::lock_guard lock(impl_->mutex);
  if (impl_->dumper == nullptr) return okStatus();
  if (pcap_dump_flush(impl_->dumper) != 0) {
    return makeError(ErrorCode::kIo, "flushing capture file " + impl_->path);
  }
  return okStatus();
}

Status PcapWriter::close() {
  std::lock_guard lock(impl_->mutex);
  return impl_->closeLocked();
}

bool PcapWriter::isOpen() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->dumper != nullptr;
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
