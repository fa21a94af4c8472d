#include "config/topology_file.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <charconv>
#include <fstream>
#include <sstream>

#include "config/eni.hpp"
#include "config/eni_topology.hpp"
#include "config/xml_util.hpp"
#include "protocol/closest_name.hpp"
#include "protocol/read_file.hpp"

namespace ecsim {
namespace {

using xml::Element;

Result<std::pair<std::size_t, unsigned>> parseEndpoint(const xml::Context& ctx, const Element* e,
                                                       const char* attribute,
                                                       const TopologyConfig& cfg) {
  const char* raw = e->Attribute(attribute);
  if (raw == nullptr) {
    return ctx.error(e, std::string(e->Name()) + " needs attribute '" + attribute + "'");
  }
  std::string_view text(raw);
  auto colon = text.rfind(':');
  if (colon == std::string_view::npos) {
    return ctx.error(e, std::string(attribute) + " '" + std::string(text) +
                            "' must be SLAVE:PORT (e.g. Coupler:1)");
  }
  auto slave = cfg.findSlave(text.substr(0, colon));
  if (!slave) {
    return ctx.error(e,
                     "unknown slave '" + std::string(text.substr(0, colon)) + "' in " + attribute);
  }
  ECSIM_ASSIGN_OR_RETURN(auto port,
                         xml::parseNumber<std::uint8_t>(ctx, e, attribute, text.substr(colon + 1)));
  if (port > 3) return ctx.error(e, std::string(attribute) + ": port must be 0..3");
  return std::make_pair(*slave, static_cast<unsigned>(port));
}

// A real attribute in [lo, hi] (`fallback` when absent); NaN and infinities are refused.
Result<double> attrDouble(const xml::Context& ctx, const Element* e, const char* name,
                          double fallback, double lo, double hi, std::string_view why) {
  const char* raw = e->Attribute(name);
  if (raw == nullptr) return fallback;
  const std::string_view text(raw);
  double v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  // Written so that NaN fails the range test.
  if (ec != std::errc() || end != text.data() + text.size() || !(v >= lo && v <= hi)) {
    return ctx.error(
        e, fmt::format("attribute {}: '{}' is not a number in [{}, {}]{}", name, raw, lo, hi, why));
  }
  return v;
}

// An integer attribute in [lo, hi], or nullopt when absent.
Result<std::optional<std::int64_t>> attrInteger(const xml::Context& ctx, const Element* e,
                                                const char* name, std::int64_t lo,
                                                std::int64_t hi) {
  ECSIM_ASSIGN_OR_RETURN(auto v, xml::attrNumber<std::int64_t>(ctx, e, name));
  if (v && (*v < lo || *v > hi)) {
    return ctx.error(e, fmt::format("attribute {}: '{}' is not a number in [{}, {}]", name,
                                    e->Attribute(name), lo, hi));
  }
  return v;
}

constexpr std::string_view kCableWhy = " m (the 100BASE-TX segment limit)";

// What each element takes (docs/topology.md); anything else is an error (xml::checkNames).
const xml::Names kTopologyNames{
    {"name"}, {"Master", "Slave", "Link", "Eni", "Group"}, {"Master", "Eni"}};
const xml::Names kGroupNames{{"name", "slaves", "attached"}};
// <Eni file= esiDir=>: the slaves and wiring of an ENI; its <Slave> elements name ENI slaves and
// carry only behaviour (model, parameters, inputs, state file).
const xml::Names kEniNames{{"file", "esiDir"}};
const xml::Names kEniSlaveNames{{"name", "model", "stateFile"}, {"Input", "Param"}};
const xml::Names kMasterNames{{"cable", "redundant", "redundantCable"}};
const xml::Names kSlaveNames{
    {"name", "esi", "product", "revision", "device", "eeprom", "esc", "dc", "processingDelayNs",
     "forwardingDelayNs", "stateFile", "modules", "model", "soeDictionary", "alias", "deviceId"},
    {"Clock", "Input", "Param", "Module"},
    {"Clock"}};
// <Slave model="...">: the device models a topology may choose (docs/devices.md).
const std::vector<std::string_view> kModelNames{"cia402",  "io",       "analog",
                                                "encoder", "loopback", "none"};
const xml::Names kClockNames{{"offsetNs", "driftPpm"}};
const xml::Names kInputNames{{"entry", "value"}};
const xml::Names kParamNames{{"name", "value"}};
const xml::Names kModuleNames{{"type", "ident"}};
const xml::Names kLinkNames{{"name", "from", "to", "cable"}};

// A <Slave>'s <Input> and <Param> children.
Status parseInputsAndParams(const xml::Context& ctx, const Element* e, TopologySlave& s) {
  for (const Element* in : xml::Children(e, "Input")) {
    TopologyInput input;
    input.line = in->GetLineNum();
    ECSIM_TRY(xml::checkNames(ctx, in, kInputNames));
    const char* entry = in->Attribute("entry");
    if (entry == nullptr) return ctx.error(in, "Input needs entry=\"INDEX:SUB\"");
    std::string_view text(entry);
    auto colon = text.find(':');
    if (colon == std::string_view::npos) return ctx.error(in, "entry must be INDEX:SUB");
    ECSIM_ASSIGN_OR_RETURN(input.index, xml::parseNumber<std::uint16_t>(ctx, in, "entry index",
                                                                        text.substr(0, colon)));
    ECSIM_ASSIGN_OR_RETURN(input.subIndex, xml::parseNumber<std::uint8_t>(ctx, in, "entry subindex",
                                                                          text.substr(colon + 1)));
    ECSIM_ASSIGN_OR_RETURN(auto value, xml::attrNumber<std::int64_t>(ctx, in, "value"));
    if (!value) return ctx.error(in, "Input needs a value");
    input.value = *value;
    s.inputs.push_back(input);
  }
  for (const Element* param : xml::Children(e, "Param")) {
    ECSIM_TRY(xml::checkNames(ctx, param, kParamNames));
    const char* pname = param->Attribute("name");
    const char* value = param->Attribute("value");
    if (pname == nullptr || value == nullptr) {
      return ctx.error(param, "Param needs name and value attributes");
    }
    s.params.push_back({pname, value, param->GetLineNum()});
  }
  return okStatus();
}

// model="NAME" of a <Slave>, one of kModelNames.
Status parseModel(const xml::Context& ctx, const Element* e, TopologySlave& s) {
  const char* model = e->Attribute("model");
  if (model == nullptr) return okStatus();
  if (std::find(kModelNames.begin(), kModelNames.end(), std::string_view(model)) ==
      kModelNames.end()) {
    return ctx.error(e, unknownNameText("model", model, kModelNames, " on <Slave>"));
  }
  s.model = model;
  return okStatus();
}

Result<TopologySlave> parseSlave(const xml::Context& ctx, const Element* e,
                                 const std::filesystem::path& folder) {
  TopologySlave s;
  s.line = e->GetLineNum();
  ECSIM_TRY(xml::checkNames(ctx, e, kSlaveNames));
  const char* name = e->Attribute("name");
  if (name == nullptr || std::string_view(name).empty()) {
    return ctx.error(e, "Slave needs a name attribute");
  }
  s.name = name;
  if (const char* esi = e->Attribute("esi")) s.esiFile = folder / esi;
  ECSIM_ASSIGN_OR_RETURN(s.productCode, xml::attrNumber<std::uint32_t>(ctx, e, "product"));
  ECSIM_ASSIGN_OR_RETURN(s.revision, xml::attrNumber<std::uint32_t>(ctx, e, "revision"));
  if (const char* device = e->Attribute("device")) s.builtin = device;
  if (const char* eeprom = e->Attribute("eeprom")) s.eepromFile = folder / eeprom;
  if (!s.eepromFile.empty() && (!s.esiFile.empty() || !s.builtin.empty())) {
    return ctx.error(e, "Slave '" + s.name + "': eeprom cannot be combined with esi or device");
  }
  if (s.esiFile.empty() && s.builtin.empty() && s.eepromFile.empty()) s.builtin = "generic";
  if (!s.esiFile.empty() && !s.productCode) {
    return ctx.error(e, "Slave '" + s.name + "' names an ESI file but no product code");
  }
  if (!s.esiFile.empty() && !s.builtin.empty()) {
    return ctx.error(e, "Slave '" + s.name + "': give either esi+product or device, not both");
  }
  if (const char* esc = e->Attribute("esc")) s.esc = esc;
  if (const char* dc = e->Attribute("dc")) {
    s.dc = dc;
    if (s.dc != "full" && s.dc != "delay-only" && s.dc != "none") {
      return ctx.error(e, "dc must be full, delay-only or none");
    }
  }
  ECSIM_ASSIGN_OR_RETURN(s.processingDelayNs,
                         attrInteger(ctx, e, "processingDelayNs", 0, kMaxEscDelayNs));
  ECSIM_ASSIGN_OR_RETURN(s.forwardingDelayNs,
                         attrInteger(ctx, e, "forwardingDelayNs", 0, kMaxEscDelayNs));
  ECSIM_ASSIGN_OR_RETURN(s.alias, xml::attrNumber<std::uint16_t>(ctx, e, "alias"));
  ECSIM_ASSIGN_OR_RETURN(s.deviceId, xml::attrNumber<std::uint16_t>(ctx, e, "deviceId"));
  if (const Element* clock = e->FirstChildElement("Clock")) {
    ECSIM_TRY(xml::checkNames(ctx, clock, kClockNames));
    ECSIM_ASSIGN_OR_RETURN(
        auto offset, attrInteger(ctx, clock, "offsetNs", -kMaxClockOffsetNs, kMaxClockOffsetNs));
    s.clockOffsetNs = offset.value_or(0);
    ECSIM_ASSIGN_OR_RETURN(
        s.driftPpm, attrDouble(ctx, clock, "driftPpm", 0.0, -kMaxDriftPpm, kMaxDriftPpm, " ppm"));
  }
  if (const char* state = e->Attribute("stateFile")) s.stateFile = folder / state;
  ECSIM_TRY(parseModel(ctx, e, s));
  if (!s.model.empty() && s.esiFile.empty()) {
    return ctx.error(e, "Slave '" + s.name + "': model= needs a device from an ESI file (esi=)");
  }
  s.folder = folder;
  ECSIM_TRY(parseInputsAndParams(ctx, e, s));
  if (const char* moduleFile = e->Attribute("modules")) s.moduleFile = folder / moduleFile;
  if (const char* dict = e->Attribute("soeDictionary")) {
    if (s.esiFile.empty()) {
      return ctx.error(
          e, "Slave '" + s.name + "': soeDictionary= needs a device from an ESI file (esi=)");
    }
    s.soeDictionaryFile = folder / dict;
  }
  for (const Element* m : xml::Children(e, "Module")) {
    TopologyModule module;
    module.line = m->GetLineNum();
    ECSIM_TRY(xml::checkNames(ctx, m, kModuleNames));
    if (const char* type = m->Attribute("type")) module.type = type;
    ECSIM_ASSIGN_OR_RETURN(module.ident, xml::attrNumber<std::uint32_t>(ctx, m, "ident"));
    if (module.type.empty() == !module.ident.has_value()) {
      return ctx.error(m, "Module needs either type=\"NAME\" or ident=\"#xIDENT\"");
    }
    s.modules.push_back(std::move(module));
  }
  if ((!s.modules.empty() || !s.moduleFile.empty()) && s.esiFile.empty()) {
    return ctx.error(e, "Slave '" + s.name + "': modules need a device from an ESI file (esi=)");
  }
  return s;
}

// A topology on an ENI (<Eni file= esiDir=>): the ENI's slaves and wiring (topologyFromEni),
// then each <Slave name=> adds behaviour to the ENI slave of that name.
Result<TopologyConfig> parseEniTopology(const xml::Context& ctx, const Element* root,
                                        const Element* eniElement,
                                        const std::filesystem::path& folder) {
  ECSIM_TRY(xml::checkNames(ctx, eniElement, kEniNames));
  const char* eniName = eniElement->Attribute("file");
  if (eniName == nullptr || *eniName == 0)
    return ctx.error(eniElement, "Eni needs file=\"ENI.xml\"");
  if (const Element* link = root->FirstChildElement("Link")) {
    return ctx.error(link, "a topology on an <Eni> takes its wiring from the ENI: no <Link>");
  }
  const std::filesystem::path eniFile = folder / eniName;
  const char* esiDir = eniElement->Attribute("esiDir");
  const std::filesystem::path esiFolder =
      esiDir != nullptr ? folder / esiDir : eniFile.parent_path();
  auto eni = loadEniFile(eniFile);
  if (!eni.ok()) return ctx.error(eniElement, eni.error().message());
  auto built = topology::topologyFromEni(*eni, {esiFolder});
  if (!built.ok()) return ctx.error(eniElement, built.error().message());
  TopologyConfig cfg = std::move(built).value();
  cfg.warnings = std::move(eni->warnings);
  std::vector<std::string_view> names;
  for (std::size_t i = 0; i < cfg.slaves.size(); ++i) {
    cfg.byName.emplace(cfg.slaves[i].name, i);
    names.push_back(cfg.slaves[i].name);
    // Errors building it name this file (TopologyConfig::file): the line is the <Eni>'s, until
    // a <Slave> below names it.
    cfg.slaves[i].line = eniElement->GetLineNum();
  }
  for (auto& link : cfg.links) link.line = eniElement->GetLineNum();
  std::map<std::size_t, int> given;  // ENI slave -> line of its <Slave>
  for (const Element* e : xml::Children(root, "Slave")) {
    ECSIM_TRY(xml::checkNames(ctx, e, kEniSlaveNames));
    const char* name = e->Attribute("name");
    if (name == nullptr || *name == 0) return ctx.error(e, "Slave needs a name attribute");
    const auto found = cfg.byName.find(std::string_view(name));
    if (found == cfg.byName.end()) {
      return ctx.error(e,
                       unknownNameText("slave", name, names, " in " + eniFile.filename().string()));
    }
    if (auto [it, fresh] = given.emplace(found->second, e->GetLineNum()); !fresh) {
      return ctx.error(e,
                       fmt::format("slave '{}' given twice (first on line {})", name, it->second));
    }
    TopologySlave& s = cfg.slaves[found->second];
    ECSIM_TRY(parseModel(ctx, e, s));
    if (const char* state = e->Attribute("stateFile")) s.stateFile = folder / state;
    ECSIM_TRY(parseInputsAndParams(ctx, e, s));
    s.folder = folder;
    s.line = e->GetLineNum();
  }
  return cfg;
}

// Before anything runs: every cable has a name of its own ("master" is the master's), and every
// slave is reached from the one at the master through the links (a slave no link reaches is
// not on the wire: a misspelt <Link> took it off without a word).
Status checkWiring(const xml::Context& ctx, const TopologyConfig& cfg) {
  std::map<std::string_view, int> names;
  for (const auto& l : cfg.links) {
    if (l.name == "master") {
      return ctx.error(l.line, "cable name 'master' is the master's cable (to the first slave)");
    }
    if (auto [it, fresh] = names.emplace(l.name, l.line); !fresh) {
      return ctx.error(l.line, fmt::format("cable name '{}' given twice (first on line {})", l.name,
                                           it->second));
    }
  }
  std::vector<std::vector<std::size_t>> neighbours(cfg.slaves.size());
  for (const auto& l : cfg.links) {
    neighbours[l.fromSlave].push_back(l.toSlave);
    neighbours[l.toSlave].push_back(l.fromSlave);
  }
  std::vector<bool> reached(cfg.slaves.size(), false);
  std::vector<std::size_t> todo{0};
  reached[0] = true;
  while (!todo.empty()) {
    const std::size_t s = todo.back();
    todo.pop_back();
    for (std::size_t n : neighbours[s]) {
      if (!reached[n]) {
        reached[n] = true;
        todo.push_back(n);
      }
    }
  }
  for (std::size_t i = 0; i < cfg.slaves.size(); ++i) {
    if (!reached[i]) {
      return ctx.error(cfg.slaves[i].line,
                       fmt::format("slave '{}' is reached by no link from '{}' (the slave at the "
                                   "master)",
                                   cfg.slaves[i].name, cfg.slaves[0].name));
    }
  }
  return okStatus();
}

// <Group name="Tool" slaves="T1 T2" attached="true">: after the wiring is known (its junction
// link is the one link between a member and a slave outside).
Status parseGroups(const xml::Context& ctx, const Element* root, TopologyConfig& cfg) {
  std::map<std::size_t, std::string> memberOf;  // slave -> its group
  std::vector<std::string_view> names;
  for (const auto& slave : cfg.slaves) names.push_back(slave.name);
  for (const Element* e : xml::Children(root, "Group")) {
    ECSIM_TRY(xml::checkNames(ctx, e, kGroupNames));
    TopologyGroup g;
    g.line = e->GetLineNum();
    const char* name = e->Attribute("name");
    const char* slaves = e->Attribute("slaves");
    if (name == nullptr || *name == '\0') return ctx.error(e, "Group needs attribute 'name'");
    if (slaves == nullptr) return ctx.error(e, "Group needs attribute 'slaves' (names)");
    g.name = name;
    for (const auto& other : cfg.groups) {
      if (other.name == g.name) {
        return ctx.error(
            e, fmt::format("group name '{}' given twice (first on line {})", g.name, other.line));
      }
    }
    if (const char* attached = e->Attribute("attached")) {
      const std::string_view a(attached);
      if (a != "true" && a != "false") {
        return ctx.error(e, fmt::format("attached: '{}' is not true or false", a));
      }
      g.attached = a == "true";
    }
    std::string_view list(slaves);
    while (!list.empty()) {
      const auto start = list.find_first_not_of(" ,");
      if (start == std::string_view::npos) break;
      list.remove_prefix(start);
      const std::string_view member = list.substr(0, list.find_first_of(" ,"));
      list.remove_prefix(member.size());
      auto index = cfg.findSlave(member);
      if (!index) {
        return ctx.error(
            e, fmt::format("slaves: no slave named '{}'{}", member, didYouMean(member, names)));
      }
      if (*index == 0) {
        return ctx.error(e, fmt::format("slaves: '{}' is the slave at the master; a group is "
                                        "attached behind another slave",
                                        member));
      }
      if (auto [it, fresh] = memberOf.emplace(*index, g.name); !fresh) {
        return ctx.error(e,
                         fmt::format("slaves: '{}' is in group '{}' already", member, it->second));
      }
      g.slaves.push_back(*index);
    }
    if (g.slaves.empty()) return ctx.error(e, "slaves: a group needs at least one slave");
    auto member = [&](std::size_t s) {
      return std::find(g.slaves.begin(), g.slaves.end(), s) != g.slaves.end();
    };
    std::optional<std::size_t> junction;
    for (std::size_t i = 0; i < cfg.links.size(); ++i) {
      const auto& l = cfg.links[i];
      if (member(l.fromSlave) == member(l.toSlave)) continue;
      if (junction) {
        return ctx.error(e, fmt::format("group '{}' is joined to the rest by two links ('{}' and "
                                        "'{}'): a group hangs from one junction port",
                                        g.name, cfg.links[*junction].name, l.name));
      }
      junction = i;
    }
    if (!junction) return ctx.error(e, fmt::format("group '{}' has no link to the rest", g.name));
    g.junctionLink = *junction;
    cfg.groups.push_back(std::move(g));
  }
  return okStatus();
}

}  // namespace

std::optional<std::size_t> TopologyConfig::findSlave(std::string_view n) const {
  if (byName.size() == slaves.size()) {
    auto it = byName.find(n);
    if (it == byName.end()) return std::nullopt;
    return it->second;
  }
  for (std::size_t i = 0; i < slaves.size(); ++i) {  // slaves filled in without the index
    if (slaves[i].name == n) return i;
  }
  return std::nullopt;
}

Result<TopologyConfig> parseTopology(std::string_view text, const std::filesystem::path& file) {
  xml::Context ctx(file.string());
  tinyxml2::XMLDocument doc;
  ECSIM_TRY(xml::parseDocument(text, ctx, doc));
  const Element* root = doc.RootElement();
  if (root == nullptr || std::string_view(root->Name()) != "Topology") {
    return ctx.error(root, "root element must be <Topology>");
  }
  ECSIM_TRY(xml::checkNames(ctx, root, kTopologyNames));
  TopologyConfig cfg;
  cfg.file = file;
  if (const char* name = root->Attribute("name")) cfg.name = name;
  const std::filesystem::path folder = file.parent_path();
  const Element* master = root->FirstChildElement("Master");
  if (master != nullptr) {
    ECSIM_TRY(xml::checkNames(ctx, master, kMasterNames));
    ECSIM_ASSIGN_OR_RETURN(cfg.masterCableMetres,
                           attrDouble(ctx, master, "cable", 1.0, 0, kMaxCableMetres, kCableWhy));
    ECSIM_ASSIGN_OR_RETURN(cfg.redundantCableMetres, attrDouble(ctx, master, "redundantCable", 1.0,
                                                                0, kMaxCableMetres, kCableWhy));
    cfg.masterLine = master->GetLineNum();
  }
  if (const Element* eniElement = root->FirstChildElement("Eni")) {
    if (master != nullptr && master->Attribute("redundant") != nullptr) {
      return ctx.error(master, "redundant: not with <Eni> (the ENI gives the wiring)");
    }
    ECSIM_ASSIGN_OR_RETURN(TopologyConfig onEni, parseEniTopology(ctx, root, eniElement, folder));
    onEni.file = file;
    onEni.name = cfg.name.empty() ? onEni.name : cfg.name;
    onEni.masterCableMetres = cfg.masterCableMetres;
    ECSIM_TRY(parseGroups(ctx, root, onEni));  // groups of ENI slaves, on the ENI's wiring
    return onEni;
  }
  for (const Element* e : xml::Children(root, "Slave")) {
    if (cfg.slaves.size() == kMaxSlaves) {
      return ctx.error(
          e, fmt::format("more than {} slaves (the address space of a segment)", kMaxSlaves));
    }
    ECSIM_ASSIGN_OR_RETURN(auto slave, parseSlave(ctx, e, folder));
    if (!cfg.byName.emplace(slave.name, cfg.slaves.size()).second) {
      return ctx.error(e, "duplicate slave name '" + slave.name + "'");
    }
    cfg.slaves.push_back(std::move(slave));
  }
  if (cfg.slaves.empty()) return ctx.error(root, "topology has no <Slave>");
  for (const Element* e : xml::Children(root, "Link")) {
    TopologyLink link;
    link.line = e->GetLineNum();
    ECSIM_TRY(xml::checkNames(ctx, e, kLinkNames));
    if (const char* name = e->Attribute("name")) link.name = name;
    ECSIM_ASSIGN_OR_RETURN(auto from, parseEndpoint(ctx, e, "from", cfg));
    ECSIM_ASSIGN_OR_RETURN(auto to, parseEndpoint(ctx, e, "to", cfg));
    link.fromSlave = from.first;
    link.fromPort = from.second;
    link.toSlave = to.first;
    link.toPort = to.second;
    ECSIM_ASSIGN_OR_RETURN(link.cableMetres,
                           attrDouble(ctx, e, "cable", 1.0, 0, kMaxCableMetres, kCableWhy));
    cfg.links.push_back(link);
  }
  cfg.explicitLinks = !cfg.links.empty();
  if (!cfg.explicitLinks) {  // a line in the written order, port 1 -> port 0
    for (std::size_t i = 1; i < cfg.slaves.size(); ++i) {
      cfg.links.push_back({"", i - 1, 1, i, 0, 1.0, cfg.slaves[i].line});
    }
  }
  if (master != nullptr && master->Attribute("redundant") != nullptr) {
    ECSIM_ASSIGN_OR_RETURN(cfg.redundantPort, parseEndpoint(ctx, master, "redundant", cfg));
    for (const auto& l : cfg.links) {
      if ((l.fromSlave == cfg.redundantPort->first && l.fromPort == cfg.redundantPort->second) ||
          (l.toSlave == cfg.redundantPort->first && l.toPort == cfg.redundantPort->second)) {
        return ctx.error(master, fmt::format("redundant: {}:{} is already wired (line {})",
                                             cfg.slaves[cfg.redundantPort->first].name,
                                             cfg.redundantPort->second, l.line));
      }
    }
    if (*cfg.redundantPort == std::pair<std::size_t, unsigned>{0, 0}) {
      return ctx.error(master, "redundant: port 0 of the first slave is the master's own cable");
    }
  }
  for (auto& l : cfg.links) {
    if (l.name.empty())
      l.name = cfg.slaves[l.fromSlave].name + ":" + std::to_string(l.fromPort) + "-" +
               cfg.slaves[l.toSlave].name + ":" + std::to_string(l.toPort);
  }
  ECSIM_TRY(checkWiring(ctx, cfg));
  ECSIM_TRY(parseGroups(ctx, root, cfg));
  return cfg;
}

Result<TopologyConfig> loadTopologyFile(const std::filesystem::path& path) {
  ECSIM_ASSIGN_OR_RETURN(const std::string text, readRegularFile(path, kMaxXmlFileBytes));
  return parseTopology(text, path);
}

}  // namespace ecsim
