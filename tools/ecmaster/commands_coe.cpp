// ecmaster upload | download | sdos: CoE services of one slave.
#include <fmt/core.h>

#include "tools/ecmaster/commands.hpp"
#include "tools/ecmaster/values.hpp"

namespace ecsim::tools::ecmaster {
namespace {

struct SdoOptions {
  std::size_t position{0};
  std::string object;  // IDX:SUB
  std::string value;
  std::string type;
  bool completeAccess{false};
  bool entries{false};
};

int runUpload(const GlobalOptions& g, const SdoOptions& o) {
  auto address = parseObjectAddress(o.object);
  if (!address.ok()) return fail(address.error());
  auto type = o.type.empty() ? Result<ValueType>(ValueType::kRaw) : parseValueType(o.type);
  if (!type.ok()) return fail(type.error());
  auto c = connectAndScan(g, false);
  if (!c.ok()) return fail(c.error());
  master::Master& m = (*c)->master();
  if (auto s = ensureMailbox(m, o.position); !s.ok()) return fail(s.error());
  auto data = m.sdoUpload(o.position, address->first, address->second, o.completeAccess);
  if (!data.ok()) return fail(data.error());
  if (g.json) {
    nlohmann::json j{{"position", o.position},
                     {"index", address->first},
                     {"subindex", address->second},
                     {"bytes", hexBytes(*data)}};
    auto v = jsonValue(*type, *data);
    if (!v.ok()) return fail(v.error());
    j["value"] = *v;
    printJson(j);
    return 0;
  }
  auto text = formatValue(*type, *data);
  if (!text.ok()) return fail(text.error());
  fmt::print("{}\n", *text);
  return 0;
}

int runDownload(const GlobalOptions& g, const SdoOptions& o) {
  auto address = parseObjectAddress(o.object);
  if (!address.ok()) return fail(address.error());
  auto type = parseValueType(o.type);
  if (!type.ok()) return fail(type.error());
  auto bytes = encodeValue(*type, o.value);
  if (!bytes.ok()) return fail(bytes.error());
  auto c = connectAndScan(g, false);
  if (!c.ok()) return fail(c.error());
  master::Master& m = (*c)->master();
  if (auto s = ensureMailbox(m, o.position); !s.ok()) return fail(s.error());
  auto status =
      m.sdoDownload(o.position, address->first, address->second, *bytes, o.completeAccess);
  if (!status.ok()) return fail(status.error());
  if (g.json) {
    printJson({{"position", o.position},
               {"index", address->first},
               {"subindex", address->second},
               {"written", hexBytes(*bytes)}});
  }
  return 0;
}

std::string_view objectCodeName(std::uint8_t code) {
  switch (static_cast<ObjectCode>(code)) {
    case ObjectCode::kVar:
      return "VAR";
    case ObjectCode::kArray:
      return "ARRAY";
    case ObjectCode::kRecord:
      return "RECORD";
  }
  return "?";
}

std::string accessText(std::uint16_t a) {
  std::string s;
  for (auto [read, write] : {std::pair{kAccessReadPreOp, kAccessWritePreOp},
                             std::pair{kAccessReadSafeOp, kAccessWriteSafeOp},
                             std::pair{kAccessReadOp, kAccessWriteOp}}) {
    s += (a & read) != 0 ? 'R' : '_';
    s += (a & write) != 0 ? 'W' : '_';
  }
  return s;
}

int runSdos(const GlobalOptions& g, const SdoOptions& o) {
  auto c = connectAndScan(g, false);
  if (!c.ok()) return fail(c.error());
  master::Master& m = (*c)->master();
  if (auto s = ensureMailbox(m, o.position); !s.ok()) return fail(s.error());
  auto list = m.readOdList(o.position);
  if (!list.ok()) return fail(list.error());
  nlohmann::json objects = nlohmann::json::array();
  for (std::uint16_t index : list->indexes) {
    auto object = m.readObjectDescription(o.position, index);
    if (!object.ok()) return fail(object.error());
    nlohmann::json jo{{"index", index},
                      {"objectCode", std::string(objectCodeName(object->objectCode))},
                      {"maxSubindex", object->maxSubindex},
                      {"name", object->name}};
    if (!g.json) {
      fmt::print("{} {:<6} \"{}\"\n", hex(index, 4), objectCodeName(object->objectCode),
                 object->name);
    }
    if (o.entries) {
      nlohmann::json entries = nlohmann::json::array();
      for (unsigned sub = 0; sub <= object->maxSubindex; ++sub) {
        auto entry = m.readEntryDescription(o.position, index, static_cast<std::uint8_t>(sub));
        if (!entry.ok()) continue;  // gaps in records
        entries.push_back({{"subindex", sub},
                           {"dataType", entry->dataType},
                           {"bitLength", entry->bitLength},
                           {"access", accessText(entry->objectAccess)},
                           {"name", entry->name}});
        if (!g.json) {
          fmt::print("  {}:{:02x} type {} {:4} bit {} \"{}\"\n", hex(index, 4), sub,
                     hex(entry->dataType, 4), entry->bitLength, accessText(entry->objectAccess),
                     entry->name);
        }
      }
      jo["entries"] = entries;
    }
    objects.push_back(jo);
  }
  if (g.json) printJson({{"position", o.position}, {"objects", objects}});
  return 0;
}

}  // namespace

Status ensureMailbox(master::Master& m, std::size_t position) {
  if (position >= m.slaves().size()) {
    return makeError(ErrorCode::kNotFound, fmt::format("no slave at position {}", position));
  }
  if (!m.slaves()[position].mailbox) {
    return makeError(ErrorCode::kUnsupported, m.slaves()[position].label() + " has no mailbox");
  }
  if (m.slaves()[position].state().value_or(AlState::kInit) == AlState::kInit) {
    return m.bringTo(AlState::kPreOp);
  }
  return okStatus();
}

CommandRunner addUploadCommand(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<SdoOptions>();
  auto* cmd = app.add_subcommand("upload", "Read an object entry (SDO upload)");
  cmd->add_option("-p,--position", o->position, "Slave position");
  cmd->add_option("object", o->object, "IDX:SUB, e.g. 0x1018:02")->required();
  cmd->add_option("-t,--type", o->type,
                  "bool, int8..int64, uint8..uint64, float, double, "
                  "string, octets (default: raw bytes)");
  cmd->add_flag("--complete", o->completeAccess, "Complete access (the whole object)");
  return [&global, o] { return runUpload(global, *o); };
}

CommandRunner addDownloadCommand(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<SdoOptions>();
  auto* cmd = app.add_subcommand("download", "Write an object entry (SDO download)");
  cmd->add_option("-p,--position", o->position, "Slave position");
  cmd->add_option("object", o->object, "IDX:SUB, e.g. 0x8000:13")->required();
  cmd->add_option("value", o->value, "Value in the given type")->required();
  cmd->add_option("-t,--type", o->type,
                  "bool, int8..int64, uint8..uint64, float, double, "
                  "string, octets")
      ->required();
  cmd->add_flag("--complete", o->completeAccess, "Complete access (the whole object)");
  return [&global, o] { return runDownload(global, *o); };
}

CommandRunner addSdosCommand(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<SdoOptions>();
  auto* cmd = app.add_subcommand("sdos", "List a slave's object dictionary (SDO information)");
  cmd->add_option("-p,--position", o->position, "Slave position");
  cmd->add_flag("-e,--entries", o->entries, "Describe every entry too");
  return [&global, o] { return runSdos(global, *o); };
}

}  // namespace ecsim::tools::ecmaster
