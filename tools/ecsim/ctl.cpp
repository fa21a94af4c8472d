// `ecsim ctl [--socket PATH] ACTION [ARGS...]`: sends one fault action to a running
// `ecsim serve` through its control socket and prints the reply ("ok ..." or "error ...").
//   ecsim ctl --socket /run/ecsim/ecsim0.sock link-down cable=drives
#include <fmt/core.h>

#include <chrono>
#include <string>
#include <vector>

#include "tools/ecsim/commands.hpp"
#include "topology/control_server.hpp"

namespace ecsim::tools {
namespace {

struct CtlOptions {
  std::string socket{"/run/ecsim/ecsim0.sock"};
  std::vector<std::string> words;
  unsigned timeoutMs{2000};
};

int runCtl(const CtlOptions& o) {
  std::string line;
  for (const auto& w : o.words) {
    // One request is one line: a newline in an argument would send a second action.
    for (char c : w) {
      if (c == '\n' || c == '\r') {
        fmt::print(stderr, "ecsim ctl: argument '{}' holds a line break\n", w);
        return 2;
      }
    }
    if (!line.empty()) line += ' ';
    // An argument whose value has spaces is sent quoted: signal="sine amplitude=5".
    const auto eq = w.find('=');
    if (eq != std::string::npos && w.find(' ') != std::string::npos && w[eq + 1] != '"') {
      line += w.substr(0, eq + 1) + "\"" + w.substr(eq + 1) + "\"";
    } else {
      line += w;
    }
  }
  auto reply = topology::sendControlLine(o.socket, line, std::chrono::milliseconds(o.timeoutMs));
  if (!reply.ok()) {
    fmt::print(stderr, "ecsim ctl: {}\n", reply.error().message());
    return 2;
  }
  fmt::print("{}\n", *reply);
  return reply->rfind("ok", 0) == 0 ? 0 : 1;
}

}  // namespace

CommandRunner addCtlCommand(CLI::App& app) {
  auto opts = std::make_shared<CtlOptions>();
  auto* cmd = app.add_subcommand("ctl", "Send a fault action to a running `ecsim serve`");
  cmd->add_option("--socket", opts->socket, "Control socket of the server")->capture_default_str();
  cmd->add_option("--timeout-ms", opts->timeoutMs,
                  "How long to wait for the connection and for the reply")
      ->check(CLI::Range(1u, 3'600'000u))
      ->capture_default_str();
  cmd->add_option("action", opts->words, "ACTION [key=value ...] (docs/scenarios.md)")->required();
  return [opts] { return runCtl(*opts); };
}

}  // namespace ecsim::tools
