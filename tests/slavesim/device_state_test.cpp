// A device's state file (slavesim/devices/device_state.hpp) is written only where it is safe:
// a regular ecsim state file or a new one, never a device node, FIFO, symbolic link or a file
// of someone else (each refused with the path and left as it was); and a drive that moves
// saves periodically in simulated time, so kill -9 loses at most one interval of motion.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "slavesim/devices/device_models.hpp"
#include "slavesim/devices/device_params.hpp"
#include "slavesim/devices/device_state.hpp"
#include "support/privileges.hpp"
#include "tests/slavesim/drive_test_support.hpp"
#include "tests/slavesim/temp_dir.hpp"

namespace ecsim::testing {
namespace {

class StateFileSafety : public TempDir {
 protected:
  static std::string contents(const std::filesystem::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
};

std::string errorOf(const Status& s) {
  return s.ok() ? "(saved)" : s.error().context;
}

TEST_F(StateFileSafety, AFifoIsRefusedAndLeftAFifo) {
  const auto fifo = dir_ / "drive.state";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const Status saved = dev::saveDeviceState(fifo, {1.0});
  EXPECT_FALSE(saved.ok());
  EXPECT_NE(errorOf(saved).find(fifo.string() + ": a FIFO"), std::string::npos) << errorOf(saved);
  struct stat st {};
  ASSERT_EQ(::lstat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode)) << "replaced by a regular file";
  // Reading does not block on it (no writer): refused at once.
  auto loaded = dev::loadDeviceState(fifo);
  ASSERT_FALSE(loaded.ok());
  EXPECT_NE(loaded.error().context.find("a FIFO"), std::string::npos) << loaded.error().context;
}

TEST_F(StateFileSafety, ADeviceNodeIsRefusedAndLeftADeviceNode) {
  // A /dev/zero of our own (major 1, minor 5) in the temporary folder; /dev is not touched.
  const auto node = dir_ / "zero";
  if (::mknod(node.c_str(), S_IFCHR | 0600, makedev(1, 5)) != 0) {
    if (ciMode()) FAIL() << "CI=true and mknod needs CAP_MKNOD";
    GTEST_SKIP() << "mknod needs CAP_MKNOD";
  }
  const Status saved = dev::saveDeviceState(node, {1.0});
  EXPECT_NE(errorOf(saved).find(node.string() + ": a character device"), std::string::npos)
      << errorOf(saved);
  struct stat st {};
  ASSERT_EQ(::lstat(node.c_str(), &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode)) << "the device node was replaced";
  // A drive naming it is refused at creation (it used to read /dev/zero without end).
  auto loaded = dev::loadDeviceState(node);
  ASSERT_FALSE(loaded.ok());
  EXPECT_NE(loaded.error().context.find("a character device"), std::string::npos);
}

TEST_F(StateFileSafety, ASymbolicLinkIsRefusedAndItsTargetLeftAlone) {
  const auto target = dir_ / "real.state";
  ASSERT_TRUE(dev::saveDeviceState(target, {2.0}).ok());
  const std::string before = contents(target);
  const auto link = dir_ / "link.state";
  std::filesystem::create_symlink(target, link);
  const Status saved = dev::saveDeviceState(link, {3.0});
  EXPECT_NE(errorOf(saved).find(link.string() + ": a symbolic link"), std::string::npos)
      << errorOf(saved);
  EXPECT_TRUE(std::filesystem::is_symlink(link)) << "the link was replaced";
  EXPECT_EQ(contents(target), before);
  EXPECT_FALSE(dev::loadDeviceState(link).ok());
}

TEST_F(StateFileSafety, AFileThatIsNotAStateFileIsRefusedAndKept) {
  const auto notes = dir_ / "notes.txt";
  std::ofstream(notes) << "my notes\nline two\n";
  const Status saved = dev::saveDeviceState(notes, {1.0});
  EXPECT_NE(errorOf(saved).find(notes.string() + ":1: not an ecsim device state file"),
            std::string::npos)
      << errorOf(saved);
  EXPECT_EQ(contents(notes), "my notes\nline two\n");
  // An empty file too (it is not ours: a state file always has its magic line).
  const auto empty = dir_ / "empty";
  std::ofstream{empty};
  EXPECT_FALSE(dev::saveDeviceState(empty, {1.0}).ok());
  EXPECT_EQ(std::filesystem::file_size(empty), 0u);
  // A large file is not read in full to find out.
  const auto big = dir_ / "big";
  std::ofstream(big) << std::string(1 << 20, 'x');
  const Status bigSaved = dev::saveDeviceState(big, {1.0});
  EXPECT_NE(errorOf(bigSaved).find("more than 4096 bytes"), std::string::npos) << errorOf(bigSaved);
  EXPECT_EQ(std::filesystem::file_size(big), 1u << 20);
}

TEST_F(StateFileSafety, ANewFileAndOurOwnAreWrittenAndALeftoverTemporaryIsReplaced) {
  const auto path = dir_ / "axis.state";
  ASSERT_TRUE(dev::saveDeviceState(path, {1.5}).ok());
  std::ofstream(dir_ / "axis.state.tmp") << "half a save";  // a save interrupted by kill -9
  ASSERT_TRUE(dev::saveDeviceState(path, {2.5}).ok()) << errorOf(dev::saveDeviceState(path, {2.5}));
  auto loaded = dev::loadDeviceState(path);
  ASSERT_TRUE(loaded.ok()) << loaded.error().message();
  EXPECT_EQ(loaded->shaftAngle, 2.5);
  EXPECT_FALSE(std::filesystem::exists(dir_ / "axis.state.tmp"));
  // A FIFO where the temporary goes is refused as well, not opened.
  ASSERT_EQ(::mkfifo((dir_ / "axis.state.tmp").c_str(), 0600), 0);
  EXPECT_FALSE(dev::saveDeviceState(path, {3.5}).ok());
  EXPECT_EQ(dev::loadDeviceState(path)->shaftAngle, 2.5);
}

// A joint falls under gravity with its power stage off; after 1 s of simulated time the drive
// is not destroyed (as after kill -9: no clean shutdown) and its state file is read. It used
// to hold the angle of the last AL state change (22 degrees off in the run).
TEST_F(StateFileSafety, ADriveMovingUnderGravitySavesEveryHundredMilliseconds) {
  dev::DriveParams p = benchParams();
  p.motor.gravityTorque = 0.05;
  p.stateFile = dir_ / "joint.state";
  DriveBench b(p);
  ASSERT_NE(b.drive, nullptr);
  std::vector<double> angles;  // at the end of each 1 ms step
  for (int ms = 0; ms < 1000; ++ms) {
    b.tick();
    angles.push_back(b.drive->axis().motor().angle());
  }
  const double now = angles.back();
  const double hundredMsAgo = angles[angles.size() - 1 - 100];
  ASSERT_GT(std::abs(now - angles.front()), 0.5) << "the joint must move for the test to mean "
                                                    "anything";
  auto file = dev::loadDeviceState(p.stateFile);
  ASSERT_TRUE(file.ok()) << file.error().message();
  EXPECT_LE(std::abs(file->shaftAngle - now), std::abs(now - hundredMsAgo) + 1e-12)
      << "file " << file->shaftAngle << " rad, the joint at " << now << " rad";
  // Saves come in simulated time: the file has an angle the joint had on a 100 ms boundary.
  bool onBoundary = false;
  for (std::size_t k = 99; k < angles.size(); k += 100) onBoundary |= angles[k] == file->shaftAngle;
  EXPECT_TRUE(onBoundary) << file->shaftAngle;
}

TEST_F(StateFileSafety, TheSaveIntervalIsATopologyParameter) {
  dev::DeviceModelOptions options;
  ASSERT_TRUE(dev::applyDeviceParams(options, {{"drive.stateSaveIntervalMs", "20", 4}}).ok());
  EXPECT_EQ(options.drive.stateSaveInterval, 20 * kNsPerMs);
  ASSERT_TRUE(dev::applyDeviceParams(options, {{"drive.stateSaveIntervalMs", "0", 4}}).ok());
  EXPECT_EQ(options.drive.stateSaveInterval, 0);
  auto bad = dev::applyDeviceParams(options, {{"drive.stateSaveIntervalMs", "-1", 7}});
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().context.find("line 7"), std::string::npos) << bad.error().context;
  // With 20 ms the file follows more closely.
  dev::DriveParams p = benchParams();
  p.motor.gravityTorque = 0.05;
  p.stateFile = dir_ / "joint.state";
  p.stateSaveInterval = 20 * kNsPerMs;
  DriveBench b(p);
  b.run(500 * kNsPerMs);
  const double at500 = b.drive->axis().motor().angle();
  b.run(19 * kNsPerMs);
  auto file = dev::loadDeviceState(p.stateFile);
  ASSERT_TRUE(file.ok());
  EXPECT_EQ(file->shaftAngle, at500) << "saved at 500 ms, not again before 520 ms";
}

}  // namespace
}  // namespace ecsim::testing
