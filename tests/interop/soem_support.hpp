// SOEM against `ecsim serve` over a veth pair inside a private network namespace: the
// harness the interop tests share (a SOEM program on one veth end, the simulator on the other).
#pragma once

#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>
#include <signal.h>

#include <cstdio>
#include <cstring>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "link/netns.hpp"
#include "support/test_network.hpp"

namespace ecsim::testing {

inline const std::string kEcsim = std::string(ECSIM_BINARY_DIR) + "/tools/ecsim/ecsim";
inline const std::string kEcmaster = std::string(ECSIM_BINARY_DIR) + "/tools/ecmaster/ecmaster";
inline const std::filesystem::path kSoem = ECSIM_SOEM_DIR;

inline std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  std::string t = s.str();
  for (auto& c : t) {
    if (c == '\r') c = '\n';  // SOEM's cyclic lines end with \r
  }
  return t;
}

// SCHED_FIFO priority for the third-party master a test starts: with it, a scheduling stall
// on a loaded machine does not make the master miss the simulator's answers ("No slaves
// found!"). Below `ecsim serve --rt` (80), so the simulator still answers first.
inline constexpr int kMasterFifoPriority = 70;

// Whether this process may start SCHED_FIFO programs (root or CAP_SYS_NICE, an rtprio limit,
// and a cgroup with real-time runtime): a throwaway thread tries it on itself. Empty when
// permitted, else why not.
inline std::string realtimeRefusal() {
  std::string refusal;
  std::thread probe([&refusal] {
    sched_param param{};
    param.sched_priority = kMasterFifoPriority;
    if (const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param); rc != 0) {
      refusal = std::strerror(rc);
    }
  });
  probe.join();
  return refusal;
}

// `argv` run under `chrt -f` at kMasterFifoPriority where permitted; otherwise unchanged,
// with a note on stderr (the test goes on at normal priority, more exposed to load).
inline std::vector<std::string> withRealtimePriority(std::vector<std::string> argv) {
  if (const std::string refusal = realtimeRefusal(); !refusal.empty()) {
    std::fprintf(stderr,
                 "note: SCHED_FIFO not permitted (%s): %s runs at normal priority and may miss "
                 "frames on a loaded machine\n",
                 refusal.c_str(), argv.empty() ? "the master" : argv.front().c_str());
    return argv;
  }
  std::vector<std::string> rt{"chrt", "-f", std::to_string(kMasterFifoPriority)};
  rt.insert(rt.end(), argv.begin(), argv.end());
  return rt;
}

// `ecsim ctl --socket SOCKET WORDS...`: its exit status and output.
struct CtlResult {
  int status{-1};
  std::string out;
};

inline CtlResult ctl(const std::string& socket, const std::vector<std::string>& words) {
  std::vector<std::string> argv{kEcsim, "ctl", "--socket", socket};
  argv.insert(argv.end(), words.begin(), words.end());
  const std::string log = ::testing::TempDir() + "ctl_" + std::to_string(::getpid()) + ".log";
  CtlResult r;
  auto child = spawnProcess(argv, SpawnOptions{log, log});
  if (!child.ok()) return r;
  auto rc = child->wait(std::chrono::seconds(10));  // a bound against a hang only
  r.status = rc.ok() ? *rc : -1;
  r.out = readText(log);
  std::filesystem::remove(log);
  return r;
}

// Waits until `file` holds `text` while `process` runs, at most `limit`.
inline bool waitForText(const std::string& file, const std::string& text, ChildProcess& process,
                        std::chrono::seconds limit) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  while (readText(file).find(text) == std::string::npos && process.running() &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return readText(file).find(text) != std::string::npos;
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
    // --rt: answers must come within SOEM's 2 ms even when the host is busy (CI builds).
    std::vector<std::string> serve{kEcsim, "serve", "--rt", "--iface", ns->simulatorInterface()};
    serve.insert(serve.end(), serveArgs_.begin(), serveArgs_.end());
    auto server = ns->spawn(serve, SpawnOptions{serveLog_, serveLog_});
    EXPECT_TRUE(server.ok());
    if (!server.ok()) return {};
    // Ready once it says it serves (the socket is open then); a fixed sleep raced with a
    // slow start on a busy host ("No slaves found!").
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (readText(serveLog_).find("ecsim: serving") == std::string::npos && server->running() &&
           std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    EXPECT_NE(readText(serveLog_).find("ecsim: serving"), std::string::npos)
        << "ecsim serve did not start:\n"
        << readText(serveLog_);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    std::vector<std::string> argv{(kSoem / program).string(), ns->masterInterface()};
    argv.insert(argv.end(), args.begin(), args.end());
    std::vector<std::string> timed{"timeout", std::to_string(timeout.count())};
    timed.insert(timed.end(), argv.begin(), argv.end());
    auto child = ns->spawn(withRealtimePriority(std::move(timed)), SpawnOptions{outLog, outLog});
    EXPECT_TRUE(child.ok());
    if (!child.ok()) return {};
    if (during_) {
      during_(*ns);
      (void)child->kill(SIGTERM);  // a program that runs until stopped (SOEM v2 eoe_test)
    }
    auto code = child->wait(timeout + std::chrono::seconds(10));
    EXPECT_TRUE(code.ok());
    EXPECT_TRUE(server->running()) << "ecsim serve died:\n" << readText(serveLog_);
    (void)server->kill(SIGINT);
    (void)server->wait(std::chrono::seconds(5));
    return readText(outLog);
  }
  std::string serveLog() const { return readText(serveLog_); }
  // Work done in the namespace while the program runs (it is stopped afterwards).
  void setDuring(std::function<void(VethNamespace&)> during) { during_ = std::move(during); }

 private:
  std::vector<std::string> serveArgs_;
  std::function<void(VethNamespace&)> during_;
  std::string serveLog_;
  int counter_{0};
};

}  // namespace ecsim::testing
