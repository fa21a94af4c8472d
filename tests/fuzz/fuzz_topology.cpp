// libFuzzer target for the topology file reader (config/topology_file.hpp) and the network
// builder (topology/network_builder.hpp): arbitrary bytes as a topology file, and the network
// it describes built when it names no file.
//
// The file is placed in a folder that does not exist, so relative file names (ESI, EEPROM,
// state files, signal CSVs) resolve to nothing; a topology naming a file is only parsed, never
// built, so that the fuzzer neither reads nor writes outside its scratch folder. Networks of
// more than kMaxBuiltSlaves are only parsed too (their building time is a benchmark's matter).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "config/topology_file.hpp"
#include "topology/network_builder.hpp"

namespace {

constexpr std::size_t kMaxBuiltSlaves = 256;

bool namesAFile(const ecsim::TopologySlave& slave) {
  if (!slave.esiFile.empty() || !slave.eepromFile.empty() || !slave.stateFile.empty()) return true;
  for (const auto& param : slave.params) {
    if (param.value.find("csv") != std::string::npos) return true;  // signal="csv file=..."
  }
  return false;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view xml(reinterpret_cast<const char*>(data), size);
  auto config = ecsim::parseTopology(xml, "/nonexistent-ecsim-fuzz/topology.xml");
  if (!config.ok() || config->slaves.size() > kMaxBuiltSlaves) return 0;
  for (const auto& slave : config->slaves) {
    if (namesAFile(slave)) return 0;
  }
  (void)ecsim::topology::buildNetwork(*config);
  return 0;
}
