#include "slavesim/devices/device_state.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <system_error>

namespace ecsim::slavesim::devices {
namespace {

constexpr char kMagic[] = "ecsim-device-state";
constexpr int kVersion = 1;
constexpr char kShaftAngle[] = "shaft-angle-rad";

Error parseError(const std::filesystem::path& path, int line, const std::string& what) {
  return makeError(ErrorCode::kParse, path.string() + ":" + std::to_string(line) + ": " + what);
}

}  // namespace

Result<DeviceState> loadDeviceState(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    return makeError(ErrorCode::kNotFound, path.string() + ": no device state file");
  }
  std::ifstream in(path);
  if (!in) return makeError(ErrorCode::kIo, path.string() + ": cannot open device state file");
  DeviceState state;
  bool header = false;
  bool angle = false;
  std::string line;
  int lineNo = 0;
  while (std::getline(in, line)) {
    ++lineNo;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line.front() == '#') continue;
    const std::size_t space = line.find(' ');
    const std::string key = line.substr(0, space);
    const std::string value = space == std::string::npos ? "" : line.substr(space + 1);
    if (!header) {
      if (key != kMagic) return parseError(path, lineNo, "not an ecsim device state file");
      if (value != std::to_string(kVersion)) {
        return parseError(path, lineNo, "unsupported device state version '" + value + "'");
      }
      header = true;
      continue;
    }
    if (key == kShaftAngle) {
      double v = 0.0;
      auto [ptr, err] = std::from_chars(value.data(), value.data() + value.size(), v);
      if (err != std::errc() || ptr != value.data() + value.size() || !std::isfinite(v)) {
        return parseError(path, lineNo, "bad shaft angle '" + value + "'");
      }
      state.shaftAngle = v;
      angle = true;
    }
    // Unknown keys are skipped: later versions of a version-1 file may add some.
  }
  if (!header) return parseError(path, lineNo, "empty device state file");
  if (!angle) return parseError(path, lineNo, std::string("no ") + kShaftAngle + " line");
  return state;
}

Status saveDeviceState(const std::filesystem::path& path, const DeviceState& state) {
  std::filesystem::path tmp = path;
  tmp += ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    if (!out) return makeError(ErrorCode::kIo, tmp.string() + ": cannot write device state");
    char number[64];
    // %.17g reads back to the same double.
    std::snprintf(number, sizeof number, "%.17g", state.shaftAngle);
    out << "# ecsim device state: the drive's shaft angle, kept across power cycles\n"
        << kMagic << " " << kVersion << "\n"
        << kShaftAngle << " " << number << "\n";
    out.flush();
    if (!out) return makeError(ErrorCode::kIo, tmp.string() + ": write failed");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    return makeError(ErrorCode::kIo,
                     path.string() + ": cannot replace device state: " + ec.message());
  }
  return okStatus();
}

}  // namespace ecsim::slavesim::devices
