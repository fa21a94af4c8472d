// libFuzzer target for the ENI reader (config/eni.hpp): arbitrary bytes as an ENI file; what
// it accepts is written back (formatEni, as `ecmaster --export-eni` does) and read again, and
// turned into a topology (topology/network_from_eni.hpp) with no ESI folder to search, so no
// file is read.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "config/eni.hpp"
#include "topology/network_from_eni.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view xml(reinterpret_cast<const char*>(data), size);
  auto eni = ecsim::parseEni(xml, "/nonexistent-ecsim-fuzz/eni.xml");
  if (!eni.ok()) return 0;
  for (const auto& slave : eni->slaves) (void)eni->findSlave(slave.physAddr);
  const std::string written = ecsim::formatEni(*eni);
  (void)ecsim::parseEni(written, "/nonexistent-ecsim-fuzz/written-eni.xml");
  (void)ecsim::topology::topologyFromEni(*eni, {});
  return 0;
}
