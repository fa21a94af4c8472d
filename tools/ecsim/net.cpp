// `ecsim net up NAME [--netns]` / `ecsim net down NAME`: a veth pair for a master application.
#include <fmt/core.h>

#include "link/veth_setup.hpp"
#include "tools/ecsim/commands.hpp"

namespace ecsim::tools {

CommandRunner addNetCommand(CLI::App& app) {
  struct Options {
    std::string name;
    bool netns{false};
    bool up{false};
  };
  auto opts = std::make_shared<Options>();
  auto* net = app.add_subcommand("net", "Create or remove a veth pair for a master application");
  net->require_subcommand(1);
  auto* up =
      net->add_subcommand("up", "Create veth pair NAME (master end NAME, simulator end NAMEs)");
  up->add_option("name", opts->name, "Pair name (1-14 characters)")->required();
  up->add_flag("--netns", opts->netns, "Put both ends in a new network namespace ecsim-NAME");
  auto* down = net->add_subcommand("down", "Remove what `ecsim net up NAME` created");
  down->add_option("name", opts->name, "Pair name")->required();
  up->callback([opts] { opts->up = true; });
  return [opts] {
    VethSetupOptions o;
    o.ownNamespace = opts->netns;
    if (opts->up) {
      auto s = vethUp(opts->name, o);
      if (!s.ok()) {
        fmt::print(stderr, "ecsim net up: {}\n", s.error().message());
        return 1;
      }
      fmt::print("master interface: {}\nsimulator interface: {}\n", s->masterInterface,
                 s->simulatorInterface);
      if (!s->netns.empty()) {
        fmt::print("namespace: {}  (run: ip netns exec {} YOUR_MASTER {})\n", s->netns, s->netns,
                   s->masterInterface);
      }
      fmt::print("serve with: ecsim serve --iface {}{}\n", s->simulatorInterface,
                 s->netns.empty() ? "" : " --netns " + s->netns);
      return 0;
    }
    auto s = vethDown(opts->name, o);
    if (!s.ok()) {
      fmt::print(stderr, "ecsim net down: {}\n", s.error().message());
      return 1;
    }
    return 0;
  };
}

}  // namespace ecsim::tools
