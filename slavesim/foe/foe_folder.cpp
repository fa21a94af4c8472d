#include "slavesim/foe/foe_folder.hpp"

#include "slavesim/record_text.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <memory>

namespace ecsim::slavesim::foe {
namespace {

constexpr std::string_view kFilePrefix = "file-";
constexpr std::string_view kTmpSuffix = ".tmp";
constexpr std::string_view kRecordName = "firmware";
constexpr std::string_view kMagic = "ecsim-foe-firmware";
constexpr std::string_view kVersion = "1";
constexpr std::string_view kPending = "pending";
constexpr std::string_view kInstalled = "installed-version";
constexpr std::size_t kMaxRecordBytes = 64 * 1024;
constexpr std::size_t kReadBlock = 64 * 1024;

Error ioError(const std::string& path, const std::string& what, int err) {
  return makeError(ErrorCode::kIo, path + ": " + what + errnoText(err));
}

Error refused(const std::string& path, const std::string& why) {
  return makeError(ErrorCode::kInvalidArgument,
                   path + ": " + why + ": refused as an FoE file folder, left as it is");
}

bool plain(unsigned char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '.' ||
         c == '_' || c == '-';
}

int hexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

// Reads a regular file (not following a link) into `file`, refusing more than `limit` bytes.
Status readRegular(const std::string& path, std::size_t limit, FoeFile& file) {
  UniqueFd fd(::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC));
  if (!fd.valid() && errno == ELOOP) return refused(path, "a symbolic link");
  if (!fd.valid()) return ioError(path, "", errno);
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0) return ioError(path, "", errno);
  if (!S_ISREG(st.st_mode)) return refused(path, fileKindText(st.st_mode));
  if (static_cast<std::size_t>(st.st_size) > limit) {
    return refused(path, "more than " + std::to_string(limit) + " bytes");
  }
  std::vector<std::uint8_t> block(kReadBlock);
  for (;;) {
    const ssize_t n = ::read(fd.get(), block.data(), block.size());
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return ioError(path, "", errno);
    if (n == 0) return okStatus();
    if (file.size() + static_cast<std::size_t>(n) > limit) {
      return refused(path, "more than " + std::to_string(limit) + " bytes");
    }
    file.append(ConstBytes(block).first(static_cast<std::size_t>(n)));
  }
}

Status parseRecord(const std::string& path, std::string_view text, FoeFolderContent& content) {
  const RecordFormat format{kMagic, kVersion, "FoE firmware record"};
  auto read = readRecord(
      path, text, format, [&](int lineNo, std::string_view key, std::string_view value) -> Status {
        std::optional<std::string>* field = key == kPending     ? &content.pending
                                            : key == kInstalled ? &content.installedVersion
                                                                : nullptr;
        if (field == nullptr) {
          return recordError(
              path, lineNo,
              "unknown key '" + std::string(key) + "' (known: pending, installed-version)");
        }
        auto decoded = percentDecode(value);
        if (!decoded || decoded->empty()) {
          return recordError(path, lineNo, "bad value '" + std::string(value) + "'");
        }
        *field = std::move(*decoded);
        return okStatus();
      });
  if (!read.ok()) return read.takeError();
  return okStatus();
}

Status readFirmwareRecord(const std::string& path, FoeFolderContent& content) {
  FoeFile file;
  ECSIM_TRY(readRegular(path, kMaxRecordBytes, file));
  const std::vector<std::uint8_t> bytes = file.bytes();
  return parseRecord(
      path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), content);
}

}  // namespace

std::filesystem::path foeFolderFor(const std::filesystem::path& stateFile) {
  return stateFile.string() + ".foe";
}

std::string percentEncode(std::string_view text) {
  static constexpr std::array<char, 16> kHex{'0', '1', '2', '3', '4', '5', '6', '7',
                                             '8', '9', 'A', 'B', 'C', 'D', 'E', 'F'};
  std::string out;
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (plain(c)) {
      out.push_back(ch);
    } else {
      out.push_back('%');
      out.push_back(kHex[c >> 4]);
      out.push_back(kHex[c & 0x0F]);
    }
  }
  return out;
}

std::optional<std::string> percentDecode(std::string_view text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (plain(c)) {
      out.push_back(text[i]);
      continue;
    }
    if (c != '%' || i + 2 >= text.size()) return std::nullopt;
    const int hi = hexValue(text[i + 1]);
    const int lo = hexValue(text[i + 2]);
    if (hi < 0 || lo < 0) return std::nullopt;
    out.push_back(static_cast<char>(hi * 16 + lo));
    i += 2;
  }
  return out;
}

Result<FoeFolder> FoeFolder::open(const std::filesystem::path& path, FoeFolderContent& content,
                                  std::size_t maxFileBytes) {
  const std::string shown = path.string();
  FoeFolder folder;
  folder.path_ = path;
  ECSIM_ASSIGN_OR_RETURN(const bool exists, folder.check());
  if (!exists) return folder;  // made with the first file or record written
  std::unique_ptr<DIR, int (*)(DIR*)> dir(::opendir(path.c_str()), &::closedir);
  if (!dir) return ioError(shown, "", errno);
  std::vector<std::string> names;
  while (const dirent* e = ::readdir(dir.get())) {
    const std::string_view name = e->d_name;
    if (name != "." && name != "..") names.emplace_back(name);
  }
  std::sort(names.begin(), names.end());  // files load in one order whatever the file system
  for (const std::string& name : names) {
    const std::string entry = (path / name).string();
    if (name.size() > kTmpSuffix.size() &&
        std::string_view(name).substr(name.size() - kTmpSuffix.size()) == kTmpSuffix) {
      continue;  // an interrupted transfer or record save: not a file of the device
    }
    if (name == kRecordName) {
      ECSIM_TRY(readFirmwareRecord(entry, content));
      continue;
    }
    std::optional<std::string> decoded;
    if (name.rfind(kFilePrefix, 0) == 0) decoded = percentDecode(name.substr(kFilePrefix.size()));
    if (!decoded || decoded->empty()) {
      return refused(entry, "an entry that is not file-NAME (percent-encoded) or firmware");
    }
    FoeFile file;
    ECSIM_TRY(readRegular(entry, maxFileBytes, file));
    content.files.emplace_back(std::move(*decoded), std::move(file));
  }
  return folder;
}

Result<bool> FoeFolder::check() const {
  const std::string shown = path_.string();
  struct stat st {};
  if (::lstat(path_.c_str(), &st) != 0) {
    if (errno != ENOENT) return ioError(shown, "", errno);
    return false;
  }
  if (S_ISLNK(st.st_mode)) return refused(shown, "a symbolic link (name the folder itself)");
  if (!S_ISDIR(st.st_mode)) return refused(shown, fileKindText(st.st_mode));
  return true;
}

Status FoeFolder::create() const {
  ECSIM_ASSIGN_OR_RETURN(const bool exists, check());
  if (!exists && ::mkdir(path_.c_str(), 0755) != 0 && errno != EEXIST) {
    return ioError(path_.string(), "cannot create the folder: ", errno);
  }
  return okStatus();
}

Status FoeFolder::begin(const std::string& name) {
  abandon();
  ECSIM_TRY(create());
  finalPath_ = (path_ / (std::string(kFilePrefix) + percentEncode(name))).string();
  writingPath_ = finalPath_ + std::string(kTmpSuffix);
  writing_ = UniqueFd(
      ::open(writingPath_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0644));
  if (!writing_.valid()) {
    const int err = errno;
    writingPath_.clear();
    return ioError(finalPath_ + std::string(kTmpSuffix), "", err);
  }
  return okStatus();
}

Status FoeFolder::append(ConstBytes bytes) {
  if (!writing_.valid()) return makeError(ErrorCode::kInvalidArgument, "no FoE file being written");
  return writeAll(writing_.get(), bytes, writingPath_);
}

Status FoeFolder::finish() {
  if (!writing_.valid()) return makeError(ErrorCode::kInvalidArgument, "no FoE file being written");
  if (::close(writing_.release()) != 0) {
    const int err = errno;
    abandon();
    return ioError(writingPath_, "close failed: ", err);
  }
  if (::rename(writingPath_.c_str(), finalPath_.c_str()) != 0) {
    const int err = errno;
    abandon();
    return ioError(finalPath_, "cannot replace: ", err);
  }
  writingPath_.clear();
  return okStatus();
}

void FoeFolder::abandon() {
  writing_.reset();
  if (!writingPath_.empty()) ::unlink(writingPath_.c_str());
  writingPath_.clear();
}

Status FoeFolder::saveFirmwareRecord(const std::optional<std::string>& pending,
                                     const std::optional<std::string>& installedVersion) const {
  std::string text =
      "# ecsim FoE firmware record (docs/devices.md, \"Firmware update over FoE\")\n";
  text += std::string(kMagic) + " " + std::string(kVersion) + "\n";
  if (pending) text += std::string(kPending) + " " + percentEncode(*pending) + "\n";
  if (installedVersion)
    text += std::string(kInstalled) + " " + percentEncode(*installedVersion) + "\n";
  ECSIM_TRY(create());
  const std::string record = (path_ / kRecordName).string();
  const std::string tmp = record + std::string(kTmpSuffix);
  {
    UniqueFd fd(::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0644));
    if (!fd.valid()) return ioError(tmp, "", errno);
    ECSIM_TRY(writeAll(fd.get(),
                       ConstBytes(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()),
                       tmp));
    if (::close(fd.release()) != 0) return ioError(tmp, "close failed: ", errno);
  }
  if (::rename(tmp.c_str(), record.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    return ioError(record, "cannot replace: ", err);
  }
  return okStatus();
}

}  // namespace ecsim::slavesim::foe
