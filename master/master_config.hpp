// The master's own simple configuration file (until ENI EtherCATConfig is read): the slaves
// expected on the bus, in bus order, with their identity.
//
//   <EcsimMaster>
//     <Slave name="Coupler" vendor="#x00000E5C" product="#x00001100"/>
//     <Slave name="DI1" vendor="#x00000E5C" product="#x00001008" revision="#x00010000"/>
//   </EcsimMaster>
//
// Numbers in ESI syntax (#x.., 0x.., decimal). revision and serial are optional: when absent
// they are not checked. Errors name the file and line.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "master/slave_info.hpp"
#include "protocol/result.hpp"

namespace ecsim::master {

struct ExpectedSlave {
  std::string name;
  std::uint32_t vendorId{0};
  std::uint32_t productCode{0};
  std::optional<std::uint32_t> revision;
  std::optional<std::uint32_t> serial;
  int line{0};
};

struct MasterConfig {
  std::string file;  // for messages
  std::vector<ExpectedSlave> slaves;
};

Result<MasterConfig> parseMasterConfig(std::string_view xml, std::string_view fileName);
Result<MasterConfig> loadMasterConfig(const std::filesystem::path& path);

// Compares the bus with the configuration: kNotFound when the slave counts differ, kInvalidArgument
// naming each slave whose identity differs (position, station, what was expected and found).
Status checkIdentities(const MasterConfig& config, const std::vector<SlaveInfo>& slaves);

}  // namespace ecsim::master
