#include "slavesim/devices/device_state.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <string_view>
#include <utility>

#include "protocol/unique_fd.hpp"
#include "slavesim/record_text.hpp"

namespace ecsim::slavesim::devices {
namespace {

constexpr std::string_view kMagic = "ecsim-device-state";
constexpr std::string_view kVersion = "1";
constexpr std::string_view kShaftAngle = "shaft-angle-rad";

using Buffer = std::array<char, kMaxDeviceStateBytes + 1>;

Error refused(const std::filesystem::path& path, const std::string& why) {
  return makeError(ErrorCode::kInvalidArgument,
                   path.string() + ": " + why + ": refused as a device state file, left as it is");
}

// Reads what `path` names into `buffer` without following a link or blocking: nullopt when
// there is nothing, the number of bytes when it is a regular file of at most
// kMaxDeviceStateBytes, an error naming the path otherwise.
Result<std::optional<std::size_t>> readExisting(const std::filesystem::path& path, Buffer& buffer) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) {
    if (errno == ENOENT) return std::optional<std::size_t>();
    return makeError(ErrorCode::kIo, path.string() + ": " + errnoText(errno));
  }
  if (S_ISLNK(st.st_mode)) {
    return refused(path, "a symbolic link (name the state file itself)");
  }
  if (!S_ISREG(st.st_mode)) return refused(path, fileKindText(st.st_mode));
  UniqueFd fd(::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC));
  if (fd.get() < 0) return makeError(ErrorCode::kIo, path.string() + ": " + errnoText(errno));
  if (::fstat(fd.get(), &st) != 0 || !S_ISREG(st.st_mode)) {  // replaced since the lstat
    return refused(path, "not a regular file");
  }
  std::size_t size = 0;
  while (size < buffer.size()) {
    const ssize_t n = ::read(fd.get(), buffer.data() + size, buffer.size() - size);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return makeError(ErrorCode::kIo, path.string() + ": " + errnoText(errno));
    if (n == 0) break;
    size += static_cast<std::size_t>(n);
  }
  if (size > kMaxDeviceStateBytes) {
    return refused(path, "more than " + std::to_string(kMaxDeviceStateBytes) +
                             " bytes, not a device state file");
  }
  return std::optional<std::size_t>(size);
}

Result<DeviceState> parse(const std::filesystem::path& path, std::string_view text) {
  DeviceState state;
  bool angle = false;
  const RecordFormat format{kMagic, kVersion, "device state file"};
  ECSIM_ASSIGN_OR_RETURN(
      const int lines,
      readRecord(path.string(), text, format,
                 [&](int lineNo, std::string_view key, std::string_view value) -> Status {
                   // Unknown keys are skipped: later versions of a version-1 file may add some.
                   if (key != kShaftAngle) return okStatus();
                   double v = 0.0;
                   auto [ptr, err] = std::from_chars(value.data(), value.data() + value.size(), v);
                   if (err != std::errc() || ptr != value.data() + value.size() ||
                       !std::isfinite(v)) {
                     return recordError(path.string(), lineNo,
                                        "bad shaft angle '" + std::string(value) + "'");
                   }
                   state.shaftAngle = v;
                   angle = true;
                   return okStatus();
                 }));
  if (!angle) return recordError(path.string(), lines, "no " + std::string(kShaftAngle) + " line");
  return state;
}

// Opens PATH.tmp as a new file; a regular one left by an interrupted save is removed first,
// anything else there is refused.
Result<int> createTemporary(const std::string& tmp) {
  for (int attempt = 0; attempt < 2; ++attempt) {
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (fd >= 0) return fd;
    if (errno != EEXIST) return makeError(ErrorCode::kIo, tmp + ": " + errnoText(errno));
    struct stat st {};
    if (::lstat(tmp.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) {
      return refused(tmp, "there and not a regular file");
    }
    if (::unlink(tmp.c_str()) != 0) return makeError(ErrorCode::kIo, tmp + ": " + errnoText(errno));
  }
  return makeError(ErrorCode::kIo, tmp + ": keeps coming back");
}

}  // namespace

Result<DeviceStateFile> DeviceStateFile::open(const std::filesystem::path& path) {
  DeviceStateFile file;
  file.path_ = path;
  file.tmp_ = path.string() + ".tmp";
  const auto parent = path.parent_path();
  file.folder_ = parent.empty() ? std::string(".") : parent.string();
  Buffer buffer;
  ECSIM_ASSIGN_OR_RETURN(auto size, readExisting(path, buffer));
  if (size) {
    ECSIM_ASSIGN_OR_RETURN(auto state, parse(path, std::string_view(buffer.data(), *size)));
    file.loaded_ = state;
  }
  return file;
}

Status DeviceStateFile::save(const DeviceState& state) const {
  Buffer buffer;
  ECSIM_ASSIGN_OR_RETURN(auto size, readExisting(path_, buffer));
  if (size) {
    if (auto old = parse(path_, std::string_view(buffer.data(), *size)); !old.ok()) {
      return makeError(ErrorCode::kInvalidArgument,
                       old.error().context + ": refused as a device state file, left as it is");
    }
  }
  // %.17g reads back to the same double.
  const int length = std::snprintf(
      buffer.data(), buffer.size(),
      "# ecsim device state: the drive's shaft angle, kept across power cycles\n%.*s %.*s\n"
      "%.*s %.17g\n",
      static_cast<int>(kMagic.size()), kMagic.data(), static_cast<int>(kVersion.size()),
      kVersion.data(), static_cast<int>(kShaftAngle.size()), kShaftAngle.data(), state.shaftAngle);
  if (length < 0 || static_cast<std::size_t>(length) >= buffer.size()) {
    return makeError(ErrorCode::kTooLarge, path_.string() + ": device state too long");
  }
  {
    ECSIM_ASSIGN_OR_RETURN(int raw, createTemporary(tmp_));
    UniqueFd fd(raw);
    ECSIM_TRY(writeAll(fd.get(),
                       ConstBytes(reinterpret_cast<const std::uint8_t*>(buffer.data()),
                                  static_cast<std::size_t>(length)),
                       tmp_));
    if (::fsync(fd.get()) != 0) {
      return makeError(ErrorCode::kIo, tmp_ + ": fsync failed: " + errnoText(errno));
    }
    if (::close(fd.release()) != 0) {
      return makeError(ErrorCode::kIo, tmp_ + ": close failed: " + errnoText(errno));
    }
  }
  if (::rename(tmp_.c_str(), path_.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp_.c_str());
    return makeError(ErrorCode::kIo,
                     path_.string() + ": cannot replace device state: " + errnoText(err));
  }
  // The rename itself reaches the disk only with its folder.
  UniqueFd folder(::open(folder_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (folder.get() < 0 || ::fsync(folder.get()) != 0) {
    return makeError(ErrorCode::kIo, folder_ + ": fsync of the folder failed: " + errnoText(errno));
  }
  return okStatus();
}

Status PeriodicStateSaver::tick(SimTime now, const DeviceState& state) {
  if (interval_ <= 0) return okStatus();
  const SimTime slot = now / interval_;
  if (slot_ == slot) return okStatus();
  const bool first = !slot_.has_value();
  slot_ = slot;
  if (first || savedAngle_ == state.shaftAngle) return okStatus();
  ECSIM_TRY(file_.save(state));
  savedAngle_ = state.shaftAngle;
  return okStatus();
}

Result<DeviceState> loadDeviceState(const std::filesystem::path& path) {
  ECSIM_ASSIGN_OR_RETURN(auto file, DeviceStateFile::open(path));
  if (!file.loaded()) {
    return makeError(ErrorCode::kNotFound, path.string() + ": no device state file");
  }
  return *file.loaded();
}

Status saveDeviceState(const std::filesystem::path& path, const DeviceState& state) {
  ECSIM_ASSIGN_OR_RETURN(auto file, DeviceStateFile::open(path));
  return file.save(state);
}

}  // namespace ecsim::slavesim::devices
