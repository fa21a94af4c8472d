#include "topology/control_server.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "topology/faults.hpp"

namespace ecsim::topology {
namespace {

constexpr std::size_t kReadPerPoll = 64 * 1024;  // per client, so a flood cannot hold the loop
constexpr std::size_t kAcceptsPerPoll = 64;
constexpr int kConnectRetryMs = 10;

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

// Sends what the socket takes now; removes it from `text`. False on a broken connection.
bool sendSome(int fd, std::string& text) {
  std::size_t sent = 0;
  bool alive = true;
  while (sent < text.size()) {
    const ssize_t n =
        ::send(fd, text.data() + sent, text.size() - sent, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n > 0) {
      sent += static_cast<std::size_t>(n);
    } else if (n < 0 && errno == EINTR) {
      continue;
    } else {
      alive = n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK);
      break;
    }
  }
  text.erase(0, sent);
  return alive;
}

// Waits until `fd` is writable or `timeout` passes.
bool waitWritable(int fd, std::chrono::milliseconds timeout) {
  pollfd pfd{fd, POLLOUT, 0};
  return ::poll(&pfd, 1, static_cast<int>(timeout.count())) > 0 && (pfd.revents & POLLOUT) != 0;
}

}  // namespace

Result<ControlServer> ControlServer::open(const std::filesystem::path& path,
                                          ControlLimits limits) {
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
  return ControlServer(std::move(fd), path, limits);
}

ControlServer::ControlServer(ControlServer&&) noexcept = default;
ControlServer& ControlServer::operator=(ControlServer&&) noexcept = default;

ControlServer::~ControlServer() {
  if (fd_.valid()) ::unlink(path_.c_str());
}

void ControlServer::poll(const Handler& handler, SimTime now) {
  poll(ClientHandler([&handler](std::string_view line, ClientId) { return handler(line); }), now);
}

bool ControlServer::connected(ClientId client) const {
  return std::any_of(clients_.begin(), clients_.end(),
                     [client](const Client& c) { return c.id == client && !c.closing; });
}

void ControlServer::holdOpen(ClientId client) {
  for (auto& c : clients_) {
    if (c.id == client) c.held = true;
  }
}

bool ControlServer::push(ClientId client, std::string_view line) {
  for (auto& c : clients_) {
    if (c.id != client || c.closing) continue;
    if (c.reply.size() >= kControlMaxPendingReply) return false;
    c.reply.append(line);
    c.reply += '\n';
    if (!sendSome(c.fd.get(), c.reply)) c.closing = true;
    return true;
  }
  return false;
}

void ControlServer::poll(const ClientHandler& handler, SimTime now) {
  accept(now);
  for (auto it = clients_.begin(); it != clients_.end();) {
    if (serve(*it, handler, now)) {
      ++it;
    } else {
      it = clients_.erase(it);
    }
  }
}

void ControlServer::accept(SimTime now) {
  for (std::size_t n = 0; n < kAcceptsPerPoll; ++n) {
    UniqueFd client(::accept4(fd_.get(), nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC));
    if (!client.valid()) break;
    if (clients_.size() >= limits_.maxClients) {
      std::string refusal =
          "error too many clients (" + std::to_string(limits_.maxClients) + ")\n";
      (void)sendSome(client.get(), refusal);
      continue;  // closed here
    }
    Client c;
    c.fd = std::move(client);
    c.lastHeard = now;
    c.id = ++lastId_;
    clients_.push_back(std::move(c));
  }
}

bool ControlServer::serve(Client& c, const ClientHandler& handler, SimTime now) {
  if (!sendSome(c.fd.get(), c.reply)) return false;
  std::size_t budget = kReadPerPoll;
  char buf[4096];
  // While the client leaves its answers unread, its further lines wait in the socket.
  while (!c.closing && c.reply.size() < kControlMaxPendingReply && budget > 0) {
    const ssize_t n = ::recv(c.fd.get(), buf, std::min(sizeof(buf), budget), 0);
    if (n > 0) {
      c.lastHeard = now;
      budget -= static_cast<std::size_t>(n);
      takeLines(c, std::string_view(buf, static_cast<std::size_t>(n)), handler);
      if (!sendSome(c.fd.get(), c.reply)) return false;
      continue;
    }
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) break;
    c.closing = true;  // closed by the client (its lines are answered), or broken
  }
  if (c.closing && c.reply.empty()) return false;
  if (!c.held && now - c.lastHeard > limits_.idleTimeout) {
    std::string bye = "error nothing received for " +
                      std::to_string(limits_.idleTimeout / kNsPerSecond) + " s: closed\n";
    (void)sendSome(c.fd.get(), bye);
    return false;
  }
  return true;
}

void ControlServer::takeLines(Client& c, std::string_view data,
                              const ClientHandler& handler) {
  while (!data.empty()) {
    const std::size_t nl = data.find('\n');
    const std::string_view piece = data.substr(0, nl);
    data.remove_prefix(nl == std::string_view::npos ? data.size() : nl + 1);
    if (c.discarding) {
      c.discarding = nl == std::string_view::npos;
      continue;
    }
    if (c.buffer.size() + piece.size() > kControlMaxLine) {
      c.reply += "error line longer than " + std::to_string(kControlMaxLine) + " bytes\n";
      c.buffer.clear();
      c.discarding = nl == std::string_view::npos;
      continue;
    }
    c.buffer.append(piece);
    if (nl == std::string_view::npos) return;
    c.reply += handler(c.buffer, c.id) + "\n";
    c.buffer.clear();
  }
}

std::string answerFaultLine(FaultInjector& faults, std::string_view line, SimTime now) {
  auto fault = parseFaultLine(line);
  if (!fault.ok()) return "error " + fault.error().context;
  auto done = faults.apply(*fault, now, "control");
  return done.ok() ? "ok " + *done : "error " + done.error().context;
}

std::filesystem::path controlSocketDir() {
  return "/run/ecsim";
}

std::filesystem::path defaultControlSocket(std::string_view interfaceName) {
  return controlSocketDir() / (std::string(interfaceName) + ".sock");
}

Result<std::filesystem::path> findControlSocket(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> found;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    if (entry.path().extension() == ".sock" && entry.is_socket(ec)) found.push_back(entry.path());
  }
  std::sort(found.begin(), found.end());
  if (found.size() == 1) return found.front();
  if (found.empty()) {
    return makeError(ErrorCode::kNotFound,
                     "no control socket in " + dir.string() +
                         ": is `ecsim serve` running? (else give --socket PATH or --iface IF)");
  }
  std::string names;
  for (const auto& f : found) names += (names.empty() ? "" : ", ") + f.filename().string();
  return makeError(ErrorCode::kInvalidArgument,
                   "several control sockets in " + dir.string() + " (" + names +
                       "): choose one with --iface IF or --socket PATH");
}

Result<ControlConnection> ControlConnection::open(const std::filesystem::path& path,
                                                  std::chrono::milliseconds timeout) {
  auto addr = socketAddress(path);
  if (!addr.ok()) return addr.takeError();
  UniqueFd fd(::socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0));
  if (!fd.valid()) return makeError(ErrorCode::kIo, "socket: " + errnoText(errno));
  // A Unix socket does not connect in the background: while the server's listen queue is full
  // connect() answers EAGAIN at once, so it is tried again every few milliseconds until the
  // timeout (counted in tries: no clock is read here).
  const long tries = std::max<long>(1, static_cast<long>(timeout.count()) / kConnectRetryMs);
  for (long attempt = 1;; ++attempt) {
    if (::connect(fd.get(), reinterpret_cast<const sockaddr*>(&*addr), sizeof(*addr)) == 0) break;
    if (errno != EAGAIN && errno != EINTR) {
      return makeError(ErrorCode::kIo, path.string() + ": connect: " + errnoText(errno));
    }
    if (attempt >= tries) {
      return makeError(ErrorCode::kTimeout,
                       path.string() + ": the server accepted no connection within " +
                           std::to_string(timeout.count()) + " ms (busy or full)");
    }
    ::poll(nullptr, 0, kConnectRetryMs);
  }
  return ControlConnection(std::move(fd), path);
}

Status ControlConnection::sendLine(std::string_view line, std::chrono::milliseconds timeout) {
  std::string request = std::string(line) + "\n";
  while (!request.empty()) {
    if (!waitWritable(fd_.get(), timeout)) {
      return makeError(ErrorCode::kTimeout, path_.string() + ": the server takes no request");
    }
    if (!sendSome(fd_.get(), request)) {
      return makeError(ErrorCode::kIo, path_.string() + ": send: " + errnoText(errno));
    }
  }
  return okStatus();
}

Result<std::string> ControlConnection::readLine(std::chrono::milliseconds timeout) {
  while (buffer_.find('\n') == std::string::npos) {
    auto readable = waitReadable(fd_.get(), timeout);
    if (!readable.ok()) return readable.takeError();
    if (!*readable) return makeError(ErrorCode::kTimeout, path_.string() + ": no reply");
    char buf[512];
    const ssize_t n = ::recv(fd_.get(), buf, sizeof(buf), 0);
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) continue;
    if (n <= 0) {
      if (buffer_.empty()) {
        return makeError(ErrorCode::kIo, path_.string() + ": the server closed the connection");
      }
      buffer_ += '\n';  // the last line, unterminated
      break;
    }
    buffer_.append(buf, static_cast<std::size_t>(n));
  }
  const auto nl = buffer_.find('\n');
  std::string line = buffer_.substr(0, nl);
  buffer_.erase(0, nl + 1);
  return line;
}

Result<std::string> sendControlLine(const std::filesystem::path& path, std::string_view line,
                                    std::chrono::milliseconds timeout) {
  auto connection = ControlConnection::open(path, timeout);
  if (!connection.ok()) return connection.takeError();
  if (auto sent = connection->sendLine(line, timeout); !sent.ok()) return sent.takeError();
  return connection->readLine(timeout);
}

}  // namespace ecsim::topology
