// ecmaster foe read | write: files over FoE (ETG.1000.6 §5.7), in the mailbox states or, with
// --boot, in BOOT through the bootstrap mailbox of the slave's SII (INIT -> BOOT before the
// transfer, back to INIT after it, as SOEM's firm_update does).
#include <fmt/core.h>

#include <cstdio>
#include <fstream>
#include <iterator>

#include "tools/ecmaster/commands.hpp"

namespace ecsim::tools::ecmaster {
namespace {

struct FoeOptions {
  std::size_t position{0};
  std::string name;    // the file's name in the slave
  std::string file;    // local file: read from (write), written to (read; empty: stdout)
  std::uint32_t password{0};
  bool boot{false};
};

// Runs `transfer` in BOOT (--boot) or in PREOP and up.
template <typename Transfer>
Status inState(master::Master& m, const FoeOptions& o, Transfer&& transfer) {
  if (!o.boot) {
    ECSIM_TRY(ensureMailbox(m, o.position));
    return transfer();
  }
  ECSIM_TRY(m.enterBootstrap(o.position));
  Status s = transfer();
  Status back = m.leaveBootstrap(o.position);
  ECSIM_TRY(s);
  return back;
}

int runFoeWrite(const GlobalOptions& g, const FoeOptions& o) {
  std::ifstream in(o.file, std::ios::binary);
  if (!in) return fail(fmt::format("cannot open '{}'", o.file));
  const std::vector<std::uint8_t> data((std::istreambuf_iterator<char>(in)),
                                       std::istreambuf_iterator<char>());
  const std::string name = o.name.empty() ? o.file : o.name;
  auto c = connectAndScan(g, false);
  if (!c.ok()) return fail(c.error());
  master::Master& m = (*c)->master();
  if (auto s = inState(m, o, [&] { return m.foeWrite(o.position, name, data, o.password); });
      !s.ok()) {
    return fail(s.error());
  }
  if (g.json) {
    printJson({{"position", o.position}, {"name", name}, {"bytes", data.size()}, {"boot", o.boot}});
  } else {
    fmt::print(stderr, "wrote {} bytes to '{}'\n", data.size(), name);
  }
  return 0;
}

int runFoeRead(const GlobalOptions& g, const FoeOptions& o) {
  auto c = connectAndScan(g, false);
  if (!c.ok()) return fail(c.error());
  master::Master& m = (*c)->master();
  std::vector<std::uint8_t> data;
  auto s = inState(m, o, [&]() -> Status {
    auto r = m.foeRead(o.position, o.name, o.password);
    if (!r.ok()) return r.takeError();
    data = std::move(*r);
    return okStatus();
  });
  if (!s.ok()) return fail(s.error());
  if (o.file.empty()) {
    std::fwrite(data.data(), 1, data.size(), stdout);
    return 0;
  }
  std::ofstream out(o.file, std::ios::binary);
  out.write(reinterpret_cast<const char*>(data.data()), static_cast<std::streamsize>(data.size()));
  if (!out) return fail(fmt::format("cannot write '{}'", o.file));
  if (g.json) {
    printJson({{"position", o.position}, {"name", o.name}, {"bytes", data.size()}, {"file", o.file}});
  }
  return 0;
}

}  // namespace

CommandRunner addFoeCommand(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<FoeOptions>();
  auto* cmd = app.add_subcommand("foe", "Read or write a file over FoE");
  cmd->require_subcommand(1);
  auto* write = cmd->add_subcommand("write", "Write a local file into the slave");
  write->add_option("-p,--position", o->position, "Slave position");
  write->add_option("file", o->file, "Local file to send")->required();
  write->add_option("-n,--name", o->name, "Name in the slave (default: the file argument)");
  write->add_option("--password", o->password, "FoE password (default 0)");
  write->add_flag("--boot", o->boot, "In BOOT (bootstrap mailbox), back to INIT afterwards");
  auto* read = cmd->add_subcommand("read", "Read a file from the slave");
  read->add_option("-p,--position", o->position, "Slave position");
  read->add_option("name", o->name, "Name in the slave")->required();
  read->add_option("-o,--output", o->file, "Write it to this file (default: stdout)");
  read->add_option("--password", o->password, "FoE password (default 0)");
  read->add_flag("--boot", o->boot, "In BOOT (bootstrap mailbox), back to INIT afterwards");
  return [&global, o, write] {
    return write->parsed() ? runFoeWrite(global, *o) : runFoeRead(global, *o);
  };
}

}  // namespace ecsim::tools::ecmaster
