// ecsim: a software EtherCAT network. `ecsim serve` answers a master on an interface,
// `ecsim demo` gives the one-command tour.
#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include "tools/ecsim/commands.hpp"
#include "tools/common/install_paths.hpp"

int main(int argc, char** argv) {
  CLI::App app{"ecsim - a software EtherCAT network for hardware-in-the-loop testing"};
  app.set_version_flag("--version", ecsim::tools::versionText("ecsim"));
  app.require_subcommand(1);
  auto serve = ecsim::tools::addServeCommand(app);
  auto demo = ecsim::tools::addDemoCommand(app);
  auto net = ecsim::tools::addNetCommand(app);
  auto study = ecsim::tools::addStudyCommand(app);
  auto replay = ecsim::tools::addReplayCommand(app);
  auto scenario = ecsim::tools::addScenarioCommand(app);
  auto ctl = ecsim::tools::addCtlCommand(app);
  CLI11_PARSE(app, argc, argv);
  try {
    if (app.got_subcommand("serve")) return serve();
    if (app.got_subcommand("demo")) return demo();
    if (app.got_subcommand("net")) return net();
    if (app.got_subcommand("study")) return study();
    if (app.got_subcommand("replay")) return replay();
    if (app.got_subcommand("scenario")) return scenario();
    if (app.got_subcommand("ctl")) return ctl();
  } catch (const std::exception& e) {
    fmt::print(stderr, "ecsim: {}\n", e.what());
    return 1;
  }
  return 1;
}
