#include "slavesim/eoe/eoe_params.hpp"

#include "protocol/closest_name.hpp"

namespace ecsim::slavesim::eoe {

Status applyEoeParams(EoeServer& server, const std::vector<EoeParam>& params) {
  static const std::vector<std::string_view> kNames{"eoe.ip",  "eoe.mask", "eoe.gateway", "eoe.dns",
                                                    "eoe.mac", "eoe.name", "eoe.loopback"};
  EoeIpParameters update;
  for (const EoeParam& p : params) {
    auto fail = [&](const std::string& message) {
      return makeError(ErrorCode::kInvalidArgument,
                       "line " + std::to_string(p.line) + ": " + message);
    };
    auto address = [&](std::optional<Ipv4Address>& out) -> Status {
      auto a = parseIpv4(p.value);
      if (!a.ok()) return fail(p.name + ": " + a.error().context);
      out = *a;
      return okStatus();
    };
    if (p.name == "eoe.ip") {
      ECSIM_TRY(address(update.ip));
    } else if (p.name == "eoe.mask") {
      ECSIM_TRY(address(update.subnetMask));
    } else if (p.name == "eoe.gateway") {
      ECSIM_TRY(address(update.gateway));
    } else if (p.name == "eoe.dns") {
      ECSIM_TRY(address(update.dnsServer));
    } else if (p.name == "eoe.mac") {
      auto mac = parseMac(p.value);
      if (!mac.ok()) return fail(p.name + ": " + mac.error().context);
      update.mac = *mac;
    } else if (p.name == "eoe.name") {
      if (p.value.size() > kEoeDnsNameSize) {
        return fail("eoe.name '" + p.value + "' is longer than 32 characters");
      }
      update.dnsName = p.value;
    } else if (p.name == "eoe.loopback") {
      if (p.value != "0" && p.value != "1")
        return fail("eoe.loopback is 0 or 1, not '" + p.value + "'");
      server.setLoopback(p.value == "1");
    } else {
      return fail(unknownNameText("parameter", p.name, kNames));
    }
  }
  server.setIpParameters(update);
  return okStatus();
}

}  // namespace ecsim::slavesim::eoe
