// Locating /work/shared reference data from config tests. When the data is absent the test is
// skipped with a reason, or fails when the environment variable CI is "true".
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>
#include "tests/support/ci_mode.hpp"

namespace ecsim::testdata {

inline std::filesystem::path sharedPath(const char* sub) {
  return std::filesystem::path(ECSIM_SHARED_DIR) / sub;
}

inline std::vector<std::uint8_t> readBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace ecsim::testdata

// Declares `var` as the path of `file` under ECSIM_SHARED_DIR/`sub`; skips or fails the test
// when it does not exist.
#define ECSIM_REQUIRE_SHARED_FILE(var, sub, file)                                \
  const std::filesystem::path var = ::ecsim::testdata::sharedPath(sub) / (file); \
  if (!std::filesystem::exists(var)) {                                           \
    if (::ecsim::testing::ciMode()) FAIL() << "CI=true but missing: " << var;    \
    GTEST_SKIP() << "reference data not present: " << var;                       \
  }
