// Live injection over a veth pair (issue #9 acceptance): while `ecmaster cyclic` runs against
// `ecsim serve`, `ecsim ctl` pulls the cable to the drives and plugs it in again through the
// control socket; the master must report the lost slaves and bring them back to OP.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "link/netns.hpp"
#include "support/privileges.hpp"

namespace ecsim::testing {
namespace {

const std::string kEcsim = std::string(ECSIM_BINARY_DIR) + "/tools/ecsim/ecsim";
const std::string kEcmaster = std::string(ECSIM_BINARY_DIR) + "/tools/ecmaster/ecmaster";

std::string readText(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

int ctl(const std::string& socket, const std::vector<std::string>& words, std::string& out) {
  std::vector<std::string> argv{kEcsim, "ctl", "--socket", socket};
  argv.insert(argv.end(), words.begin(), words.end());
  const auto log =
      std::filesystem::temp_directory_path() / ("ecsim-ctl-" + std::to_string(::getpid()) + ".log");
  auto child = spawnProcess(argv, SpawnOptions{log.string(), log.string()});
  if (!child.ok()) return -1;
  auto rc = child->wait(std::chrono::seconds(5));
  out = readText(log);
  std::filesystem::remove(log);
  return rc.ok() ? *rc : -1;
}

TEST(LiveInjection, CableBreakAndHealWhileEcmasterCycles) {
  ECSIM_REQUIRE_NETWORK();
  auto ns = VethNamespace::create();
  ASSERT_TRUE(ns.ok()) << ns.error().message();
  const auto dir =
      std::filesystem::temp_directory_path() / ("ecsim-live-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string socket = (dir / "ctl.sock").string();
  const std::string serveLog = (dir / "serve.log").string();
  const std::string masterLog = (dir / "master.log").string();

  auto serve = ns->spawn(
      {kEcsim, "serve", "--iface", ns->simulatorInterface(), "--paced", "--control", socket},
      SpawnOptions{serveLog, serveLog});
  ASSERT_TRUE(serve.ok()) << serve.error().message();
  for (int i = 0; i < 100 && !std::filesystem::exists(socket); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_TRUE(std::filesystem::exists(socket)) << readText(serveLog);
  // Owner-only permissions on the control socket.
  const auto perms = std::filesystem::status(socket).permissions();
  EXPECT_EQ(perms & (std::filesystem::perms::group_all | std::filesystem::perms::others_all),
            std::filesystem::perms::none);

  auto master = ns->spawn({kEcmaster, "--iface", ns->masterInterface(), "cyclic", "--cycle-us",
                           "1000", "--seconds", "8"},
                          SpawnOptions{masterLog, masterLog});
  ASSERT_TRUE(master.ok()) << master.error().message();
  std::this_thread::sleep_for(std::chrono::seconds(3));  // bring-up, then cycling in OP
  std::string reply;
  EXPECT_EQ(ctl(socket, {"link-down", "cable=drives"}, reply), 0) << reply;
  EXPECT_NE(reply.find("ok link down"), std::string::npos) << reply;
  std::this_thread::sleep_for(std::chrono::seconds(1));
  EXPECT_EQ(ctl(socket, {"link-up", "cable=drives"}, reply), 0) << reply;
  EXPECT_EQ(ctl(socket, {"link-up", "cable=nowhere"}, reply), 1) << reply;
  EXPECT_NE(reply.find("error"), std::string::npos) << reply;

  auto rc = master->wait(std::chrono::seconds(30));
  const std::string out = readText(masterLog);
  ASSERT_TRUE(rc.ok()) << out;
  // The drives behind the pulled cable (stations 0x1005 and 0x1006) are reported lost, then
  // brought back to OP.
  const auto lost = out.find("0x1005");
  ASSERT_NE(lost, std::string::npos) << out;
  EXPECT_NE(out.find("lost", lost), std::string::npos) << out;
  EXPECT_NE(out.find("back in OP"), std::string::npos) << out;
  EXPECT_GT(out.rfind("back in OP"), out.find("lost")) << out;
  (void)serve->stop();
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace ecsim::testing
