// Subcommands of `ecmaster`, in the habits of IgH's `ethercat` tool. Each registers its
// options on the CLI11 app and returns the exit code when run (0 ok, 1 failed, 2 usage).
// This is the edge of the program: errors are printed here.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "master/master.hpp"
#include "tools/ecmaster/connection.hpp"

namespace ecsim::tools::ecmaster {

struct GlobalOptions {
  ConnectOptions connect;
  bool json{false};
  std::string config;     // --config FILE: expected slaves (identity check)
  std::string names;      // --names FILE: slave names by bus position (topology or ENI)
  bool checkSerial{false};  // --check-serial: the identity check compares serial numbers too
  // --timeout-ms: per-frame timeout; 0 (not given): 2 ms, raised after the scan's count to
  // what the network needs (master::ScanOptions::adaptTimeout), said on stderr.
  unsigned timeoutMs{0};
};

using CommandRunner = std::function<int()>;

CommandRunner addSlavesCommand(CLI::App& app, const GlobalOptions& global);
CommandRunner addStatesCommand(CLI::App& app, const GlobalOptions& global);
CommandRunner addSiiCommand(CLI::App& app, const GlobalOptions& global);
CommandRunner addRegCommand(CLI::App& app, const GlobalOptions& global);
CommandRunner addPdosCommand(CLI::App& app, const GlobalOptions& global);
CommandRunner addUploadCommand(CLI::App& app, const GlobalOptions& global);
CommandRunner addDownloadCommand(CLI::App& app, const GlobalOptions& global);
CommandRunner addSdosCommand(CLI::App& app, const GlobalOptions& global);
CommandRunner addSoeCommand(CLI::App& app, const GlobalOptions& global);
CommandRunner addCyclicCommand(CLI::App& app, const GlobalOptions& global);
CommandRunner addXmlCommand(CLI::App& app, const GlobalOptions& global);
CommandRunner addEoeCommand(CLI::App& app, const GlobalOptions& global);
CommandRunner addFoeCommand(CLI::App& app, const GlobalOptions& global);

// ---- shared by the commands --------------------------------------------------------------------

// Opens the connection and scans. `reset` resets the slaves to INIT and defaults first (a
// start-up); without it the scan leaves their state alone (for looking at a running bus).
// `recovery`: MasterOptions::recovery (cyclic health: lost slaves reported and brought back).
Result<std::unique_ptr<Connection>> connectAndScan(const GlobalOptions& global, bool reset,
                                                   bool recovery = true);
// Mailbox services need PREOP: a slave found in INIT is brought there (with the others).
Status ensureMailbox(master::Master& m, std::size_t position);
// Prints "ecmaster: <message>" to stderr and returns 1.
int fail(const Error& error);
int fail(const std::string& message);
// Prints JSON (indented) to stdout.
void printJson(const nlohmann::json& value);
nlohmann::json slaveJson(const master::SlaveInfo& slave);
std::string hex(std::uint64_t value, int digits);

}  // namespace ecsim::tools::ecmaster
