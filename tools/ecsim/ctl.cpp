// `ecsim ctl [--socket PATH | --iface IF] COMMAND [ARGS...]`: asks a running `ecsim serve`
// through its control socket (docs/control.md). Queries go as JSON requests and print the
// answer plainly (a value, a table); a fault action goes as its text line and prints the reply
// ("ok ..." or "error ..."). The socket is the one `ecsim serve --iface IF` made
// (/run/ecsim/IF.sock); with neither option, the only server's. `ecsim ctl help` lists it all.
//   ecsim ctl get DO1 "Output 8"          -> 1
//   ecsim ctl --iface ecs0 link-down cable=drives
#include <fmt/core.h>

#include <chrono>
#include <filesystem>
#include <nlohmann/json.hpp>
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
  unsigned count{0};  // subscribe: stop after this many changes (0: until interrupted)
};

constexpr std::string_view kQueryHelp =
    "queries (docs/control.md):\n"
    "  get SLAVE ENTRY            a process-data entry (\"Output 8\"), or get SLAVE.ENTRY\n"
    "  get SLAVE 0xIIII:SS        an object-dictionary entry (index, subindex in hex)\n"
    "  set SLAVE ENTRY|0xIIII:SS VALUE   an input entry or an object\n"
    "  reg SLAVE REGISTER [VALUE] an ESC register by name (AlStatus) or address (0x0130);\n"
    "                             with VALUE written from the slave's side (its PDI)\n"
    "  state                      every slave's AL state and status code\n"
    "  faults                     the fault actions applied through the socket\n"
    "  subscribe SLAVE ENTRY      print the entry's value at every change (--count N)\n"
    "  '{\"op\":...}'               a JSON request, its answer printed as is\n";

bool isObjectIndex(const std::string& s) {
  return s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X') &&
         s.find(':') != std::string::npos;
}

// The JSON request of a query command, or null when `words` are a fault action.
Result<nlohmann::json> queryRequest(const std::vector<std::string>& w) {
  using nlohmann::json;
  const std::string& verb = w[0];
  const std::size_t n = w.size() - 1;
  auto usage = [&](std::string_view form) -> Result<json> {
    return makeError(ErrorCode::kInvalidArgument, fmt::format("usage: ecsim ctl {}", form));
  };
  auto target = [&](json& j, const std::string& slave, const std::string& what) {
    j["slave"] = slave;
    j[isObjectIndex(what) ? "object" : "entry"] = what;
  };
  if (verb == "get") {
    json j{{"op", "get"}};
    if (n == 1) {
      j["name"] = w[1];
    } else if (n == 2) {
      target(j, w[1], w[2]);
    } else {
      return usage("get SLAVE ENTRY|0xIIII:SS  (or get SLAVE.ENTRY)");
    }
    return j;
  }
  // A value typed on the command line: a JSON number, true/false, or 0x... hex.
  auto valueOf = [](const std::string& text) -> Result<json> {
    json value = json::parse(text, nullptr, false);
    if (!value.is_discarded() && (value.is_number() || value.is_boolean())) return value;
    const bool hex = text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X');
    if (!hex) {
      return makeError(ErrorCode::kInvalidArgument,
                       "value '" + text + "' is not a number (or true/false, 0x...)");
    }
    try {
      std::size_t used = 0;
      value = std::stoull(text.substr(2), &used, 16);
      if (used != text.size() - 2) throw std::invalid_argument("");
    } catch (const std::exception&) {
      return makeError(ErrorCode::kInvalidArgument, "value '" + text + "' is not a number");
    }
    return value;
  };
  if (verb == "set") {
    if (n != 3) return usage("set SLAVE ENTRY|0xIIII:SS VALUE");
    json j{{"op", "set"}};
    target(j, w[1], w[2]);
    ECSIM_ASSIGN_OR_RETURN(j["value"], valueOf(w[3]));
    return j;
  }
  if (verb == "reg") {
    if (n != 2 && n != 3) return usage("reg SLAVE REGISTER [VALUE]");
    if (n == 2) return json{{"op", "get"}, {"slave", w[1]}, {"register", w[2]}};
    json j{{"op", "set"}, {"slave", w[1]}, {"register", w[2]}};
    ECSIM_ASSIGN_OR_RETURN(j["value"], valueOf(w[3]));
    return j;
  }
  if (verb == "state" || verb == "faults") {
    if (n != 0) return usage(verb);
    return json{{"op", verb}};
  }
  if (verb == "subscribe") {
    json j{{"op", "subscribe"}};
    if (n == 1) {
      j["name"] = w[1];
    } else if (n == 2) {
      j["slave"] = w[1];
      j["entry"] = w[2];
    } else {
      return usage("subscribe SLAVE ENTRY [--count N]");
    }
    return j;
  }
  return json(nullptr);
}

// The answer of a query, printed plainly; the exit status.
int printAnswer(const std::string& verb, const nlohmann::json& a) {
  if (!a.value("ok", false)) {
    fmt::print(stderr, "ecsim ctl: {}\n", a.value("error", a.dump()));
    return 1;
  }
  auto text = [](const nlohmann::json& v) {
    return v.is_string() ? v.get<std::string>() : v.dump();
  };
  if (verb == "state") {
    for (const auto& s : a["slaves"]) {
      fmt::print("{:>3}  {:<16} {:<7}{} 0x{:04x}\n", s["position"].get<int>(),
                 s["name"].get<std::string>(), s["state"].get<std::string>(),
                 s["error"].get<bool>() ? "+ERR" : "    ", s["alStatusCode"].get<unsigned>());
    }
  } else if (verb == "faults") {
    for (const auto& f : a["faults"]) {
      fmt::print("{:.3f} s  {}  ({})\n", static_cast<double>(f["atNs"].get<std::int64_t>()) / 1e9,
                 f["action"].get<std::string>(), f["result"].get<std::string>());
    }
  } else if (a.contains("value")) {
    fmt::print("{}\n", text(a["value"]));
  } else if (a.contains("bytes")) {
    fmt::print("{}\n", text(a["bytes"]));
  } else {
    fmt::print("{}\n", a.dump());
  }
  return 0;
}

int runQuery(const std::filesystem::path& socket, const CtlOptions& o, const nlohmann::json& req,
             bool raw) {
  const std::chrono::milliseconds timeout(o.timeoutMs);
  auto connection = topology::ControlConnection::open(socket, timeout);
  if (!connection.ok()) {
    fmt::print(stderr, "ecsim ctl: {}\n", connection.error().message());
    return 2;
  }
  const std::string line = raw ? o.words[0] : req.dump();
  if (auto sent = connection->sendLine(line, timeout); !sent.ok()) {
    fmt::print(stderr, "ecsim ctl: {}\n", sent.error().message());
    return 2;
  }
  const bool subscribe = !raw && req.value("op", "") == "subscribe";
  unsigned changes = 0;
  for (bool first = true;; first = false) {
    // A subscription waits for changes as long as it takes (timeouts only end a wait).
    auto answer = connection->readLine(timeout);
    if (!answer.ok() && subscribe && !first && answer.error().code == ErrorCode::kTimeout) {
      continue;
    }
    if (!answer.ok()) {
      fmt::print(stderr, "ecsim ctl: {}\n", answer.error().message());
      return 2;
    }
    if (raw) {
      fmt::print("{}\n", *answer);
      return answer->find("\"ok\":true") != std::string::npos ? 0 : 1;
    }
    auto a = nlohmann::json::parse(*answer, nullptr, false);
    if (a.is_discarded()) {
      fmt::print(stderr, "ecsim ctl: the server answered no JSON: {}\n", *answer);
      return 2;
    }
    if (!subscribe) return printAnswer(o.words[0], a);
    if (first) {
      if (!a.value("ok", false)) return printAnswer(o.words[0], a);
      fmt::print("{} {}\n", a["subscribed"].get<std::string>(), a["value"].dump());
    } else {
      fmt::print("{} {}\n", a.value("name", ""), a["value"].dump());
      if (o.count != 0 && ++changes >= o.count) return 0;
    }
    std::fflush(stdout);
  }
}

int printHelp() {
  fmt::print("{}", kQueryHelp);
  fmt::print("fault actions (docs/scenarios.md, \"Live injection\"):\n");
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
  // Usage first: a wrong command line needs no server.
  const bool raw = o.words.size() == 1 && !o.words[0].empty() && o.words[0][0] == '{';
  auto request = raw ? Result<nlohmann::json>(nlohmann::json(nullptr)) : queryRequest(o.words);
  if (!request.ok()) {
    fmt::print(stderr, "ecsim ctl: {}\n", request.error().message());
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
  if (raw || !request->is_null()) return runQuery(socket, o, *request, raw);
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
  auto* cmd = app.add_subcommand("ctl", "Query or control a running `ecsim serve`");
  cmd->add_option("--socket", opts->socket,
                  "Control socket of the server (default: the only one in /run/ecsim)");
  cmd->add_option("--iface", opts->iface,
                  "The server of `ecsim serve --iface IF` (its socket /run/ecsim/IF.sock)");
  cmd->add_option("--timeout-ms", opts->timeoutMs,
                  "How long to wait for the connection and for the reply")
      ->check(CLI::Range(1u, 3'600'000u))
      ->capture_default_str();
  cmd->add_option("--count", opts->count, "subscribe: stop after N changes (default: never)");
  cmd->add_option("action", opts->words,
                  "COMMAND [ARGS...] (docs/control.md); `help` lists the commands")
      ->required();
  return [opts] { return runCtl(*opts); };
}

}  // namespace ecsim::tools
