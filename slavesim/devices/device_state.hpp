// The state a device keeps across a power cycle and across restarts of the simulator: the
// mechanical position of a drive's shaft, from which its absolute encoder counts. Stored in the
// file a topology names with stateFile= (TopologySlave::stateFile), as text:
//
//   # comment lines
//   ecsim-device-state 1
//   shaft-angle-rad 23.456789012345678
//
// with enough digits that the angle reads back bit for bit, so an absolute position is the
// same after the restart.
//
// Safety: the path must name a regular file that is an ecsim device state file (its first
// line that is not a comment is the magic line above), or nothing yet. Anything else is
// refused with an error naming the path, and left as it is: a symbolic link (name the file
// itself, not a link to it; the folders on the way may be links), a device node, FIFO, socket
// or folder, a file of more than kMaxDeviceStateBytes, and a regular file that is not a state
// file (an empty one too). Reading never blocks (O_NONBLOCK) and never follows a link.
//
// Durability: a save writes a temporary file PATH.tmp in the same folder, fsyncs it, renames
// it over PATH and fsyncs the folder, so after kill -9 or a power loss the file holds either
// the previous state or the new one, never a torn one. A save allocates no memory.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>

#include "protocol/result.hpp"
#include "protocol/time.hpp"

namespace ecsim::slavesim::devices {

struct DeviceState {
  double shaftAngle{0.0};  // rad, unbounded (multi-turn)
};

inline constexpr std::size_t kMaxDeviceStateBytes = 4096;

class DeviceStateFile {
 public:
  // Checks the path as above and reads the state when the file exists (errors name the file
  // and line: kParse when it is not a state file of a version this code reads).
  static Result<DeviceStateFile> open(const std::filesystem::path& path);

  const std::filesystem::path& path() const { return path_; }
  // The state the file held when opened; nullopt when there was no file.
  const std::optional<DeviceState>& loaded() const { return loaded_; }
  // Checks the path again (it may have been replaced meanwhile), then writes atomically and
  // durably as above.
  Status save(const DeviceState& state) const;

 private:
  std::filesystem::path path_;
  std::string tmp_;     // PATH.tmp
  std::string folder_;  // the folder to fsync after the rename
  std::optional<DeviceState> loaded_;
};

// Periodic saves in simulated time, for a device whose state changes while it runs (a joint
// falling under gravity): at most one save per `interval` (at the first call of each multiple
// of `interval` that `now` reaches), and only when the state differs from the last one this
// saver wrote. After kill -9 the file is at most one interval behind. interval 0: no periodic
// saves. A call allocates nothing; a save is a few system calls (fsync included).
class PeriodicStateSaver {
 public:
  PeriodicStateSaver(DeviceStateFile file, SimTime interval)
      : file_(std::move(file)), interval_(interval) {}
  Status tick(SimTime now, const DeviceState& state);
  // Saves now (on a state change, at the end).
  Status save(const DeviceState& state) const { return file_.save(state); }
  const DeviceStateFile& file() const { return file_; }

 private:
  DeviceStateFile file_;
  SimTime interval_;
  std::optional<SimTime> slot_;  // now / interval_ at the last call
  std::optional<double> savedAngle_;
};

// One-shot forms of the above. loadDeviceState: kNotFound when the file does not exist.
Result<DeviceState> loadDeviceState(const std::filesystem::path& path);
Status saveDeviceState(const std::filesystem::path& path, const DeviceState& state);

}  // namespace ecsim::slavesim::devices
