// The config readers load files through readRegularFile (protocol/read_file.hpp): a FIFO, a
// device or an oversized file named as an ESI, topology, ENI or master configuration is refused
// with the path and the reason, without blocking and without reading without end.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "config/eni.hpp"
#include "config/esi.hpp"
#include "config/master_config.hpp"
#include "config/topology_file.hpp"
#include "protocol/read_file.hpp"
#include "support/fifo.hpp"

namespace ecsim {
namespace {

class ConfigFileLimits : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("ecsim-config-files-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    fifo_ = dir_ / "input.xml";
    ASSERT_TRUE(testing::makeFifo(fifo_));
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  template <typename Load>
  std::string refusal(Load load) {
    auto r = testing::readWithoutHanging(fifo_, [&] { return load(fifo_); });
    return r.ok() ? std::string("accepted") : r.error().context;
  }
  std::string fifoMessage() const { return fifo_.string() + ": is a FIFO, not a regular file"; }

  std::filesystem::path dir_;
  std::filesystem::path fifo_;
};

TEST_F(ConfigFileLimits, AFifoIsRefusedByEveryReader) {
  EXPECT_EQ(refusal([](const auto& p) { return loadEsiFile(p); }), fifoMessage());
  EXPECT_EQ(refusal([](const auto& p) { return loadTopologyFile(p); }), fifoMessage());
  EXPECT_EQ(refusal([](const auto& p) { return loadEniFile(p); }), fifoMessage());
  EXPECT_EQ(refusal([](const auto& p) { return xmlRootName(p); }), fifoMessage());
  EXPECT_EQ(refusal([](const auto& p) { return loadMasterConfig(p); }), fifoMessage());
}

TEST_F(ConfigFileLimits, AnEsiThatIsADeviceIsRefused) {
  auto esi = loadEsiFile("/dev/zero");
  ASSERT_FALSE(esi.ok());
  EXPECT_EQ(esi.error().context, "/dev/zero: is a character device, not a regular file");
}

TEST_F(ConfigFileLimits, AnEsiOverTheBoundIsRefusedBeforeItIsRead) {
  const auto big = dir_ / "big.xml";
  std::ofstream(big) << "<EtherCATInfo/>";
  std::filesystem::resize_file(big, kMaxXmlFileBytes + 1);  // sparse: nothing is written
  auto esi = loadEsiFile(big);
  ASSERT_FALSE(esi.ok());
  EXPECT_EQ(esi.error().code, ErrorCode::kTooLarge);
  EXPECT_EQ(esi.error().context, big.string() + ": " + std::to_string(kMaxXmlFileBytes + 1) +
                                     " bytes; the limit is 64 MiB");
}

}  // namespace
}  // namespace ecsim
