// Where the command-line tools find their data, and what version they are. The tools are
// relocatable: an installed `bin/ecsim` finds its data in `../share/ecsim` beside itself,
// wherever the tree was unpacked (a .deb, a tarball, `cmake --install --prefix`). One variable
// overrides it: ECSIM_DATA_DIR. A tool run from the build tree uses the source tree's
// examples/ (the layout of share/ecsim: esi/, topologies/).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "protocol/result.hpp"

namespace ecsim::tools {

// The variable that overrides the data folder.
inline constexpr std::string_view kDataDirVariable = "ECSIM_DATA_DIR";

struct DataDirInputs {
  std::optional<std::string> overrideDir;  // the value of ECSIM_DATA_DIR, if set
  std::filesystem::path executable;        // this program (/proc/self/exe)
  std::filesystem::path buildDir;          // the build tree the program was built in
  std::filesystem::path sourceDataDir;     // the source tree's examples/
};

// The data folder: the override if set (an error if it is not a folder), else
// <executable>/../share/ecsim if it exists, else the source tree's examples/ when the executable
// lies in its build tree; otherwise an error saying where it looked and what to set.
Result<std::filesystem::path> findDataDir(const DataDirInputs& inputs);
// findDataDir for this process (reads the environment and /proc/self/exe: tools only).
Result<std::filesystem::path> dataDir();
// A file in the data folder, e.g. dataFile("topologies/demo.xml").
Result<std::filesystem::path> dataFile(std::string_view relative);

// "ecsim 0.1.0 (git 1a2b3c4)" or "ecsim 0.1.0" when not built from a git checkout.
std::string versionText(std::string_view tool);

}  // namespace ecsim::tools
