// What the master is configured with: the slaves expected on the bus, in bus order, with their
// identity, read from either of two files (loadMasterConfig looks at the root element):
//
//   - an ENI file (<EtherCATConfig>, config/eni.hpp): identity, station address, mailbox,
//     register and CoE init commands per transition, process data; the whole ENI is kept;
//   - ecsim's own simple file:
//
//       <EcsimMaster>
//         <Slave name="Coupler" vendor="#x00000E5C" product="#x00001100"/>
//         <Slave name="DI1" vendor="#x00000E5C" product="#x00001008" revision="#x00010000"/>
//       </EcsimMaster>
//
//     numbers in ESI syntax (#x.., 0x.., decimal); revision and serial are optional (when
//     absent they are not checked).
//
// Errors name the file and line.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "config/eni.hpp"
#include "protocol/result.hpp"

namespace ecsim {

struct ExpectedSlave {
  std::string name;
  std::uint32_t vendorId{0};
  std::uint32_t productCode{0};
  std::optional<std::uint32_t> revision;
  std::optional<std::uint32_t> serial;
  std::optional<std::uint16_t> station;  // configured station address (ENI PhysAddr)
  int line{0};
};

struct MasterConfig {
  std::string file;  // for messages
  std::vector<ExpectedSlave> slaves;
  std::optional<EniConfig> eni;  // when read from an ENI file
};

Result<MasterConfig> parseMasterConfig(std::string_view xml, std::string_view fileName);
// The expected slaves of an ENI (identity, PhysAddr), keeping the ENI.
MasterConfig masterConfigFromEni(EniConfig eni);
// ENI or the simple format, by root element.
Result<MasterConfig> loadMasterConfig(const std::filesystem::path& path);
// The same for a file's text held in memory; `path` is used in error messages.
Result<MasterConfig> readMasterConfig(std::string_view xml, const std::filesystem::path& path);

}  // namespace ecsim
