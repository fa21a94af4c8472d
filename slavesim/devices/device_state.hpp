// The state a device keeps across a power cycle and across restarts of the simulator: the
// mechanical position of a drive's shaft, from which its absolute encoder counts. Stored in the
// file a topology names with stateFile= (TopologySlave::stateFile), as text:
//
//   # comment lines
//   ecsim-device-state 1
//   shaft-angle-rad 23.456789012345678
//
// Written atomically (a temporary file renamed over the old one) with enough digits that the
// angle reads back bit for bit, so an absolute position is the same after the restart.
#pragma once

#include <filesystem>

#include "protocol/result.hpp"

namespace ecsim::slavesim::devices {

struct DeviceState {
  double shaftAngle{0.0};  // rad, unbounded (multi-turn)
};

// kNotFound when the file does not exist; kParse (naming file and line) when it is not a state
// file of a version this code reads.
Result<DeviceState> loadDeviceState(const std::filesystem::path& path);
Status saveDeviceState(const std::filesystem::path& path, const DeviceState& state);

}  // namespace ecsim::slavesim::devices
