// Whether the tests run under CI=true, where a missing prerequisite (shared data, a privilege,
// a built tool) is a failure instead of a skip (the developers' guide). The one definition.
#pragma once

#include <cstdlib>
#include <string_view>

namespace ecsim::testing {

inline bool ciMode() {
  const char* ci = std::getenv("CI");
  return ci != nullptr && std::string_view(ci) == "true";
}

}  // namespace ecsim::testing
