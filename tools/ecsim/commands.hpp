// Subcommands of the `ecsim` tool. Each registers its options on the CLI11 app and returns
// the process exit code when run. This is the edge of the program: errors are printed here.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>

namespace ecsim::tools {

using CommandRunner = std::function<int()>;

CommandRunner addServeCommand(CLI::App& app);
CommandRunner addDemoCommand(CLI::App& app);
CommandRunner addNetCommand(CLI::App& app);
CommandRunner addStudyCommand(CLI::App& app);
CommandRunner addReplayCommand(CLI::App& app);
CommandRunner addScenarioCommand(CLI::App& app);
CommandRunner addCtlCommand(CLI::App& app);

}  // namespace ecsim::tools
