// ecmaster eoe: a slave's EoE IP parameters (ETG.1000.6 §5.7). With KEY=VALUE settings
// (ip, mask, gw, dns, mac, name) they are sent in a Set IP Parameter request; then the
// slave's parameters are read back with Get IP Parameter and printed.
#include <fmt/core.h>

#include "protocol/closest_name.hpp"
#include "tools/ecmaster/commands.hpp"

namespace ecsim::tools::ecmaster {
namespace {

struct EoeOptions {
  std::size_t position{0};
  unsigned port{0};
  std::vector<std::string> settings;  // KEY=VALUE
};

Result<EoeIpParameters> parseSettings(const std::vector<std::string>& settings) {
  static const std::vector<std::string_view> kKeys{"ip", "mask", "gw", "dns", "mac", "name"};
  EoeIpParameters p;
  for (const std::string& s : settings) {
    const auto eq = s.find('=');
    if (eq == std::string::npos) {
      return makeError(ErrorCode::kInvalidArgument,
                       "'" + s + "' is not KEY=VALUE (keys: ip, mask, gw, dns, mac, name)");
    }
    const std::string key = s.substr(0, eq);
    const std::string value = s.substr(eq + 1);
    auto address = [&](std::optional<Ipv4Address>& out) -> Status {
      ECSIM_ASSIGN_OR_RETURN(out, parseIpv4(value));
      return okStatus();
    };
    if (key == "ip") {
      ECSIM_TRY(address(p.ip));
    } else if (key == "mask") {
      ECSIM_TRY(address(p.subnetMask));
    } else if (key == "gw") {
      ECSIM_TRY(address(p.gateway));
    } else if (key == "dns") {
      ECSIM_TRY(address(p.dnsServer));
    } else if (key == "mac") {
      ECSIM_ASSIGN_OR_RETURN(p.mac, parseMac(value));
    } else if (key == "name") {
      if (value.size() > kEoeDnsNameSize) {
        return makeError(ErrorCode::kInvalidArgument,
                         "name '" + value + "' is longer than 32 characters");
      }
      p.dnsName = value;
    } else {
      return makeError(ErrorCode::kInvalidArgument, unknownNameText("setting", key, kKeys));
    }
  }
  return p;
}

int runEoe(const GlobalOptions& g, const EoeOptions& o) {
  auto settings = parseSettings(o.settings);
  if (!settings.ok()) return fail(settings.error());
  auto c = connectAndScan(g, false);
  if (!c.ok()) return fail(c.error());
  master::Master& m = (*c)->master();
  if (auto s = ensureMailbox(m, o.position); !s.ok()) return fail(s.error());
  const auto port = static_cast<std::uint8_t>(o.port);
  if (!o.settings.empty()) {
    if (auto s = m.eoeSetIp(o.position, *settings, port); !s.ok()) return fail(s.error());
  }
  auto p = m.eoeGetIp(o.position, port);
  if (!p.ok()) return fail(p.error());
  auto ip = [](const std::optional<Ipv4Address>& a) -> nlohmann::json {
    return a ? nlohmann::json(formatIpv4(*a)) : nlohmann::json(nullptr);
  };
  if (g.json) {
    printJson({{"position", o.position},
               {"port", o.port},
               {"mac", p->mac ? nlohmann::json(formatMac(*p->mac)) : nlohmann::json(nullptr)},
               {"ip", ip(p->ip)},
               {"mask", ip(p->subnetMask)},
               {"gw", ip(p->gateway)},
               {"dns", ip(p->dnsServer)},
               {"name", p->dnsName ? nlohmann::json(*p->dnsName) : nlohmann::json(nullptr)}});
    return 0;
  }
  auto text = [](const std::optional<Ipv4Address>& a) { return a ? formatIpv4(*a) : "-"; };
  fmt::print("mac  {}\nip   {}\nmask {}\ngw   {}\ndns  {}\nname {}\n",
             p->mac ? formatMac(*p->mac) : "-", text(p->ip), text(p->subnetMask), text(p->gateway),
             text(p->dnsServer), p->dnsName.value_or("-"));
  return 0;
}

}  // namespace

CommandRunner addEoeCommand(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<EoeOptions>();
  auto* cmd = app.add_subcommand(
      "eoe", "Set (KEY=VALUE) and show a slave's EoE IP parameters (Set/Get IP Parameter)");
  cmd->add_option("-p,--position", o->position, "Slave position");
  cmd->add_option("--port", o->port, "EoE port (0..15)")->check(CLI::Range(0u, 15u));
  cmd->add_option("settings", o->settings,
                  "ip=A.B.C.D mask=A.B.C.D gw=A.B.C.D dns=A.B.C.D mac=AA:BB:CC:DD:EE:FF name=TEXT");
  return [&global, o] { return runEoe(global, *o); };
}

}  // namespace ecsim::tools::ecmaster
