// For tests that need network privileges (veth pairs, namespaces, raw sockets, TAP): under
// CI=true a missing capability is a failure; elsewhere the test is skipped with the reason.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "link/netns.hpp"

namespace ecsim::testing {

inline bool ciModeForPrivileges() {
  const char* ci = std::getenv("CI");
  return ci != nullptr && std::string(ci) == "true";
}

}  // namespace ecsim::testing

#define ECSIM_REQUIRE_NETWORK()                                               \
  do {                                                                        \
    if (auto caps = ::ecsim::checkNetworkCapabilities(); !caps.ok()) {        \
      if (::ecsim::testing::ciModeForPrivileges())                            \
        FAIL() << "CI=true and " << caps.error().message();                   \
      GTEST_SKIP() << "needs network privileges: " << caps.error().message(); \
    }                                                                         \
  } while (false)
