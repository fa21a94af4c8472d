// readRegularFile (protocol/read_file.hpp): regular files of bounded size only, never blocking.
#include "protocol/read_file.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace ecsim {
namespace {

class ReadFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("ecsim-read-file-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return dir_ / name;
  }
  std::filesystem::path dir_;
};

TEST_F(ReadFileTest, ReadsARegularFileAndASymlinkToOne) {
  const auto file = write("a.txt", std::string("x\0y", 3));
  auto text = readRegularFile(file, 16);
  ASSERT_TRUE(text.ok()) << text.error().message();
  EXPECT_EQ(*text, std::string("x\0y", 3));
  std::filesystem::create_symlink(file, dir_ / "link.txt");
  auto linked = readRegularFile(dir_ / "link.txt", 16);
  ASSERT_TRUE(linked.ok()) << linked.error().message();
  EXPECT_EQ(*linked, *text);
}

TEST_F(ReadFileTest, AFileAtTheBoundIsReadOneByteMoreIsRefused) {
  const auto file = write("b.txt", "12345678");
  EXPECT_TRUE(readRegularFile(file, 8).ok());
  auto over = readRegularFile(file, 7);
  ASSERT_FALSE(over.ok());
  EXPECT_EQ(over.error().code, ErrorCode::kTooLarge);
  EXPECT_EQ(over.error().context, file.string() + ": 8 bytes; the limit is 7 bytes");
}

TEST_F(ReadFileTest, AFifoIsRefusedWithoutWaitingForAWriter) {
  const auto fifo = dir_ / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto r = readRegularFile(fifo, 1024);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().context, fifo.string() + ": is a FIFO, not a regular file");
}

TEST_F(ReadFileTest, DevicesDirectoriesAndMissingFilesAreRefused) {
  auto zero = readRegularFile("/dev/zero", kMaxXmlFileBytes);
  ASSERT_FALSE(zero.ok());
  EXPECT_EQ(zero.error().context, "/dev/zero: is a character device, not a regular file");
  auto dir = readRegularFile(dir_, 1024);
  ASSERT_FALSE(dir.ok());
  EXPECT_EQ(dir.error().context, dir_.string() + ": is a directory, not a regular file");
  auto missing = readRegularFile(dir_ / "missing.xml", 1024);
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().code, ErrorCode::kNotFound);
  EXPECT_EQ(missing.error().context,
            (dir_ / "missing.xml").string() + ": cannot open: No such file or directory");
}

TEST_F(ReadFileTest, AFileThatReportsNoSizeIsStillBounded) {
  // /proc files report size 0 and are read to their end, never beyond the bound.
  auto small = readRegularFile("/proc/self/status", kMaxTextFileBytes);
  ASSERT_TRUE(small.ok()) << small.error().message();
  EXPECT_NE(small->find("Name:"), std::string::npos);
  auto bounded = readRegularFile("/proc/self/status", 10);
  ASSERT_FALSE(bounded.ok());
  EXPECT_EQ(bounded.error().code, ErrorCode::kTooLarge);
}

}  // namespace
}  // namespace ecsim
