// ecmaster xml [--output FILE]: an ENI (EtherCATConfig) of the scanned bus, with its process
// data as the master configures it (the slaves are left in PREOP). `ecmaster --config FILE`
// and Master::loadConfig read it back.
#include <fmt/core.h>

#include <fstream>

#include "master/eni_export.hpp"
#include "tools/ecmaster/commands.hpp"

namespace ecsim::tools::ecmaster {

CommandRunner addXmlCommand(CLI::App& app, const GlobalOptions& global) {
  auto* cmd = app.add_subcommand("xml", "Write an ENI (EtherCATConfig) of the scanned bus");
  auto output = std::make_shared<std::string>();
  cmd->add_option("-o,--output", *output, "Write to this file instead of stdout");
  return [&global, output]() -> int {
    auto c = connectAndScan(global, /*reset=*/true);
    if (!c.ok()) return fail(c.error());
    master::Master& m = (*c)->master();
    if (auto s = m.bringTo(AlState::kPreOp); !s.ok()) return fail(s.error());
    if (auto s = m.configureProcessData(); !s.ok()) return fail(s.error());
    const std::string xml = formatEni(master::eniFromMaster(m));
    if (output->empty()) {
      fmt::print("{}", xml);
      return 0;
    }
    std::ofstream out(*output, std::ios::binary);
    out << xml;
    if (!out) return fail(*output + ": cannot be written");
    fmt::print(stderr, "ecmaster: {} slaves written to {}\n", m.slaves().size(), *output);
    return 0;
  };
}

}  // namespace ecsim::tools::ecmaster
