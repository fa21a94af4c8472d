// For tests that need network privileges (veth pairs, namespaces, raw sockets, TAP): under
// CI=true a missing capability is a failure; elsewhere the test is skipped with the reason.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "link/netns.hpp"
#include "tests/support/ci_mode.hpp"

#define ECSIM_REQUIRE_NETWORK()                                                           \
  do {                                                                                    \
    if (auto caps = ::ecsim::checkNetworkCapabilities(); !caps.ok()) {                    \
      if (::ecsim::testing::ciMode()) FAIL() << "CI=true and " << caps.error().message(); \
      GTEST_SKIP() << "needs network privileges: " << caps.error().message();             \
    }                                                                                     \
  } while (false)
