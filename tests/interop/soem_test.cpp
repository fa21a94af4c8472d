// SOEM against `ecsim serve` over a veth pair inside a private network namespace. SOEM's
// sample programs always exit 0, so the checks read what they print (the success and failure
// lines are listed in ../shared/notes/soem-interop.md §4).
#include <gtest/gtest.h>
#include <signal.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <thread>

#include "link/netns.hpp"
#include "support/test_network.hpp"

namespace ecsim::testing {
namespace {

const std::string kEcsim = std::string(ECSIM_BINARY_DIR) + "/tools/ecsim/ecsim";
const std::filesystem::path kSoem = ECSIM_SOEM_DIR;

std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  std::string t = s.str();
  for (auto& c : t) {
    if (c == '\r') c = '\n';  // SOEM's cyclic lines end with \r
  }
  return t;
}

int countMatches(const std::string& text, const std::string& pattern) {
  std::regex re(pattern);
  return static_cast<int>(
      std::distance(std::sregex_iterator(text.begin(), text.end(), re), std::sregex_iterator()));
}

#define ECSIM_REQUIRE_SOEM()                                                            \
  do {                                                                                  \
    if (auto caps = checkNetworkCapabilities(); !caps.ok()) {                           \
      if (ciMode()) FAIL() << "CI=true and " << caps.error().message();                 \
      GTEST_SKIP() << "needs network privileges: " << caps.error().message();           \
    }                                                                                   \
    if (!std::filesystem::exists(kSoem / "bin-v1" / "slaveinfo")) {                     \
      if (ciMode()) FAIL() << "SOEM not built in " << kSoem << " (../shared missing?)"; \
      GTEST_SKIP() << "SOEM not built (../shared/tools/build-soem.sh not found)";       \
    }                                                                                   \
  } while (false)

// ecsim serve on one veth end, a SOEM program on the other; returns the program's output.
class SoemRun {
 public:
  explicit SoemRun(std::vector<std::string> serveArgs) : serveArgs_(std::move(serveArgs)) {}

  std::string run(const std::string& program, const std::vector<std::string>& args,
                  std::chrono::seconds timeout) {
    auto ns = VethNamespace::create();
    EXPECT_TRUE(ns.ok()) << (ns.ok() ? "" : ns.error().message());
    if (!ns.ok()) return {};
    const std::string tag = std::to_string(::getpid()) + "_" + std::to_string(counter_++);
    serveLog_ = ::testing::TempDir() + "soem_serve_" + tag + ".log";
    const std::string outLog = ::testing::TempDir() + "soem_out_" + tag + ".log";
    std::vector<std::string> serve{kEcsim, "serve", "--iface", ns->simulatorInterface()};
    serve.insert(serve.end(), serveArgs_.begin(), serveArgs_.end());
    auto server = ns->spawn(serve, SpawnOptions{serveLog_, serveLog_});
    EXPECT_TRUE(server.ok());
    if (!server.ok()) return {};
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // socket open
    std::vector<std::string> argv{(kSoem / program).string(), ns->masterInterface()};
    argv.insert(argv.end(), args.begin(), args.end());
    std::vector<std::string> timed{"timeout", std::to_string(timeout.count())};
    timed.insert(timed.end(), argv.begin(), argv.end());
    auto child = ns->spawn(timed, SpawnOptions{outLog, outLog});
    EXPECT_TRUE(child.ok());
    if (!child.ok()) return {};
    auto code = child->wait(timeout + std::chrono::seconds(10));
    EXPECT_TRUE(code.ok());
    EXPECT_TRUE(server->running()) << "ecsim serve died:\n" << readText(serveLog_);
    (void)server->kill(SIGINT);
    (void)server->wait(std::chrono::seconds(5));
    return readText(outLog);
  }
  std::string serveLog() const { return readText(serveLog_); }

 private:
  std::vector<std::string> serveArgs_;
  std::string serveLog_;
  int counter_{0};
};

TEST(SoemV1, SlaveinfoListsEverySlaveWithItsIdentity) {
  ECSIM_REQUIRE_SOEM();
  SoemRun run({"--slaves", "3"});
  std::string out = run.run("bin-v1/slaveinfo", {"-map"}, std::chrono::seconds(60));
  EXPECT_NE(out.find("3 slaves found and configured."), std::string::npos) << out;
  EXPECT_EQ(countMatches(out, "\n State: 4\n"), 3) << out;
  EXPECT_EQ(countMatches(out, "Man: 00000e5c ID: 00010001 Rev: 00010000"), 3) << out;
  EXPECT_NE(out.find("Configured address: 1003"), std::string::npos) << out;
  EXPECT_EQ(out.find("Not all slaves"), std::string::npos) << out;
  EXPECT_EQ(out.find("Name:?"), std::string::npos) << out;
}

TEST(SoemV2, SlaveinfoListsEverySlaveWithItsIdentity) {
  ECSIM_REQUIRE_SOEM();
  SoemRun run({"--slaves", "5"});
  std::string out = run.run("bin-v2/slaveinfo", {"-map"}, std::chrono::seconds(60));
  EXPECT_NE(out.find("ecx_init on"), std::string::npos) << out;
  EXPECT_NE(out.find("5 slaves found and configured."), std::string::npos) << out;
  EXPECT_EQ(countMatches(out, "\n State: 4\n"), 5) << out;
  EXPECT_EQ(out.find("Not all slaves"), std::string::npos) << out;
}

}  // namespace
}  // namespace ecsim::testing
