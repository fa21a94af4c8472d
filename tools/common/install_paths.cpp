#include "tools/common/install_paths.hpp"

#include <cstdlib>
#include <system_error>

#include "tools/common/version.hpp"

namespace ecsim::tools {
namespace fs = std::filesystem;

namespace {

bool isFolder(const fs::path& p) {
  std::error_code ec;
  return fs::is_directory(p, ec);
}

// `inner` is `outer` or lies below it (both made absolute and normal first).
bool isWithin(const fs::path& inner, const fs::path& outer) {
  if (outer.empty()) return false;
  const fs::path a = inner.lexically_normal();
  const fs::path b = outer.lexically_normal();
  auto ai = a.begin();
  for (auto bi = b.begin(); bi != b.end(); ++bi, ++ai) {
    if (bi->empty()) continue;  // a trailing separator
    if (ai == a.end() || *ai != *bi) return false;
  }
  return true;
}

}  // namespace

Result<fs::path> findDataDir(const DataDirInputs& in) {
  if (in.overrideDir) {
    if (!isFolder(*in.overrideDir)) {
      return Error{ErrorCode::kNotFound,
                   std::string(kDataDirVariable) + "=" + *in.overrideDir + " is not a folder"};
    }
    return fs::path(*in.overrideDir);
  }
  const fs::path installed =
      (in.executable.parent_path() / ".." / "share" / "ecsim").lexically_normal();
  if (isFolder(installed)) return installed;
  if (isWithin(in.executable, in.buildDir) && isFolder(in.sourceDataDir)) return in.sourceDataDir;
  return Error{ErrorCode::kNotFound, "no data folder: " + installed.string() +
                                         " does not exist (set " + std::string(kDataDirVariable) +
                                         " to the folder holding topologies/ and esi/)"};
}

Result<fs::path> dataDir() {
  DataDirInputs in;
  if (const char* v = std::getenv(std::string(kDataDirVariable).c_str())) in.overrideDir = v;
  std::error_code ec;
  in.executable = fs::read_symlink("/proc/self/exe", ec);
  in.buildDir = ECSIM_TOOLS_BUILD_DIR;
  in.sourceDataDir = ECSIM_TOOLS_SOURCE_DATA_DIR;
  return findDataDir(in);
}

Result<fs::path> dataFile(std::string_view relative) {
  auto dir = dataDir();
  if (!dir.ok()) return dir.error();
  return *dir / fs::path(relative);
}

std::string versionText(std::string_view tool) {
  std::string text = std::string(tool) + " " + std::string(kVersion);
  if (!kGitRevision.empty()) text += " (git " + std::string(kGitRevision) + ")";
  return text;
}

}  // namespace ecsim::tools
