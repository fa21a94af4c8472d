// An EoE device's settings from a topology file (<Param name="eoe.ip" value="192.168.9.200"/>,
// docs/topology.md): the IP parameters a master would otherwise set with Set IP Parameter,
// present from power-up, and where frames not for the device's own stack go.
//
//   eoe.ip, eoe.mask, eoe.gateway, eoe.dns   IPv4 addresses (a.b.c.d)
//   eoe.mac                                   aa:bb:cc:dd:ee:ff
//   eoe.name                                  DNS name, up to 32 characters
//   eoe.loopback                              0/1: other frames return to the master
// An unknown eoe.* name or a bad value is an error naming the parameter's line.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "protocol/result.hpp"
#include "slavesim/eoe/eoe_server.hpp"

namespace ecsim::slavesim::eoe {

constexpr std::string_view kEoeParamPrefix = "eoe.";

struct EoeParam {
  std::string name;  // with the "eoe." prefix
  std::string value;
  int line{0};
};

Status applyEoeParams(EoeServer& server, const std::vector<EoeParam>& params);

}  // namespace ecsim::slavesim::eoe
