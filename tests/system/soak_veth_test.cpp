// The CI soak (issue #21): ecsim-soak sends 100,000 seeded frames, a fifth of them malformed,
// to `ecsim serve --slaves 4` over a veth pair in a namespace of its own, and checks every
// answer against the ESC datasheet. The test fails on any error the soak reports, on a server
// that did not survive, and on any sanitizer report in the server's output (the asan preset
// runs this same test against the sanitizer build).
#include <gtest/gtest.h>
#include <signal.h>

#include <filesystem>
#include <iostream>
#include <optional>
#include <string>

#include "link/netns.hpp"
#include "support/privileges.hpp"
#include "support/readiness.hpp"

namespace ecsim::testing {
namespace {

const std::string kEcsim = std::string(ECSIM_BINARY_DIR) + "/tools/ecsim/ecsim";
const std::string kSoak = std::string(ECSIM_BINARY_DIR) + "/tools/ecsim-soak/ecsim-soak";

// Bounds against a hang only (a sanitizer build on a busy 2-core machine is slow to start,
// answer and report).
constexpr std::chrono::seconds kExitWait{30};
constexpr unsigned kSlowAnswerMs = 5000;
constexpr unsigned kStartUpMs = 30000;

// An MTU above 1514 bytes of frame: the oversized frames reach the server instead of being
// refused by the kernel on the soak's side.
constexpr int kJumboMtu = 2048;

// The soak's report line "name   value": the value, or -1 when the line is missing.
long reported(const std::string& output, const std::string& name) {
  const auto at = output.find("\n" + name + " ");
  if (at == std::string::npos) return -1;
  return std::stol(output.substr(output.find_first_not_of(' ', at + 1 + name.size())));
}

bool sanitizerReport(const std::string& log) {
  return log.find("Sanitizer") != std::string::npos ||
         log.find("runtime error:") != std::string::npos;
}

class SoakedServer {
 public:
  // The control socket goes to the temporary folder, removed with the object: a server killed
  // by a test (SIGKILL) leaves its socket behind, and the default one is in /run/ecsim.
  explicit SoakedServer(const std::string& tag)
      : log_(uniqueTempPath("soak_" + tag + ".log")),
        control_(uniqueTempPath("soak_" + tag + ".sock")) {
    auto ns = VethNamespace::create(VethOptions{kJumboMtu, true});
    if (!ns.ok()) {
      error_ = ns.error().message();
      return;
    }
    ns_.emplace(std::move(ns).value());
    auto child = ns_->spawn({kEcsim, "serve", "--iface", ns_->simulatorInterface(), "--slaves", "4",
                             "--control", control_},
                            SpawnOptions{log_, log_});
    if (!child.ok()) {
      error_ = child.error().message();
      return;
    }
    server_ = std::move(child).value();
  }
  SoakedServer(const SoakedServer&) = delete;
  SoakedServer& operator=(const SoakedServer&) = delete;
  ~SoakedServer() {
    if (server_.pid() > 0) (void)server_.stop();
    std::filesystem::remove(control_);
  }
  const std::string& error() const { return error_; }
  const std::string& log() const { return log_; }
  ChildProcess& server() { return server_; }

  Result<CommandOutput> soak(const std::vector<std::string>& extra) {
    return ns_->run(soakArguments(extra));
  }
  Result<ChildProcess> spawnSoak(const std::vector<std::string>& extra, const std::string& log) {
    return ns_->spawn(soakArguments(extra), SpawnOptions{log, log});
  }

 private:
  std::vector<std::string> soakArguments(const std::vector<std::string>& extra) const {
    std::vector<std::string> argv{kSoak,
                                  "--iface",
                                  ns_->masterInterface(),
                                  "--server-pid",
                                  std::to_string(server_.pid()),
                                  "--wait-ready-ms",
                                  std::to_string(kStartUpMs),
                                  "--timeout-ms",
                                  std::to_string(kSlowAnswerMs)};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return argv;
  }

  std::string log_;
  std::string control_;
  std::string error_;
  std::optional<VethNamespace> ns_;
  ChildProcess server_;
};

TEST(SoakVeth, HundredThousandFramesAllCheckedServerUnharmed) {
  ECSIM_REQUIRE_NETWORK();
  SoakedServer net("ci");
  ASSERT_TRUE(net.error().empty()) << net.error();
  auto out = net.soak({"--frames", "100000", "--seed", "21", "--slaves", "4", "--malformed-percent",
                       "20", "--window", "8"});
  ASSERT_TRUE(out.ok()) << out.error().message();
  const std::string& text = out->output;
  EXPECT_EQ(out->exitCode, 0) << text << readWholeFile(net.log());
  EXPECT_EQ(reported(text, "frames sent"), 100000) << text;
  EXPECT_EQ(reported(text, "answered"), reported(text, "valid sent")) << text;
  for (const char* zero : {"timeouts", "wkc errors", "data errors", "send errors",
                           "malformed answered", "malformed refused", "foreign frames"}) {
    EXPECT_EQ(reported(text, zero), 0) << zero << "\n" << text;
  }
  // About a fifth malformed, every kind sent.
  EXPECT_GT(reported(text, "malformed sent"), 15000) << text;
  for (const char* kind :
       {"  truncated", "  length past end", "  broken chain", "  EtherCAT type not 1",
        "  random bytes", "  other EtherType", "  oversized"}) {
    EXPECT_GT(reported(text, kind), 1000) << kind << "\n" << text;
  }
  ASSERT_TRUE(net.server().running()) << readWholeFile(net.log());
  ASSERT_TRUE(net.server().kill(SIGINT).ok());
  auto code = net.server().wait(kExitWait);
  ASSERT_TRUE(code.ok()) << "ecsim serve did not stop after SIGINT";
  const std::string log = readWholeFile(net.log());
  EXPECT_EQ(*code, 0) << log;
  EXPECT_FALSE(sanitizerReport(log)) << log;
  // The server saw and counted every malformed frame its EtherType let through (oversized
  // ones end at the socket, other EtherTypes never reach it): none lost, none executed.
  const auto at = log.find("malformed dropped ");
  ASSERT_NE(at, std::string::npos) << log;
  const long dropped = std::stol(log.substr(at + std::string("malformed dropped ").size()));
  EXPECT_EQ(dropped, reported(text, "  truncated") + reported(text, "  length past end") +
                         reported(text, "  broken chain") +
                         reported(text, "  EtherCAT type not 1") + reported(text, "  random bytes"))
      << log << text;
  std::cout << text;  // the figures, for the CI log
  if (!HasFailure()) std::filesystem::remove(net.log());
}

// The soak can fail: told the slaves are ET1200s (type 0x12) while the server simulates
// ET1100s, every BRD of the type register is a data error, reported with the frame and the
// datagram, and the exit status is 1.
TEST(SoakVeth, WrongExpectationIsReportedAsDataError) {
  ECSIM_REQUIRE_NETWORK();
  SoakedServer net("wrong");
  ASSERT_TRUE(net.error().empty()) << net.error();
  auto out = net.soak({"--frames", "2000", "--seed", "3", "--esc-type", "0x12"});
  ASSERT_TRUE(out.ok()) << out.error().message();
  const std::string& text = out->output;
  // The set-up's own BRD of the type register already disagrees.
  EXPECT_EQ(out->exitCode, 2) << text;
  EXPECT_NE(text.find("ESC type 0x11, expected 0x12"), std::string::npos) << text;
  EXPECT_NE(text.find("result             FAIL"), std::string::npos) << text;
  ASSERT_TRUE(net.server().kill(SIGINT).ok());
  ASSERT_TRUE(net.server().wait(kExitWait).ok());
  if (!HasFailure()) std::filesystem::remove(net.log());
}

// A server that dies during the soak: the soak notices (its answers stop, its process is gone),
// says so and exits with 1.
TEST(SoakVeth, ServerDeathIsReported) {
  ECSIM_REQUIRE_NETWORK();
  SoakedServer net("death");
  ASSERT_TRUE(net.error().empty()) << net.error();
  const std::string soakLog = uniqueTempPath("soak_death_client.log");
  auto soak = net.spawnSoak({"--frames", "100000000"}, soakLog);
  ASSERT_TRUE(soak.ok()) << soak.error().message();
  ASSERT_TRUE(waitForText(soakLog, "slaves set up", *soak)) << readWholeFile(soakLog);
  ASSERT_TRUE(net.server().kill(SIGKILL).ok());
  auto code = soak->wait(std::chrono::seconds(60));
  ASSERT_TRUE(code.ok()) << "the soak went on after the server died";
  const std::string text = readWholeFile(soakLog);
  EXPECT_EQ(*code, 1) << text;
  EXPECT_NE(text.find("server             ENDED"), std::string::npos) << text;
  EXPECT_NE(text.find("the server process has ended"), std::string::npos) << text;
  if (!HasFailure()) {
    std::filesystem::remove(net.log());
    std::filesystem::remove(soakLog);
  }
}

}  // namespace
}  // namespace ecsim::testing
