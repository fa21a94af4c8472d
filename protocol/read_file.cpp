#include "protocol/read_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "protocol/unique_fd.hpp"

namespace ecsim {
namespace {

std::string sizeText(std::size_t bytes) {
  if (bytes % (std::size_t{1} << 20) == 0) return std::to_string(bytes >> 20) + " MiB";
  return std::to_string(bytes) + " bytes";
}

Error failure(ErrorCode code, const std::filesystem::path& path, const std::string& why) {
  return makeError(code, path.string() + ": " + why);
}

Error osFailure(const std::filesystem::path& path, const char* call, int err) {
  return failure(err == ENOENT ? ErrorCode::kNotFound : ErrorCode::kIo, path,
                 std::string(call) + ": " + std::strerror(err));
}

}  // namespace

Result<std::string> readRegularFile(const std::filesystem::path& path, std::size_t maxBytes) {
  const UniqueFd file(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY));
  if (!file.valid()) return osFailure(path, "cannot open", errno);
  const int fd = file.get();
  struct stat st {};
  if (::fstat(fd, &st) != 0) return osFailure(path, "cannot stat", errno);
  if (!S_ISREG(st.st_mode)) {
    return failure(ErrorCode::kInvalidArgument, path,
                   std::string("is ") + fileKindText(st.st_mode) + ", not a regular file");
  }
  const auto size = static_cast<std::size_t>(st.st_size);
  const std::string limit = "; the limit is " + sizeText(maxBytes);
  if (size > maxBytes) {
    return failure(ErrorCode::kTooLarge, path, std::to_string(size) + " bytes" + limit);
  }
  // The file may grow while it is read (or report size 0, as /proc files do): read to its
  // end, never more than the bound.
  std::string content(size, '\0');
  std::size_t used = 0;
  while (true) {
    if (used == content.size()) {
      if (used > maxBytes) {
        return failure(ErrorCode::kTooLarge, path, "more than " + sizeText(maxBytes) + limit);
      }
      content.resize(std::min(maxBytes + 1, std::max<std::size_t>(used * 2, 4096)));
    }
    const ssize_t n = ::read(fd, content.data() + used, content.size() - used);
    if (n < 0) {
      if (errno == EINTR) continue;
      return osFailure(path, "read failed", errno);
    }
    if (n == 0) break;
    used += static_cast<std::size_t>(n);
  }
  content.resize(used);
  return content;
}

}  // namespace ecsim
