// The FoE file store's chunked files (slavesim/foe/foe_files.hpp): bytes appended in packets
// come back whole across chunk boundaries, and the firmware's version marker is found where a
// boundary cuts it (the image is read in place at a power cycle, docs/devices.md "Firmware
// update over FoE").
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "slavesim/foe/foe_files.hpp"

namespace ecsim::testing {
namespace {

using slavesim::foe::FoeFile;

ConstBytes bytesOf(std::string_view s) {
  return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

TEST(FoeFile, PacketsAcrossChunksComeBackWhole) {
  std::vector<std::uint8_t> image(2 * FoeFile::kChunkBytes + 777);
  for (std::size_t i = 0; i < image.size(); ++i) image[i] = static_cast<std::uint8_t>(i * 13);
  FoeFile file;
  constexpr std::size_t kPacket = 500;  // the ECS6010's 512-byte mailbox: 500 bytes a packet
  for (std::size_t at = 0; at < image.size(); at += kPacket) {
    file.append(ConstBytes(image).subspan(at, std::min(kPacket, image.size() - at)));
  }
  EXPECT_EQ(file.size(), image.size());
  EXPECT_EQ(file.bytes(), image);
  // A read packet that straddles the first boundary, and one cut short by the end.
  std::vector<std::uint8_t> out(kPacket);
  const std::size_t from = FoeFile::kChunkBytes - 100;
  ASSERT_EQ(file.copyOut(from, out), kPacket);
  EXPECT_TRUE(std::equal(out.begin(), out.end(), image.begin() + from));
  EXPECT_EQ(file.copyOut(image.size() - 10, out), 10u);
  EXPECT_EQ(file.copyOut(image.size(), out), 0u);
}

TEST(FoeFile, VersionMarkerCutByAChunkBoundaryIsFound) {
  const std::string marker = "ECSIM-SW-VERSION=3.1.4\n";
  FoeFile file;
  file.append(bytesOf("ECSIM-SW-VERSION=1.0.0\n"));  // an earlier marker: the last one counts
  const std::vector<std::uint8_t> zeros(FoeFile::kChunkBytes - 23 - 5, 0);
  file.append(zeros);
  file.append(bytesOf(marker));  // starts 5 bytes before the first boundary
  file.append(std::vector<std::uint8_t>(1000, 0));
  const auto at = file.rfind(slavesim::foe::kSoftwareVersionMarker);
  ASSERT_TRUE(at.has_value());
  EXPECT_EQ(*at, FoeFile::kChunkBytes - 5);
  EXPECT_EQ(slavesim::foe::softwareVersionIn(file), std::optional<std::string>("3.1.4"));
  EXPECT_EQ(slavesim::foe::softwareVersionIn(file), slavesim::foe::softwareVersionIn(file.bytes()))
      << "the same as on the image in one piece";
  EXPECT_FALSE(FoeFile().rfind("x").has_value());
}

}  // namespace
}  // namespace ecsim::testing
