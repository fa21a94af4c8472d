// Waiting for a real sign of readiness instead of sleeping a fixed time: tests that start
// processes (ecsim serve, ecmaster, SOEM) poll for what the process says or makes, with a
// deadline that only guards against a hang. On a busy 2-core CI machine under sanitizers a
// start-up takes seconds; a fixed sleep sized for a quiet machine races with it.
#pragma once

#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include "link/netns.hpp"

namespace ecsim::testing {

// Generous: a start-up under ASan on a loaded machine, never a normal wait.
inline constexpr std::chrono::seconds kReadyTimeout{30};

// Polls `done` every 10 ms until it holds (true) or `limit` passes (false, after a last try).
template <typename Done>
bool waitUntil(Done&& done, std::chrono::milliseconds limit = kReadyTimeout) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < deadline) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return done();
}

inline std::string readWholeFile(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Waits until the file at `path` contains `text` (a line a child process printed and flushed),
// giving up early when `child` has ended.
inline bool waitForText(const std::filesystem::path& path, const std::string& text,
                        ChildProcess& child, std::chrono::milliseconds limit = kReadyTimeout) {
  return waitUntil(
             [&] {
               return readWholeFile(path).find(text) != std::string::npos || !child.running();
             },
             limit) &&
         readWholeFile(path).find(text) != std::string::npos;
}

// A name for a temporary file of this process: the tests of another build (a developer's and
// a CI run on the same machine) may run at the same time with the same test names.
inline std::string uniqueTempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("ecsim-" + std::to_string(::getpid()) + "-" + name))
      .string();
}

}  // namespace ecsim::testing
