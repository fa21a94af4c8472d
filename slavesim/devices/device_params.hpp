// Device model parameters by name, as a topology file gives them
// (<Param name="motor.inertia" value="2.5e-5"/>, docs/topology.md lists every name):
//
//   motor.*    inertia, viscousFriction, coulombFriction, gravityTorque, gravityPendulum (0/1),
//              gravityAngle, torqueConstant, backEmfConstant, resistance, inductance,
//              voltageLimit, ratedTorque                                    (MotorParams, SI)
//   gains.*    velocityHz, currentHz (the bandwidths ServoGains::tuned() uses), then the
//              single gains positionKp, velocityKp, velocityTi, currentKp, currentTi,
//              velocityFeedForward, accelerationFeedForward overriding the tuned ones
//   axis.*     substepHz, idealCurrentLoop (0/1)
//   encoder.*  kind (incremental, single-turn, multi-turn), resolution (counts per turn),
//              multiTurnBits, quantisation (counts), noise (counts, standard deviation), seed;
//              a drive's encoder, or each channel's of an encoder terminal (ECS5001, the
//              encoder profile of any counter terminal: count = turns * resolution), whose
//              shaft starts at drive.initialShaftAngle and may be scripted by signal.N (turns)
//   drive.*    followingErrorWindow (user units, 0x6065), followingErrorTimeout (ms, 0x6066),
//              torqueLimit (per mille of rated torque, 0x6072), quickStopDeceleration
//              (counts/s^2), homeOffset (counts), initialShaftAngle (rad), mode (0x6060 at
//              power-up, e.g. 8 for CSP; a modelled mode the device's 0x6502 lists, or 0),
//              homeSwitch, negativeLimitSwitch, positiveLimitSwitch (encoder counts before the
//              home offset, or "none"; 0x60FD bits 2, 0, 1), initTimeMs,
//              faultReactionTimeoutMs, stateSaveIntervalMs (simulated ms between saves of
//              the stateFile while the shaft moves, default 100; 0: on state changes only)
//   analog.*   fullScaleVolts, conversionPeriodUs
//   signal.N   input terminals: channel N driven by a script in the text form of signal.hpp
//              ("square period=0.5", "sine amplitude=5 frequency=2", "csv file=trace.csv"),
//              digital channels on at >= 0.5, analog channels in volts; CSV files relative to
//              `baseDir` (the topology file's folder); "output slave=DO1 channel=3" follows
//              another slave's digital output (bound by the topology builder)
//   loopback.from  model="loopback": the slave whose output channel n input channel n follows
// The gains are resolved after all other parameters, so their order in the file does not
// matter. An unknown name or a value that is not a number of the right range is an error
// naming the parameter's line.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "protocol/result.hpp"
#include "slavesim/devices/device_models.hpp"

namespace ecsim::slavesim::devices {

struct DeviceParam {
  std::string name;
  std::string value;
  int line{0};  // for error messages; 0: not from a file
};

Status applyDeviceParams(DeviceModelOptions& options, const std::vector<DeviceParam>& params,
                         const std::filesystem::path& baseDir = {});

}  // namespace ecsim::slavesim::devices
