// ecmaster: ecsim's EtherCAT master as a command-line tool, in the habits of IgH's
// `ethercat` command:
//
//   ecmaster --iface ecm0 slaves
//   ecmaster --iface ecm0 upload -p 3 0x1018:02 --type uint32
//   ecmaster --iface ecm0 cyclic --cycle-us 1000 --seconds 10
//   ecmaster --sim examples/topologies/demo.xml pdos       (in-process simulator, no root)
#include <fmt/core.h>

#include <CLI/CLI.hpp>

#include "tools/common/install_paths.hpp"
#include "tools/ecmaster/commands.hpp"

int main(int argc, char** argv) {
  using namespace ecsim::tools::ecmaster;
  CLI::App app{"ecmaster - ecsim's EtherCAT master"};
  app.set_version_flag("--version", ecsim::tools::versionText("ecmaster"));
  app.require_subcommand(1);
  app.fallthrough();
  GlobalOptions global;
  app.add_option("-i,--iface", global.connect.iface, "Network interface of the EtherCAT bus");
  app.add_option("--redundant-iface", global.connect.redundantIface,
                 "Second port of a cable-redundant ring (the line's far end); ring breaks are "
                 "reported as events");
  app.add_option("--netns", global.connect.netns, "Open the interface in this network namespace");
  app.add_option("--sim", global.connect.simTopology,
                 "Talk to an in-process simulated network built from this topology file");
  app.add_option("--sim-slaves", global.connect.simSlaves,
                 "Talk to an in-process simulated line of N generic slaves");
  app.add_option("--config", global.config,
                 "Expected slaves (ENI EtherCATConfig or EcsimMaster XML): identity check");
  app.add_flag("--check-serial", global.checkSerial,
               "With --config: the serial numbers must match too (off: vendor, product and the "
               "configured revision are checked, as IgH and TwinCAT do)");
  app.add_option("--names", global.names,
                 "Name the slaves by bus position after this topology or ENI file "
                 "(Drive1.Statusword); --sim TOPOLOGY names them by itself");
  app.add_option("--timeout-ms", global.timeoutMs,
                 "Frame timeout in ms (default: 2, raised to twice the round trip the scan "
                 "measures on a long network; given: kept, with a warning when too short)")
      ->check(CLI::Range(1u, 10000u));
  app.add_flag("--json", global.json, "Machine-readable output");
  const std::vector<std::pair<std::string, CommandRunner>> commands{
      {"slaves", addSlavesCommand(app, global)},     {"states", addStatesCommand(app, global)},
      {"sii", addSiiCommand(app, global)},           {"reg", addRegCommand(app, global)},
      {"pdos", addPdosCommand(app, global)},         {"upload", addUploadCommand(app, global)},
      {"download", addDownloadCommand(app, global)}, {"sdos", addSdosCommand(app, global)},
      {"cyclic", addCyclicCommand(app, global)},     {"xml", addXmlCommand(app, global)},
      {"eoe", addEoeCommand(app, global)},           {"foe", addFoeCommand(app, global)},
      {"soe", addSoeCommand(app, global)},
  };
  CLI11_PARSE(app, argc, argv);
  try {
    for (const auto& [name, run] : commands) {
      if (app.got_subcommand(name)) return run();
    }
  } catch (const std::exception& e) {
    fmt::print(stderr, "ecmaster: {}\n", e.what());
    return 1;
  }
  return 2;
}
