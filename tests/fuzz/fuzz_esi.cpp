// libFuzzer target for the ESI reader (config/esi.hpp): arbitrary bytes as an ESI file, and a
// slave built (slavesim/esi_slave.hpp) from every device the file yields, as `ecsim serve`
// does for a topology that names it. An error result is fine; a crash, leak, sanitizer report
// or an exception is a finding.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "config/esi.hpp"
#include "slavesim/esi_slave.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view xml(reinterpret_cast<const char*>(data), size);
  auto file = ecsim::parseEsi(xml, "fuzz-esi.xml");
  if (!file.ok()) return 0;
  for (const ecsim::EsiDevice& device : file->devices) {
    (void)ecsim::slavesim::makeSlaveFromEsi(*file, device, "fuzz");
  }
  return 0;
}
