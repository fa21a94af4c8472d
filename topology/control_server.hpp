// The live-injection control socket of `ecsim serve` (docs/scenarios.md, "Live injection"): a
// Unix-domain stream socket, owner-only (mode 0600), that takes one action per line in the
// text form of topology/faults.hpp ("link-down cable=drives") and answers one line, "ok ..."
// or "error ...". poll() never blocks: the serve loop calls it between frames, so an action
// takes effect between two frames as on a real cable.
//
// Limits: at most kControlMaxClients clients at a time (one more is told "error too many
// clients (N)" and closed); a client that sends nothing for the idle timeout is closed; a line
// longer than kControlMaxLine bytes is answered "error line longer than N bytes" and discarded
// up to its newline, the connection goes on. Every complete line is answered, in order; while
// a client does not read its answers (more than kControlMaxPendingReply bytes waiting), its
// further lines wait in the socket. Lines pushed to a client (push(): a subscription's
// changes) count in the same pending reply: over the limit, push() refuses them.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "link/fd.hpp"
#include "protocol/result.hpp"
#include "protocol/time.hpp"

namespace ecsim::topology {

inline constexpr std::size_t kControlMaxClients = 8;
inline constexpr std::size_t kControlMaxLine = 4096;  // bytes, without the newline
inline constexpr std::size_t kControlMaxPendingReply = 64 * 1024;
inline constexpr SimTime kControlIdleTimeout = 60 * kNsPerSecond;

struct ControlLimits {
  std::size_t maxClients{kControlMaxClients};
  SimTime idleTimeout{kControlIdleTimeout};
};

class ControlServer {
 public:
  // Handles one request line; returns the reply (without newline).
  using Handler = std::function<std::string(std::string_view line)>;
  // Clients are numbered from 1 in the order they connect; a number is never reused.
  using ClientId = std::uint64_t;
  using ClientHandler = std::function<std::string(std::string_view line, ClientId client)>;

  // Creates the socket at `path` (a stale socket file there is replaced; the directory is
  // created with mode 0700 when missing).
  static Result<ControlServer> open(const std::filesystem::path& path, ControlLimits limits = {});
  ControlServer(ControlServer&&) noexcept;
  ControlServer& operator=(ControlServer&&) noexcept;
  ~ControlServer();  // removes the socket file

  // Accepts waiting clients, reads complete lines, answers them, closes clients idle since
  // before `now - idleTimeout` (`now` from the caller's clock). Never blocks.
  void poll(const Handler& handler, SimTime now);
  void poll(const ClientHandler& handler, SimTime now);
  // Queues `line` (a newline is added) for the client and sends what its socket takes now;
  // false when the client is gone or has more than kControlMaxPendingReply bytes unread.
  bool push(ClientId client, std::string_view line);
  bool connected(ClientId client) const;
  // The idle timeout no longer closes the client (it waits for pushed lines, e.g. a
  // subscription); it is closed when it closes its side.
  void holdOpen(ClientId client);
  const std::filesystem::path& path() const { return path_; }
  std::size_t clients() const { return clients_.size(); }

 private:
  ControlServer(UniqueFd fd, std::filesystem::path path, ControlLimits limits)
      : fd_(std::move(fd)), path_(std::move(path)), limits_(limits) {}
  struct Client {
    UniqueFd fd;
    std::string buffer;      // the start of a line not yet complete
    std::string reply;       // answers not yet taken by the client
    bool discarding{false};  // inside a line over the limit: dropped up to its newline
    bool closing{false};     // the client closed its side, or must be closed
    SimTime lastHeard{0};
    ClientId id{0};
    bool held{false};  // holdOpen: exempt from the idle timeout
  };
  void accept(SimTime now);
  // Reads what the client sent and answers its complete lines; false when it is to be closed.
  bool serve(Client& client, const ClientHandler& handler, SimTime now);
  void takeLines(Client& client, std::string_view data, const ClientHandler& handler);

  UniqueFd fd_;
  std::filesystem::path path_;
  ControlLimits limits_;
  std::vector<Client> clients_;
  ClientId lastId_{0};
};

// The client end of one connection (`ecsim ctl`): lines out, lines in.
class ControlConnection {
 public:
  // Connects, giving up after `timeout` when the server does not accept.
  static Result<ControlConnection> open(const std::filesystem::path& path,
                                        std::chrono::milliseconds timeout);
  Status sendLine(std::string_view line, std::chrono::milliseconds timeout);
  // The next line (without its newline); kTimeout when none within `timeout`, kIo when the
  // server closed the connection.
  Result<std::string> readLine(std::chrono::milliseconds timeout);

 private:
  ControlConnection(UniqueFd fd, std::filesystem::path path)
      : fd_(std::move(fd)), path_(std::move(path)) {}
  UniqueFd fd_;
  std::filesystem::path path_;
  std::string buffer_;
};

class FaultInjector;
// The answer to one control line: parsed into a typed fault (parseFaultLine: every argument
// checked) and applied at `now`: "ok <what was done>" or "error control: <why>".
std::string answerFaultLine(FaultInjector& faults, std::string_view line, SimTime now);

// Where `ecsim serve` puts its control socket unless told otherwise, and `ecsim ctl` looks for
// it: /run/ecsim/<interface>.sock.
std::filesystem::path controlSocketDir();
std::filesystem::path defaultControlSocket(std::string_view interfaceName);
// The socket `ecsim ctl` talks to when given none: the only *.sock in controlSocketDir();
// none or several is an error naming them (and how to choose).
Result<std::filesystem::path> findControlSocket(const std::filesystem::path& dir);

// Client side (`ecsim ctl`): connects (giving up after `timeout` when the server does not
// accept), sends one line, waits up to `timeout` for the reply line.
Result<std::string> sendControlLine(const std::filesystem::path& path, std::string_view line,
                                    std::chrono::milliseconds timeout);

}  // namespace ecsim::topology
