// The live-injection control socket of `ecsim serve` (docs/scenarios.md, "Live injection"): a
// Unix-domain stream socket, owner-only (mode 0600), that takes one action per line in the
// text form of topology/faults.hpp ("link-down cable=drives") and answers one line, "ok ..."
// or "error ...". poll() never blocks: the serve loop calls it between frames, so an action
// takes effect between two frames as on a real cable.
#pragma once

#include <chrono>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "link/fd.hpp"
#include "protocol/result.hpp"

namespace ecsim::topology {

class ControlServer {
 public:
  // Handles one request line; returns the reply (without newline).
  using Handler = std::function<std::string(std::string_view line)>;

  // Creates the socket at `path` (a stale socket file there is replaced; the directory is
  // created with mode 0700 when missing).
  static Result<ControlServer> open(const std::filesystem::path& path);
  ControlServer(ControlServer&&) noexcept;
  ControlServer& operator=(ControlServer&&) noexcept;
  ~ControlServer();  // removes the socket file

  // Accepts waiting clients, reads complete lines, answers them. Never blocks.
  void poll(const Handler& handler);
  const std::filesystem::path& path() const { return path_; }

 private:
  ControlServer(UniqueFd fd, std::filesystem::path path)
      : fd_(std::move(fd)), path_(std::move(path)) {}
  struct Client {
    UniqueFd fd;
    std::string buffer;
  };
  UniqueFd fd_;
  std::filesystem::path path_;
  std::vector<Client> clients_;
};

// Client side (`ecsim ctl`): sends one line, waits up to `timeout` for the reply line.
Result<std::string> sendControlLine(const std::filesystem::path& path, std::string_view line,
                                    std::chrono::milliseconds timeout);

}  // namespace ecsim::topology
