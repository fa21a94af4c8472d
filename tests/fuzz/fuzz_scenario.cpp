// libFuzzer target for the scenario file reader (scenario/scenario.hpp): arbitrary bytes as a
// scenario file. Nothing is run; the reader's own checks (actions, expectations, patterns)
// are what is exercised.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "scenario/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view xml(reinterpret_cast<const char*>(data), size);
  // A folder that does not exist: file names the scenario gives resolve to nothing.
  (void)ecsim::scenario::parseScenario(xml, "/nonexistent-ecsim-fuzz/scenario.xml");
  return 0;
}
