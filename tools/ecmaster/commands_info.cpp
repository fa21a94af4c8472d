// ecmaster slaves | states [STATE] | sii | reg read/write | pdos
#include <fmt/core.h>

#include <iostream>

#include "protocol/registers.hpp"
#include "tools/ecmaster/commands.hpp"
#include "tools/ecmaster/values.hpp"
#include "topology/slave_names.hpp"

namespace ecsim::tools::ecmaster {

std::string hex(std::uint64_t value, int digits) {
  return fmt::format("0x{:0{}x}", value, digits);
}

int fail(const std::string& message) {
  fmt::print(stderr, "ecmaster: {}\n", message);
  return 1;
}

int fail(const Error& error) {
  return fail(error.message());
}

void printJson(const nlohmann::json& value) {
  std::cout << value.dump(2) << "\n";
}

// Says what the scan's count told about the frame timeout: raised (and to what), or, with
// --timeout-ms, that it is too short for this network and what to set.
void reportTimeout(const master::Master& master, const GlobalOptions& global) {
  const auto& advice = master.timeoutAdvice();
  if (!advice) return;
  const auto ms = [](SimTime ns) { return static_cast<double>(ns) / kNsPerMs; };
  if (advice->raised) {
    fmt::print(stderr,
               "ecmaster: frame timeout raised from {:g} ms to {:.2f} ms: the count frame's round "
               "trip through {} slaves was {:.3f} ms (set --timeout-ms to choose)\n",
               ms(advice->before), ms(advice->needed), advice->slaves, ms(advice->roundTrip));
  }
  if (advice->framesRaised) {
    fmt::print(stderr,
               "ecmaster: frames in flight raised from {} to {}: the line holds {} full-size "
               "frames during one round trip\n",
               advice->framesBefore, master.transport().options().maxFramesInFlight,
               advice->framesFitting);
  }
  if (!advice->raised && global.timeoutMs != 0 && advice->needed > advice->before) {
    fmt::print(stderr,
               "ecmaster: warning: --timeout-ms {} is short for this network: the count frame's "
               "round trip through {} slaves was {:.3f} ms; frames may time out, set --timeout-ms "
               "{} or more\n",
               global.timeoutMs, advice->slaves, ms(advice->roundTrip),
               (advice->needed + kNsPerMs - 1) / kNsPerMs);
  }
}

Result<std::unique_ptr<Connection>> connectAndScan(const GlobalOptions& global, bool reset,
                                                   bool recovery) {
  master::MasterOptions options;
  options.scan.resetToDefaults = reset;
  options.recovery = recovery;
  if (global.timeoutMs != 0) {
    options.transport.timeout = static_cast<SimTime>(global.timeoutMs) * kNsPerMs;
    options.scan.adaptTimeout = false;  // the user's choice stands (a warning if too short)
  }
  options.identity.serial = global.checkSerial;
  ECSIM_ASSIGN_OR_RETURN(auto connection, Connection::open(global.connect, options));
  if (!global.config.empty()) {
    ECSIM_TRY(connection->master().loadConfig(global.config));
    // An ENI is a vendor format: what its reader ignored is said, not lost (issue #21).
    if (const auto& eni = connection->master().config()->eni) {
      for (const auto& w : eni->warnings) fmt::print(stderr, "ecmaster: warning: {}\n", w);
    }
  }
  // Names: --names FILE, else the simulated network's own (unless --config names them).
  if (!global.names.empty()) {
    ECSIM_ASSIGN_OR_RETURN(auto names, topology::loadSlaveNames(global.names));
    connection->master().setSlaveNames(std::move(names));
  } else if (connection->simulated() && global.config.empty()) {
    connection->master().setSlaveNames(connection->simulatedNames());
  }
  const Status scanned = connection->master().scan();
  reportTimeout(connection->master(), global);
  ECSIM_TRY(scanned);
  const std::size_t named = connection->master().slaveNames().size();
  if (!global.names.empty() && named != connection->master().slaves().size()) {
    fmt::print(stderr, "ecmaster: warning: {} names {} slaves, the bus has {}\n", global.names,
               named, connection->master().slaves().size());
  }
  if (const auto& config = connection->master().config()) {
    ECSIM_TRY(master::checkIdentities(*config, connection->master().slaves(),
                                      connection->master().options().identity));
  }
  return connection;
}

nlohmann::json slaveJson(const master::SlaveInfo& s) {
  nlohmann::json j;
  j["position"] = s.position;
  j["station"] = s.station;
  j["alias"] = s.alias;
  j["state"] = master::describeAlStatus(s.alStatus);
  j["alStatusCode"] = s.alStatusCode;
  j["vendorId"] = s.identity().vendorId;
  j["productCode"] = s.identity().productCode;
  j["revision"] = s.identity().revision;
  j["serial"] = s.identity().serial;
  j["name"] = s.displayName();  // the configured name (topology, ENI), else the SII's
  j["siiName"] = s.name;
  j["escType"] = s.escType;
  j["fmmus"] = s.fmmuCount;
  j["syncManagers"] = s.syncManagerCount;
  j["dc"] = s.hasDc();
  j["activePorts"] = s.activePorts;
  j["parent"] = s.parent;
  j["mailboxProtocols"] = s.mailbox ? s.mailbox->protocols : 0;
  return j;
}

namespace {

struct PositionOption {
  std::size_t position{0};
};

int runSlaves(const GlobalOptions& g, bool verbose) {
  auto c = connectAndScan(g, false);
  if (!c.ok()) return fail(c.error());
  const auto& slaves = (*c)->master().slaves();
  if (g.json) {
    nlohmann::json list = nlohmann::json::array();
    for (const auto& s : slaves) list.push_back(slaveJson(s));
    printJson(list);
    return 0;
  }
  for (const auto& s : slaves) {
    fmt::print("{:3}  {}  {:<12} vendor {} product {} rev {}  {}\n", s.position, hex(s.station, 4),
               master::describeAlStatus(s.alStatus), hex(s.identity().vendorId, 8),
               hex(s.identity().productCode, 8), hex(s.identity().revision, 8),
               s.configuredName.empty() || s.configuredName == s.name
                   ? s.displayName()
                   : s.configuredName + " (" + s.name + ")");
    if (!verbose) continue;
    fmt::print("       ESC type {} rev {} build {}, {} FMMUs, {} SMs, {} KB RAM{}\n",
               hex(s.escType, 2), s.escRevision, s.escBuild, s.fmmuCount, s.syncManagerCount,
               s.ramKb, s.hasDc() ? ", DC" : "");
    fmt::print("       alias {}, ports {:04b} (3..0), parent {}, serial {}\n", s.alias,
               s.activePorts, s.parent < 0 ? std::string("master") : std::to_string(s.parent),
               hex(s.identity().serial, 8));
    if (s.mailbox) {
      fmt::print("       mailbox out {} +{}, in {} +{}, protocols {}\n",
                 hex(s.mailbox->outStart, 4), s.mailbox->outSize, hex(s.mailbox->inStart, 4),
                 s.mailbox->inSize, hex(s.mailbox->protocols, 4));
    }
    if (s.alStatusCode != 0) {
      fmt::print("       AL status code {}\n", master::describeAlStatusCode(s.alStatusCode));
    }
  }
  if (slaves.empty()) fmt::print("no slaves found\n");
  return 0;
}

Result<AlState> parseState(std::string text) {
  for (auto& ch : text) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  for (AlState s : {AlState::kInit, AlState::kPreOp, AlState::kSafeOp, AlState::kOp}) {
    if (toString(s) == text) return s;
  }
  if (text == "SAFE-OP" || text == "SAFE_OP") return AlState::kSafeOp;
  if (text == "PRE-OP" || text == "PRE_OP") return AlState::kPreOp;
  return makeError(ErrorCode::kInvalidArgument,
                   "unknown state '" + text + "' (INIT, PREOP, SAFEOP, OP)");
}

int runStates(const GlobalOptions& g, const std::string& target) {
  std::optional<AlState> state;
  if (!target.empty()) {
    auto s = parseState(target);
    if (!s.ok()) return fail(s.error());
    state = *s;
  }
  auto c = connectAndScan(g, false);
  if (!c.ok()) return fail(c.error());
  master::Master& m = (*c)->master();
  Status result = state ? m.bringTo(*state) : m.readStates();
  if (state) (void)m.readStates();
  if (g.json) {
    nlohmann::json j;
    nlohmann::json list = nlohmann::json::array();
    for (const auto& s : m.slaves()) {
      list.push_back({{"position", s.position},
                      {"station", s.station},
                      {"name", s.displayName()},
                      {"state", master::describeAlStatus(s.alStatus)},
                      {"alStatusCode", s.alStatusCode},
                      {"alStatusText", std::string(alStatusCodeText(s.alStatusCode))}});
    }
    j["slaves"] = list;
    j["ok"] = result.ok();
    if (!result.ok()) j["error"] = result.error().message();
    printJson(j);
  } else {
    for (const auto& s : m.slaves()) {
      fmt::print("{:3}  {}  {:<12} {}{}\n", s.position, hex(s.station, 4),
                 master::describeAlStatus(s.alStatus), s.displayName(),
                 s.alStatusCode != 0
                     ? "  AL status code " + master::describeAlStatusCode(s.alStatusCode)
                     : "");
    }
  }
  return result.ok() ? 0 : fail(result.error());
}

void printSii(const master::SlaveInfo& s) {
  const SiiContents& c = s.siiContents;
  fmt::print("{}\n", s.label());
  fmt::print("  identity      vendor {} product {} revision {} serial {}\n",
             hex(c.identity.vendorId, 8), hex(c.identity.productCode, 8),
             hex(c.identity.revision, 8), hex(c.identity.serial, 8));
  fmt::print("  config        PDI control {} PDI config {} alias {}\n", hex(c.config.pdiControl, 4),
             hex(c.config.pdiConfiguration, 4), c.config.stationAlias);
  fmt::print("  mailbox       out {} +{}, in {} +{}, protocols {}\n",
             hex(c.standardMailbox.receiveOffset, 4), c.standardMailbox.receiveSize,
             hex(c.standardMailbox.sendOffset, 4), c.standardMailbox.sendSize,
             hex(c.mailboxProtocols, 4));
  fmt::print("  EEPROM        {} bytes, version {}, {} bytes read\n", c.eepromBytes(), c.version,
             s.sii.size());
  for (std::size_t i = 0; i < c.strings.size(); ++i) {
    fmt::print("  string {:3}    {}\n", i + 1, c.strings[i]);
  }
  if (c.general) {
    fmt::print(
        "  general       name #{} group #{} CoE details {} FoE {} EoE {} flags {} "
        "E-bus {} mA\n",
        c.general->nameIndex, c.general->groupIndex, hex(c.general->coeDetails, 2),
        hex(c.general->foeDetails, 2), hex(c.general->eoeDetails, 2), hex(c.general->flags, 2),
        c.general->currentOnEbus);
  }
  for (std::size_t i = 0; i < c.fmmus.size(); ++i) {
    fmt::print("  FMMU{}         usage {}\n", i, hex(static_cast<unsigned>(c.fmmus[i]), 2));
  }
  for (std::size_t i = 0; i < c.syncManagers.size(); ++i) {
    const auto& sm = c.syncManagers[i];
    fmt::print("  SM{}           start {} length {} control {} enable {} type {}\n", i,
               hex(sm.startAddress, 4), sm.length, hex(sm.control, 2), hex(sm.enable, 2),
               static_cast<unsigned>(sm.type));
  }
  for (const auto* list : {&c.rxPdos, &c.txPdos}) {
    for (const auto& pdo : *list) {
      fmt::print("  {} {} SM{} \"{}\"\n", list == &c.rxPdos ? "RxPDO" : "TxPDO", hex(pdo.index, 4),
                 pdo.syncManager, c.string(pdo.nameIndex));
      for (const auto& e : pdo.entries) {
        fmt::print("      {}:{:02x} {:3} bit type {} \"{}\"\n", hex(e.index, 4), e.subIndex,
                   e.bitLength, hex(e.dataType, 4), c.string(e.nameIndex));
      }
    }
  }
  if (s.siiDamage) fmt::print("  damage        {}\n", s.siiDamage->message());
}

int runSii(const GlobalOptions& g, std::size_t position, bool raw) {
  auto c = connectAndScan(g, false);
  if (!c.ok()) return fail(c.error());
  const auto& slaves = (*c)->master().slaves();
  if (position >= slaves.size()) return fail(fmt::format("no slave at position {}", position));
  const auto& s = slaves[position];
  if (g.json) {
    nlohmann::json j = slaveJson(s);
    j["sii"] = hexBytes(s.sii);
    j["strings"] = s.siiContents.strings;
    printJson(j);
  } else if (raw) {
    for (std::size_t i = 0; i < s.sii.size(); i += 16) {
      fmt::print(
          "{:04x}  {}\n", i,
          hexBytes(ConstBytes(s.sii).subspan(i, std::min<std::size_t>(16, s.sii.size() - i))));
    }
  } else {
    printSii(s);
  }
  return 0;
}

int runRegRead(const GlobalOptions& g, std::size_t position, const std::string& addressText,
               unsigned length, const std::string& typeName) {
  auto address = parseUnsigned(addressText, 0xFFFF);
  if (!address.ok()) return fail(address.error());
  auto type = typeName.empty() ? Result<ValueType>(ValueType::kRaw) : parseValueType(typeName);
  if (!type.ok()) return fail(type.error());
  if (valueSize(*type) != 0) length = static_cast<unsigned>(valueSize(*type));
  auto c = connectAndScan(g, false);
  if (!c.ok()) return fail(c.error());
  auto bytes = (*c)->master().readRegisters(position, static_cast<std::uint16_t>(*address),
                                            static_cast<std::uint16_t>(length));
  if (!bytes.ok()) return fail(bytes.error());
  auto name = reg::findRegister(static_cast<std::uint16_t>(*address));
  if (g.json) {
    nlohmann::json j{{"position", position}, {"address", *address}, {"bytes", hexBytes(*bytes)}};
    if (name) j["register"] = std::string(name->name);
    if (auto v = jsonValue(*type, *bytes); v.ok()) j["value"] = *v;
    printJson(j);
    return 0;
  }
  auto text = formatValue(*type, *bytes);
  if (!text.ok()) return fail(text.error());
  fmt::print("{}{}\n", *text, name ? fmt::format("  ({})", name->name) : "");
  return 0;
}

int runRegWrite(const GlobalOptions& g, std::size_t position, const std::string& addressText,
                const std::string& valueText, const std::string& typeName) {
  auto address = parseUnsigned(addressText, 0xFFFF);
  if (!address.ok()) return fail(address.error());
  auto type = parseValueType(typeName);
  if (!type.ok()) return fail(type.error());
  auto bytes = encodeValue(*type, valueText);
  if (!bytes.ok()) return fail(bytes.error());
  auto c = connectAndScan(g, false);
  if (!c.ok()) return fail(c.error());
  auto status =
      (*c)->master().writeRegisters(position, static_cast<std::uint16_t>(*address), *bytes);
  if (!status.ok()) return fail(status.error());
  if (g.json)
    printJson({{"position", position}, {"address", *address}, {"written", hexBytes(*bytes)}});
  return 0;
}

int runPdos(const GlobalOptions& g, std::optional<std::size_t> position) {
  auto c = connectAndScan(g, false);
  if (!c.ok()) return fail(c.error());
  master::Master& m = (*c)->master();
  if (auto s = m.bringTo(AlState::kPreOp); !s.ok()) return fail(s.error());
  if (auto s = m.configureProcessData(); !s.ok()) return fail(s.error());
  const auto& layout = m.layout();
  nlohmann::json list = nlohmann::json::array();
  for (const auto& sl : layout.slaves) {
    if (position && sl.position != *position) continue;
    const auto& info = m.slaves()[sl.position];
    nlohmann::json js{{"position", sl.position},
                      {"source", std::string(toString(m.processData()[sl.position].source))},
                      {"outputOffset", sl.outputOffset},
                      {"outputBytes", sl.outputBytes},
                      {"inputOffset", sl.inputOffset},
                      {"inputBytes", sl.inputBytes}};
    nlohmann::json sms = nlohmann::json::array();
    if (!g.json) {
      fmt::print("{}: PDOs from {}\n", info.label(), toString(m.processData()[sl.position].source));
    }
    for (const auto& sm : sl.sms) {
      nlohmann::json jsm{{"sm", sm.sm},
                         {"outputs", sm.outputs},
                         {"start", sm.setting.start},
                         {"control", sm.setting.control.encode()},
                         {"length", sm.setting.length},
                         {"logicalStart", sm.logicalStart}};
      if (!g.json) {
        fmt::print("  SM{} {:<7} start {} control {} length {:3}{}\n", sm.sm,
                   sm.outputs ? "outputs" : "inputs", hex(sm.setting.start, 4),
                   hex(sm.setting.control.encode(), 2), sm.setting.length,
                   sm.setting.length > 0 ? "  logical " + hex(sm.logicalStart, 8) : "");
      }
      nlohmann::json pdos = nlohmann::json::array();
      for (const auto& pdo : sm.pdos) {
        nlohmann::json jp{{"index", pdo.index}, {"name", pdo.name}};
        nlohmann::json entries = nlohmann::json::array();
        if (!g.json) {
          fmt::print("    {} {} \"{}\"\n", sm.outputs ? "RxPDO" : "TxPDO", hex(pdo.index, 4),
                     pdo.name);
        }
        for (const auto& e : pdo.entries) {
          entries.push_back({{"index", e.index},
                             {"subindex", e.subindex},
                             {"bitLength", e.bitLength},
                             {"name", e.name}});
          if (!g.json) {
            fmt::print("      {}:{:02x} {:3} bit \"{}\"\n", hex(e.index, 4), e.subindex,
                       e.bitLength, e.name);
          }
        }
        jp["entries"] = entries;
        pdos.push_back(jp);
      }
      jsm["pdos"] = pdos;
      sms.push_back(jsm);
    }
    js["syncManagers"] = sms;
    list.push_back(js);
  }
  if (g.json) {
    printJson({{"outputBytes", layout.outputBytes},
               {"inputBytes", layout.inputBytes},
               {"frames", layout.frameCount},
               {"slaves", list}});
  } else {
    fmt::print(
        "process image: {} output bytes, {} input bytes, {} LRW datagram(s) in {} "
        "frame(s)\n",
        layout.outputBytes, layout.inputBytes, layout.datagrams.size(), layout.frameCount);
  }
  return 0;
}

}  // namespace

CommandRunner addSlavesCommand(CLI::App& app, const GlobalOptions& global) {
  auto verbose = std::make_shared<bool>(false);
  auto* cmd = app.add_subcommand("slaves", "List the slaves: position, address, state, identity");
  cmd->add_flag("-v,--verbose", *verbose, "ESC, ports, topology and mailbox details");
  return [&global, verbose] { return runSlaves(global, *verbose); };
}

CommandRunner addStatesCommand(CLI::App& app, const GlobalOptions& global) {
  auto target = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand("states", "Show every slave's AL state, or bring all to STATE");
  cmd->add_option("state", *target, "INIT, PREOP, SAFEOP or OP (configuring on the way up)");
  return [&global, target] { return runStates(global, *target); };
}

CommandRunner addSiiCommand(CLI::App& app, const GlobalOptions& global) {
  auto position = std::make_shared<std::size_t>(0);
  auto raw = std::make_shared<bool>(false);
  auto* cmd = app.add_subcommand("sii", "Show a slave's SII (EEPROM) contents");
  cmd->add_option("-p,--position", *position, "Slave position (0 = first)");
  cmd->add_flag("--raw", *raw, "Hex dump of the bytes read");
  return [&global, position, raw] { return runSii(global, *position, *raw); };
}

CommandRunner addRegCommand(CLI::App& app, const GlobalOptions& global) {
  struct Options {
    std::size_t position{0};
    std::string address;
    unsigned length{2};
    std::string value;
    std::string type;
  };
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("reg", "Read or write ESC registers");
  cmd->require_subcommand(1);
  auto* read = cmd->add_subcommand("read", "Read LENGTH bytes at ADDRESS");
  read->add_option("-p,--position", o->position, "Slave position");
  read->add_option("address", o->address, "Register address (0x130)")->required();
  read->add_option("length", o->length, "Bytes to read (default 2)");
  read->add_option("-t,--type", o->type, "Show as this type (uint16, int32, ...)");
  auto* write = cmd->add_subcommand("write", "Write VALUE at ADDRESS");
  write->add_option("-p,--position", o->position, "Slave position");
  write->add_option("address", o->address, "Register address")->required();
  write->add_option("value", o->value, "Value")->required();
  write->add_option("-t,--type", o->type, "Value type (uint8, uint16, octets, ...)")->required();
  return [&global, o, read] {
    if (read->parsed()) return runRegRead(global, o->position, o->address, o->length, o->type);
    return runRegWrite(global, o->position, o->address, o->value, o->type);
  };
}

CommandRunner addPdosCommand(CLI::App& app, const GlobalOptions& global) {
  auto position = std::make_shared<std::optional<std::size_t>>();
  auto* cmd = app.add_subcommand(
      "pdos", "Show SMs, PDOs and entries as found in CoE or SII, with process image offsets");
  cmd->add_option("-p,--position", *position, "Only this slave");
  return [&global, position] { return runPdos(global, *position); };
}

}  // namespace ecsim::tools::ecmaster
