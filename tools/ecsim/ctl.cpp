// `ecsim ctl [--socket PATH | --iface IF] ACTION [ARGS...]`: sends one fault action to a
// running `ecsim serve` through its control socket and prints the reply ("ok ..." or
// "error ..."). The socket is the one `ecsim serve --iface IF` made (/run/ecsim/IF.sock);
// with neither option, the only server's. `ecsim ctl help` lists the actions and their
// arguments (the server refuses anything else, naming the closest valid name).
//   ecsim ctl --iface ecs0 link-down cable=drives
#include <fmt/core.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "tools/ecsim/commands.hpp"
#include "topology/control_server.hpp"
#include "topology/faults.hpp"

namespace ecsim::tools {
namespace {

struct CtlOptions {
  std::string socket;
  std::string iface;
  std::vector<std::string> words;
  unsigned timeoutMs{2000};
};

int printHelp() {
  fmt::print("actions (docs/scenarios.md, \"Live injection\"):\n");
  for (std::string_view verb : topology::faultVerbs()) {
    std::string args;
    for (std::string_view a : topology::faultArguments(verb)) args += fmt::format(" {}=", a);
    fmt::print("  {}{}\n", verb, args);
  }
  return 0;
}

int runCtl(const CtlOptions& o) {
  if (o.words.size() == 1 && (o.words[0] == "help" || o.words[0] == "list")) return printHelp();
  if (!o.socket.empty() && !o.iface.empty()) {
    fmt::print(stderr, "ecsim ctl: give --socket or --iface, not both\n");
    return 2;
  }
  std::filesystem::path socket = o.socket;
  if (!o.iface.empty()) socket = topology::defaultControlSocket(o.iface);
  if (socket.empty()) {
    auto found = topology::findControlSocket(topology::controlSocketDir());
    if (!found.ok()) {
      fmt::print(stderr, "ecsim ctl: {}\n", found.error().message());
      return 2;
    }
    socket = *found;
  }
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
  auto reply = topology::sendControlLine(socket, line, std::chrono::milliseconds(o.timeoutMs));
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
  cmd->add_option("--socket", opts->socket,
                  "Control socket of the server (default: the only one in /run/ecsim)");
  cmd->add_option("--iface", opts->iface,
                  "The server of `ecsim serve --iface IF` (its socket /run/ecsim/IF.sock)");
  cmd->add_option("--timeout-ms", opts->timeoutMs,
                  "How long to wait for the connection and for the reply")
      ->check(CLI::Range(1u, 3'600'000u))
      ->capture_default_str();
  cmd->add_option("action", opts->words,
                  "ACTION [key=value ...] (docs/scenarios.md); `help` lists the actions")
      ->required();
  return [opts] { return runCtl(*opts); };
}

}  // namespace ecsim::tools
