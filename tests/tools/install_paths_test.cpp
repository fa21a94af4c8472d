// The tools' data folder is found relative to the executable (issue #19, relocatable install):
// an installed tree works wherever it is unpacked, ECSIM_DATA_DIR overrides, and a tool run
// from the build tree uses the source tree's examples/.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <regex>

#include "tools/common/install_paths.hpp"

namespace ecsim::tools {
namespace {
namespace fs = std::filesystem;

class DataDirTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::path(::testing::TempDir()) /
            ("datadir_" + std::to_string(::getpid()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_ / "opt" / "x" / "bin");
    std::ofstream(root_ / "opt" / "x" / "bin" / "ecsim") << "";
    fs::create_directories(root_ / "build" / "tools" / "ecsim");
    fs::create_directories(root_ / "src" / "examples" / "topologies");
  }
  void TearDown() override { fs::remove_all(root_); }
  DataDirInputs inputs(const fs::path& executable) const {
    return DataDirInputs{std::nullopt, executable, root_ / "build", root_ / "src" / "examples"};
  }
  fs::path root_;
};

TEST_F(DataDirTest, AnInstalledTreeFindsShareBesideBinWhereverItIs) {
  fs::create_directories(root_ / "opt" / "x" / "share" / "ecsim");
  auto dir = findDataDir(inputs(root_ / "opt" / "x" / "bin" / "ecsim"));
  ASSERT_TRUE(dir.ok()) << dir.error().message();
  EXPECT_EQ(*dir, (root_ / "opt" / "x" / "share" / "ecsim").lexically_normal());
  // Moved elsewhere, it follows.
  fs::rename(root_ / "opt" / "x", root_ / "moved");
  dir = findDataDir(inputs(root_ / "moved" / "bin" / "ecsim"));
  ASSERT_TRUE(dir.ok()) << dir.error().message();
  EXPECT_EQ(*dir, (root_ / "moved" / "share" / "ecsim").lexically_normal());
}

TEST_F(DataDirTest, TheVariableOverridesAndMustNameAFolder) {
  fs::create_directories(root_ / "opt" / "x" / "share" / "ecsim");
  auto in = inputs(root_ / "opt" / "x" / "bin" / "ecsim");
  in.overrideDir = (root_ / "src" / "examples").string();
  auto dir = findDataDir(in);
  ASSERT_TRUE(dir.ok()) << dir.error().message();
  EXPECT_EQ(*dir, root_ / "src" / "examples");
  in.overrideDir = (root_ / "nowhere").string();
  dir = findDataDir(in);
  ASSERT_FALSE(dir.ok());
  EXPECT_NE(dir.error().message().find("ECSIM_DATA_DIR=" + (root_ / "nowhere").string()),
            std::string::npos)
      << dir.error().message();
}

TEST_F(DataDirTest, TheBuildTreeUsesTheSourceTreesExamples) {
  auto dir = findDataDir(inputs(root_ / "build" / "tools" / "ecsim" / "ecsim"));
  ASSERT_TRUE(dir.ok()) << dir.error().message();
  EXPECT_EQ(*dir, root_ / "src" / "examples");
}

TEST_F(DataDirTest, AnInstalledToolNeverFallsBackToTheSourceTree) {
  // No share/ecsim beside it and not in the build tree: an error saying what to set, not the
  // source tree it was built from.
  auto dir = findDataDir(inputs(root_ / "opt" / "x" / "bin" / "ecsim"));
  ASSERT_FALSE(dir.ok());
  EXPECT_NE(dir.error().message().find("ECSIM_DATA_DIR"), std::string::npos);
  EXPECT_NE(dir.error().message().find((root_ / "opt" / "x" / "share" / "ecsim").string()),
            std::string::npos)
      << dir.error().message();
  // A sibling folder whose name starts like the build tree's is not inside it.
  fs::create_directories(root_ / "build2" / "bin");
  EXPECT_FALSE(findDataDir(inputs(root_ / "build2" / "bin" / "ecsim")).ok());
}

TEST(VersionText, NamesToolVersionAndRevision) {
  const std::string text = versionText("ecsim");
  EXPECT_TRUE(std::regex_match(
      text, std::regex(R"(ecsim [0-9]+\.[0-9]+\.[0-9]+( \(git [0-9a-f]{10}(-dirty)?\))?)")))
      << text;
}

}  // namespace
}  // namespace ecsim::tools
