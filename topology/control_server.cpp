#include "topology/control_server.hpp"

#include <fcntl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace ecsim::topology {
namespace {

constexpr std::size_t kMaxLine = 4096;

Result<sockaddr_un> socketAddress(const std::filesystem::path& path) {
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  const std::string p = path.string();
  if (p.size() >= sizeof(addr.sun_path)) {
    return makeError(ErrorCode::kInvalidArgument, p + ": socket path too long");
  }
  std::memcpy(addr.sun_path, p.c_str(), p.size() + 1);
  return addr;
}

void sendAll(int fd, std::string_view text) {
  while (!text.empty()) {
    const ssize_t n = ::send(fd, text.data(), text.size(), MSG_NOSIGNAL);
    if (n <= 0) return;
    text.remove_prefix(static_cast<std::size_t>(n));
  }
}

}  // namespace

Result<ControlServer> ControlServer::open(const std::filesystem::path& path) {
  std::error_code ec;
  const auto dir = path.parent_path();
  if (!dir.empty() && !std::filesystem::exists(dir, ec)) {
    std::filesystem::create_directories(dir, ec);
    if (ec) return makeError(ErrorCode::kIo, dir.string() + ": " + ec.message());
    ::chmod(dir.c_str(), 0700);
  }
  auto addr = socketAddress(path);
  if (!addr.ok()) return addr.takeError();
  UniqueFd fd(::socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0));
  if (!fd.valid()) return makeError(ErrorCode::kIo, "control socket: " + errnoText(errno));
  ::unlink(path.c_str());  // a socket left by a killed run
  // Owner-only from the start: no window in which others could connect.
  const mode_t old = ::umask(0077);
  const int bound = ::bind(fd.get(), reinterpret_cast<const sockaddr*>(&*addr), sizeof(*addr));
  ::umask(old);
  if (bound != 0) {
    return makeError(ErrorCode::kIo, path.string() + ": bind: " + errnoText(errno));
  }
  ::chmod(path.c_str(), 0600);
  if (::listen(fd.get(), 8) != 0) {
    return makeError(ErrorCode::kIo, path.string() + ": listen: " + errnoText(errno));
  }
  return ControlServer(std::move(fd), path);
}

ControlServer::ControlServer(ControlServer&&) noexcept = default;
ControlServer& ControlServer::operator=(ControlServer&&) noexcept = default;

ControlServer::~ControlServer() {
  if (fd_.valid()) ::unlink(path_.c_str());
}

void ControlServer::poll(const Handler& handler) {
  while (true) {
    UniqueFd client(::accept4(fd_.get(), nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC));
    if (!client.valid()) break;
    clients_.push_back({std::move(client), {}});
  }
  for (auto it = clients_.begin(); it != clients_.end();) {
    char buf[512];
    bool done = false;
    while (true) {
      const ssize_t n = ::recv(it->fd.get(), buf, sizeof(buf), 0);
      if (n > 0) {
        it->buffer.append(buf, static_cast<std::size_t>(n));
        if (it->buffer.size() > kMaxLine) {
          sendAll(it->fd.get(), "error request line too long\n");
          done = true;
          break;
        }
        continue;
      }
      if (n == 0) done = true;  // closed by the client
      break;                    // EAGAIN: nothing more now
    }
    std::size_t nl;
    while (!it->buffer.empty() && (nl = it->buffer.find('\n')) != std::string::npos) {
      const std::string line = it->buffer.substr(0, nl);
      it->buffer.erase(0, nl + 1);
      sendAll(it->fd.get(), handler(line) + "\n");
    }
    if (done) {
      it = clients_.erase(it);
    } else {
      ++it;
    }
  }
}

Result<std::string> sendControlLine(const std::filesystem::path& path, std::string_view line,
                                    std::chrono::milliseconds timeout) {
  auto addr = socketAddress(path);
  if (!addr.ok()) return addr.takeError();
  UniqueFd fd(::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0));
  if (!fd.valid()) return makeError(ErrorCode::kIo, "socket: " + errnoText(errno));
  if (::connect(fd.get(), reinterpret_cast<const sockaddr*>(&*addr), sizeof(*addr)) != 0) {
    return makeError(ErrorCode::kIo, path.string() + ": connect: " + errnoText(errno));
  }
  sendAll(fd.get(), std::string(line) + "\n");
  std::string reply;
  while (reply.find('\n') == std::string::npos) {
    auto readable = waitReadable(fd.get(), timeout);
    if (!readable.ok()) return readable.takeError();
    if (!*readable) return makeError(ErrorCode::kTimeout, path.string() + ": no reply");
    char buf[512];
    const ssize_t n = ::recv(fd.get(), buf, sizeof(buf), 0);
    if (n <= 0) break;
    reply.append(buf, static_cast<std::size_t>(n));
  }
  if (auto nl = reply.find('\n'); nl != std::string::npos) reply.resize(nl);
  return reply;
}

}  // namespace ecsim::topology
