// libFuzzer target for the master's configuration reader (config/master_config.hpp): arbitrary
// bytes as the file `ecmaster --config` reads, ecsim's <EcsimMaster> or an ENI.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "config/master_config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view xml(reinterpret_cast<const char*>(data), size);
  (void)ecsim::readMasterConfig(xml, "fuzz-master.xml");
  return 0;
}
