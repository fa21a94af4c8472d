// libFuzzer target for the SII decoder (protocol/sii.hpp): arbitrary bytes as an EEPROM image,
// read strictly and leniently (as the master and `ecsim sii` do), every category's data and
// string looked at.
#include <cstddef>
#include <cstdint>

#include "protocol/sii.hpp"

namespace {

void inspect(const ecsim::SiiImage& image) {
  for (const auto& category : image.categories()) (void)image.categoryData(category);
  for (std::size_t i = 0; i <= image.contents().strings.size() + 1; ++i) (void)image.string(i);
  (void)image.checksumOk();
  (void)image.contents().eepromBytes();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const ecsim::ConstBytes in(data, size);
  if (auto lenient = ecsim::SiiImage::parseLenient(in); lenient.ok()) inspect(*lenient);
  if (auto strict = ecsim::SiiImage::parse(in); strict.ok()) inspect(*strict);
  return 0;
}
