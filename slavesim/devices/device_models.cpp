#include "slavesim/devices/device_models.hpp"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cmath>
#include <limits>
#include <optional>
#include <string_view>

#include "slavesim/coe/standard_objects.hpp"
#include "slavesim/devices/device_params.hpp"
#include "slavesim/generic_slave.hpp"

namespace ecsim::slavesim::devices {
namespace {

constexpr std::uint32_t kProductDigitalInputs = 0x00001008;
constexpr std::uint32_t kProductDigitalOutputs = 0x00002008;
constexpr std::uint32_t kProductAnalogInputs = 0x00003102;
constexpr std::uint32_t kProductDrive = 0x00007201;
constexpr std::uint32_t kProductRobotDrive = 0x00007211;
constexpr std::uint32_t kProductSsiEncoder = 0x00005001;
constexpr std::uint32_t kBeckhoffVendorId = 0x00000002;
constexpr std::uint32_t kBeckhoffEj5002 = 0x138A2852;
constexpr std::uint32_t kProfileDrive = 402;
constexpr std::uint32_t kProfileModularDevice = 5001;  // ETG.5001 MDP
constexpr std::uint16_t kEncoderResolution = 0x2011;
constexpr std::uint8_t kIdentityVendorSub = 1;  // 0x1018:01 vendor id
constexpr std::uint16_t kAxisIndexStep = 0x800;  // ETG.6010 multi-axis layout
constexpr unsigned kMaxAxes = 8;

template <typename T>
Status install(ProcessDataDevice& device, Result<std::unique_ptr<T>> model) {
  if (!model.ok()) return model.takeError();
  device.setApplication(std::move(model).value());
  return okStatus();
}

template <typename T>
Status installDrive(ProcessDataDevice& device, Result<std::unique_ptr<T>> model,
                    const EmergencySink& emergencies) {
  if (!model.ok()) return model.takeError();
  (*model)->setEmergencySink(emergencies);
  device.setApplication(std::move(model).value());
  return okStatus();
}

// drive.mode against the supported drive modes 0x6502 of each axis (the parameter's value was
// checked against the modes ecsim models when it was read).
Status checkDriveMode(const coe::ObjectDictionary& od, const DriveParams& drive, int line,
                      unsigned axes) {
  if (!drive.initialMode) return okStatus();
  for (unsigned n = 0; n < std::max(axes, 1u); ++n) {
    const auto index = static_cast<std::uint16_t>(cia402::obj::kSupportedDriveModes +
                                                  n * kAxisIndexStep);
    const auto supported = od.get<std::uint32_t>(index, 0);
    const std::uint32_t runnable =
        cia402::runnableModes(supported.ok() ? std::optional<std::uint64_t>(*supported)
                                             : std::nullopt);
    if (cia402::startsIn(*drive.initialMode, runnable)) continue;
    char text[160];
    std::snprintf(text, sizeof text,
                  "parameter 'drive.mode'%s = '%d': axis %u's supported drive modes 0x%04X = "
                  "0x%08X do not list it; allowed: ",
                  line > 0 ? (" on line " + std::to_string(line)).c_str() : "",
                  static_cast<int>(*drive.initialMode), n, static_cast<unsigned>(index),
                  static_cast<unsigned>(supported.ok() ? *supported : 0));
    return makeError(ErrorCode::kInvalidArgument, text + cia402::describeModes(runnable));
  }
  return okStatus();
}

// One drive per axis of the dictionary: a Cia402Drive for one, a MultiAxisDrive for more.
Status installDrives(ProcessDataDevice& device, const DriveParams& drive,
                     const EmergencySink& emergencies, int modeLine) {
  coe::ObjectDictionary& od = device.dictionary();
  const unsigned count = cia402AxisCount(od);
  ECSIM_TRY(checkDriveMode(od, drive, modeLine, count));
  if (count <= 1) return installDrive(device, Cia402Drive::create(od, drive), emergencies);
  std::vector<std::unique_ptr<Cia402Drive>> axes;
  for (unsigned n = 0; n < count; ++n) {
    DriveParams params = drive;
    params.axisNumber = n;
    if (n > 0) params.stateFile.clear();  // the state file is axis 0's
    ECSIM_ASSIGN_OR_RETURN(auto axis, Cia402Drive::create(od, params));
    axis->setEmergencySink(emergencies);
    axes.push_back(std::move(axis));
  }
  device.setApplication(std::make_unique<MultiAxisDrive>(std::move(axes)));
  return okStatus();
}

template <typename Terminal>
Status applyScripts(Terminal& terminal, const std::vector<std::pair<unsigned, Signal>>& scripts) {
  for (const auto& [channel, signal] : scripts) {
    if (channel < 1 || channel > terminal.channels()) {
      return makeError(ErrorCode::kInvalidArgument, "signal." + std::to_string(channel) +
                                                        ": the terminal has channels 1.." +
                                                        std::to_string(terminal.channels()));
    }
    terminal.setScript(channel, signal);
  }
  return okStatus();
}

}  // namespace

DeviceModelKind deviceModelFor(std::uint32_t vendorId, std::uint32_t productCode,
                               std::optional<std::uint32_t> profileNo, bool hasDriveObjects) {
  if (vendorId == kBeckhoffVendorId && productCode == kBeckhoffEj5002) {
    return DeviceModelKind::kSsiEncoder;
  }
  const bool drive = profileNo ? *profileNo == kProfileDrive : hasDriveObjects;
  if (vendorId != kEcsimVendorId) return drive ? DeviceModelKind::kCia402Drive : DeviceModelKind::kNone;
  switch (productCode) {
    case kProductDigitalInputs:
      return DeviceModelKind::kDigitalInputs;
    case kProductDigitalOutputs:
      return DeviceModelKind::kDigitalOutputs;
    case kProductAnalogInputs:
      return DeviceModelKind::kAnalogInputs;
    case kProductDrive:
      return DeviceModelKind::kCia402Drive;
    case kProductRobotDrive:
      return DeviceModelKind::kRobotDrive;
    case kProductSsiEncoder:
      return DeviceModelKind::kSsiEncoder;
    default:
      break;
  }
  return drive ? DeviceModelKind::kCia402Drive : DeviceModelKind::kNone;
}

DeviceModelKind chooseIoProfile(coe::ObjectDictionary& od, std::optional<std::uint32_t> profileNo) {
  if (profileNo && *profileNo != kProfileModularDevice) return DeviceModelKind::kNone;
  const IoProfileChoice choice = ioProfileOf(od);
  if (choice.analog) return DeviceModelKind::kAnalog;
  return choice.digital ? DeviceModelKind::kIo : DeviceModelKind::kNone;
}

std::optional<DeviceModelKind> deviceModelByName(std::string_view name) {
  if (name == "cia402") return DeviceModelKind::kCia402Drive;
  if (name == "io") return DeviceModelKind::kIo;
  if (name == "analog") return DeviceModelKind::kAnalog;
  if (name == "loopback") return DeviceModelKind::kLoopback;
  if (name == "encoder") return DeviceModelKind::kEncoder;
  if (name == "none") return DeviceModelKind::kNone;
  return std::nullopt;
}

std::vector<std::string> deviceModelNames() {
  return {"cia402", "io", "analog", "encoder", "loopback", "none"};
}

unsigned cia402AxisCount(const coe::ObjectDictionary& od) {
  unsigned n = 0;
  while (n < kMaxAxes) {
    const auto shift = static_cast<std::uint16_t>(n * kAxisIndexStep);
    if (od.findEntry(static_cast<std::uint16_t>(cia402::obj::kControlword + shift), 0) == nullptr ||
        od.findEntry(static_cast<std::uint16_t>(cia402::obj::kStatusword + shift), 0) == nullptr) {
      break;
    }
    ++n;
  }
  return n;
}

Status attachDeviceModel(ProcessDataDevice& device, DeviceModelKind kind,
                         const DeviceModelOptions& options) {
  device.setApplication(nullptr);  // the old model goes first (and saves its state)
  coe::ObjectDictionary& od = device.dictionary();
  if (!options.scripts.empty() && kind != DeviceModelKind::kDigitalInputs &&
      kind != DeviceModelKind::kAnalogInputs && kind != DeviceModelKind::kSsiEncoder &&
      kind != DeviceModelKind::kIo && kind != DeviceModelKind::kAnalog &&
      kind != DeviceModelKind::kLoopback && kind != DeviceModelKind::kEncoder) {
    return makeError(ErrorCode::kInvalidArgument,
                     "input scripts (signal.N) need an input terminal or an encoder");
  }
  DriveParams drive = options.drive;
  if (!options.stateFile.empty()) drive.stateFile = options.stateFile;
  // 0x2011 is ecsim's encoder resolution object only in ecsim's own devices (0x1018:01); a
  // vendor's 0x2011 is the vendor's (the Ingenia EVS-NET-01's is a status word).
  const auto vendor = od.get<std::uint32_t>(coe::kIdentityIndex, kIdentityVendorSub);
  const bool ecsimResolution = vendor.ok() && *vendor == kEcsimVendorId;
  drive.resolutionFromDictionary = !options.encoderResolutionSet;  // else 0x608F may set it
  if (options.encoderResolutionSet) {
    if (ecsimResolution && od.findEntry(kEncoderResolution, 0) != nullptr) {
      ECSIM_TRY(od.set<std::uint32_t>(kEncoderResolution, 0, drive.encoder.countsPerRevolution));
    }
  } else if (const auto cpr = od.get<std::uint32_t>(kEncoderResolution, 0);
             ecsimResolution && cpr.ok() && *cpr > 0) {
    drive.encoder.countsPerRevolution = *cpr;
  }
  switch (kind) {
    case DeviceModelKind::kNone:
      return okStatus();
    case DeviceModelKind::kDigitalInputs: {
      ECSIM_ASSIGN_OR_RETURN(auto terminal, DigitalInputTerminal::create(od));
      ECSIM_TRY(applyScripts(*terminal, options.scripts));
      device.setApplication(std::move(terminal));
      return okStatus();
    }
    case DeviceModelKind::kDigitalOutputs:
      return install(device, DigitalOutputTerminal::create(od));
    case DeviceModelKind::kAnalogInputs: {
      ECSIM_ASSIGN_OR_RETURN(auto terminal, AnalogInputTerminal::create(od, 2, options.analog));
      ECSIM_TRY(applyScripts(*terminal, options.scripts));
      device.setApplication(std::move(terminal));
      return okStatus();
    }
    case DeviceModelKind::kCia402Drive:
      return installDrives(device, drive, options.emergencies, options.driveModeLine);
    case DeviceModelKind::kRobotDrive:
      ECSIM_TRY(checkDriveMode(od, drive, options.driveModeLine, 1));
      return installDrive(device, RobotDrive::create(od, drive), options.emergencies);
    case DeviceModelKind::kIo:
    case DeviceModelKind::kLoopback: {
      ECSIM_ASSIGN_OR_RETURN(auto io, makeDigitalIo(od));
      if (!options.scripts.empty() && !io->digitalInputs) {
        return makeError(ErrorCode::kInvalidArgument,
                         "input scripts (signal.N): the device has no digital inputs");
      }
      if (io->digitalInputs) ECSIM_TRY(applyScripts(*io->digitalInputs, options.scripts));
      if (kind == DeviceModelKind::kLoopback && !io->digitalInputs) {
        return makeError(ErrorCode::kInvalidArgument,
                         "model loopback: the device has no digital inputs");
      }
      device.setApplication(std::move(io));
      return okStatus();
    }
    case DeviceModelKind::kAnalog: {
      ECSIM_ASSIGN_OR_RETURN(auto io, makeAnalogIo(od, options.analog));
      if (!options.scripts.empty() && !io->analogInputs) {
        return makeError(ErrorCode::kInvalidArgument,
                         "input scripts (signal.N): the device has no analog inputs");
      }
      if (io->analogInputs) ECSIM_TRY(applyScripts(*io->analogInputs, options.scripts));
      device.setApplication(std::move(io));
      return okStatus();
    }
    case DeviceModelKind::kSsiEncoder: {
      EncoderTerminalOptions encoder{drive.encoder, drive.initialShaftAngle, drive.stateFile,
                                     drive.stateSaveInterval};
      ECSIM_ASSIGN_OR_RETURN(auto terminal, SsiEncoderTerminal::create(od, encoder));
      ECSIM_TRY(applyScripts(*terminal, options.scripts));
      device.setApplication(std::move(terminal));
      return okStatus();
    }
    case DeviceModelKind::kEncoder: {
      EncoderTerminalOptions encoder{drive.encoder, drive.initialShaftAngle, drive.stateFile,
                                     drive.stateSaveInterval};
      ECSIM_ASSIGN_OR_RETURN(auto terminal, SsiEncoderTerminal::createForCounters(od, encoder));
      ECSIM_TRY(applyScripts(*terminal, options.scripts));
      device.setApplication(std::move(terminal));
      return okStatus();
    }
  }
  return okStatus();
}

Status restartDeviceModel(ProcessDataDevice& device, DeviceModelKind kind,
                          const DeviceModelOptions& options) {
  DeviceModelOptions next = options;
  Application* old = device.application();
  if (auto* drive = dynamic_cast<Cia402Drive*>(old)) {
    next.drive.initialShaftAngle = drive->axis().motor().angle();
    if (!next.emergencies) next.emergencies = drive->emergencySink();
  }
  auto carryScripts = [&next](const auto& terminal) {
    next.scripts.clear();
    for (unsigned c = 1; c <= terminal.channels(); ++c) {
      if (terminal.script(c)) next.scripts.emplace_back(c, *terminal.script(c));
    }
  };
  if (auto* di = digitalInputsIn(old)) carryScripts(*di);
  if (auto* ai = analogInputsIn(old)) carryScripts(*ai);
  std::vector<std::pair<double, std::uint8_t>> encoderChannels;  // shaft angle, faults
  if (auto* enc = dynamic_cast<SsiEncoderTerminal*>(old)) {
    carryScripts(*enc);
    for (unsigned c = 1; c <= enc->channels(); ++c) {
      encoderChannels.emplace_back(enc->shaftAngle(c), enc->fault(c));
    }
    if (!encoderChannels.empty()) next.drive.initialShaftAngle = encoderChannels.front().first;
  }
  ECSIM_TRY(attachDeviceModel(device, kind, next));
  if (auto* enc = dynamic_cast<SsiEncoderTerminal*>(device.application())) {
    for (unsigned c = 1; c <= encoderChannels.size() && c <= enc->channels(); ++c) {
      // With a state file the new terminal read channel 1's angle from it: the same angle.
      enc->setShaftAngle(c, encoderChannels[c - 1].first);
      enc->setFault(c, encoderChannels[c - 1].second);
    }
  }
  return okStatus();
}

Application* deviceModelOf(Slave& slave) {
  auto* pd = dynamic_cast<ProcessDataDevice*>(slave.device());
  return pd == nullptr ? nullptr : pd->application();
}

Cia402Drive* driveOf(Slave& slave) { return driveOf(slave, 0); }

Cia402Drive* driveOf(Slave& slave, unsigned axis) {
  Application* model = deviceModelOf(slave);
  if (auto* multi = dynamic_cast<MultiAxisDrive*>(model)) {
    return axis < multi->axes() ? &multi->axis(axis) : nullptr;
  }
  return axis == 0 ? dynamic_cast<Cia402Drive*>(model) : nullptr;
}

RobotDrive* robotDriveOf(Slave& slave) {
  return dynamic_cast<RobotDrive*>(deviceModelOf(slave));
}

DigitalInputTerminal* digitalInputsOf(Slave& slave) {
  return digitalInputsIn(deviceModelOf(slave));
}

DigitalOutputTerminal* digitalOutputsOf(Slave& slave) {
  return digitalOutputsIn(deviceModelOf(slave));
}

AnalogInputTerminal* analogInputsOf(Slave& slave) {
  return analogInputsIn(deviceModelOf(slave));
}

AnalogOutputTerminal* analogOutputsOf(Slave& slave) {
  return analogOutputsIn(deviceModelOf(slave));
}

SsiEncoderTerminal* encoderTerminalOf(Slave& slave) {
  return dynamic_cast<SsiEncoderTerminal*>(deviceModelOf(slave));
}

// ---- parameters by name (device_params.hpp) ------------------------------------------------
namespace {

Error paramError(const DeviceParam& p, const std::string& message) {
  std::string where = p.line > 0 ? "line " + std::to_string(p.line) + ": " : std::string();
  return makeError(ErrorCode::kInvalidArgument,
                   where + "parameter '" + p.name + "' = '" + p.value + "': " + message);
}

Result<double> number(const DeviceParam& p, double min = -std::numeric_limits<double>::max(),
                      double max = std::numeric_limits<double>::max()) {
  double v = 0.0;
  const char* begin = p.value.data();
  const char* end = begin + p.value.size();
  auto [ptr, ec] = std::from_chars(begin, end, v);
  if (ec != std::errc() || ptr != end || !std::isfinite(v)) {
    return paramError(p, "not a number");
  }
  if (v < min || v > max) {
    return paramError(p, "must be within " + std::to_string(min) + " .. " + std::to_string(max));
  }
  return v;
}

Result<bool> flag(const DeviceParam& p) {
  if (p.value == "1" || p.value == "true") return true;
  if (p.value == "0" || p.value == "false") return false;
  return paramError(p, "must be 0 or 1");
}

template <typename T>
Result<T> integer(const DeviceParam& p, T min, T max) {
  ECSIM_ASSIGN_OR_RETURN(double v, number(p, static_cast<double>(min), static_cast<double>(max)));
  if (v != std::floor(v)) return paramError(p, "must be a whole number");
  return static_cast<T>(v);
}

constexpr double kPositive = 1e-300;
constexpr double kHuge = std::numeric_limits<double>::max();

// A parameter of the motor, axis, encoder, drive or analog groups; false: not one of them.
Result<bool> applyPlain(DeviceModelOptions& o, const DeviceParam& p) {
  MotorParams& m = o.drive.motor;
  const std::string_view n = p.name;
  // Motor: physical values (positive where zero makes the model singular).
  struct Field {
    std::string_view name;
    double* target;
    double min;
  };
  const Field motor[] = {
      {"motor.inertia", &m.inertia, kPositive},
      {"motor.viscousFriction", &m.viscousFriction, 0.0},
      {"motor.coulombFriction", &m.coulombFriction, 0.0},
      {"motor.gravityTorque", &m.gravityTorque, -kHuge},
      {"motor.gravityAngle", &m.gravityAngle, -kHuge},
      {"motor.torqueConstant", &m.torqueConstant, kPositive},
      {"motor.backEmfConstant", &m.backEmfConstant, 0.0},
      {"motor.resistance", &m.resistance, kPositive},
      {"motor.inductance", &m.inductance, kPositive},
      {"motor.voltageLimit", &m.voltageLimit, kPositive},
      {"motor.ratedTorque", &m.ratedTorque, kPositive},
      {"drive.quickStopDeceleration", &o.drive.quickStopDeceleration, kPositive},
      {"drive.initialShaftAngle", &o.drive.initialShaftAngle, -kHuge},
      {"encoder.noise", &o.drive.encoder.noiseCounts, 0.0},
      {"analog.fullScaleVolts", &o.analog.fullScaleVolts, kPositive},
  };
  for (const Field& f : motor) {
    if (n != f.name) continue;
    ECSIM_ASSIGN_OR_RETURN(*f.target, number(p, f.min));
    return true;
  }
  if (n == "motor.gravityPendulum") {
    ECSIM_ASSIGN_OR_RETURN(m.gravityPendulum, flag(p));
  } else if (n == "axis.substepHz") {
    ECSIM_ASSIGN_OR_RETURN(o.drive.axis.substepHz, number(p, 1000.0, 1e6));
  } else if (n == "axis.idealCurrentLoop") {
    ECSIM_ASSIGN_OR_RETURN(o.drive.axis.idealCurrentLoop, flag(p));
  } else if (n == "encoder.kind") {
    if (p.value == "incremental") {
      o.drive.encoder.kind = EncoderKind::kIncremental;
    } else if (p.value == "single-turn") {
      o.drive.encoder.kind = EncoderKind::kAbsoluteSingleTurn;
    } else if (p.value == "multi-turn") {
      o.drive.encoder.kind = EncoderKind::kAbsoluteMultiTurn;
    } else {
      return paramError(p, "must be incremental, single-turn or multi-turn");
    }
  } else if (n == "encoder.resolution") {
    ECSIM_ASSIGN_OR_RETURN(o.drive.encoder.countsPerRevolution,
                           integer<std::uint32_t>(p, 1, 1u << 30));
    o.encoderResolutionSet = true;
  } else if (n == "encoder.multiTurnBits") {
    ECSIM_ASSIGN_OR_RETURN(o.drive.encoder.multiTurnBits, integer<unsigned>(p, 0, 40));
  } else if (n == "encoder.quantisation") {
    ECSIM_ASSIGN_OR_RETURN(o.drive.encoder.quantisationStep,
                           integer<std::uint32_t>(p, 1, 1u << 30));
  } else if (n == "encoder.seed") {
    ECSIM_ASSIGN_OR_RETURN(o.drive.encoder.seed, integer<std::uint64_t>(p, 0, 1ull << 52));
  } else if (n == "drive.followingErrorWindow") {
    ECSIM_ASSIGN_OR_RETURN(o.drive.followingErrorWindow, integer<std::uint32_t>(p, 0, 0xFFFFFFFFu));
  } else if (n == "drive.followingErrorTimeout") {
    ECSIM_ASSIGN_OR_RETURN(o.drive.followingErrorTimeoutMs, integer<std::uint16_t>(p, 0, 0xFFFF));
  } else if (n == "drive.torqueLimit") {
    ECSIM_ASSIGN_OR_RETURN(o.drive.maxTorquePerMille, integer<std::uint16_t>(p, 0, 0xFFFF));
  } else if (n == "drive.mode") {
    // A CiA 402 mode ecsim models (or 0, no mode); the device's 0x6502 is checked where the
    // model is attached (checkDriveMode).
    ECSIM_ASSIGN_OR_RETURN(auto mode, integer<std::int8_t>(p, -128, 127));
    if (!cia402::startsIn(mode, cia402::kModelledModes)) {
      return paramError(p, "not a mode of operation ecsim's CiA 402 drive models; allowed: " +
                               cia402::describeModes(cia402::kModelledModes));
    }
    o.drive.initialMode = mode;
    o.driveModeLine = p.line;
  } else if (n == "drive.homeSwitch" || n == "drive.negativeLimitSwitch" ||
             n == "drive.positiveLimitSwitch") {
    std::optional<double>& target = n == "drive.homeSwitch" ? o.drive.homeSwitchCounts
                                    : n == "drive.negativeLimitSwitch"
                                        ? o.drive.negativeLimitSwitchCounts
                                        : o.drive.positiveLimitSwitchCounts;
    if (p.value == "none") {
      target.reset();
    } else {
      ECSIM_ASSIGN_OR_RETURN(auto counts, integer<std::int64_t>(p, -(1ll << 52), 1ll << 52));
      target = static_cast<double>(counts);
    }
    const auto& lo = o.drive.negativeLimitSwitchCounts;
    const auto& hi = o.drive.positiveLimitSwitchCounts;
    if (lo && hi && *lo >= *hi) {
      return paramError(p, "the negative limit switch must be below the positive one (" +
                               std::to_string(static_cast<long long>(*lo)) + " >= " +
                               std::to_string(static_cast<long long>(*hi)) + ")");
    }
  } else if (n == "drive.homeOffset") {
    ECSIM_ASSIGN_OR_RETURN(o.drive.homeOffset, integer<std::int64_t>(p, -(1ll << 52), 1ll << 52));
  } else if (n == "drive.initTimeMs") {
    ECSIM_ASSIGN_OR_RETURN(auto ms, integer<std::int64_t>(p, 0, 3'600'000));
    o.drive.initTime = ms * kNsPerMs;
  } else if (n == "drive.stateSaveIntervalMs") {
    ECSIM_ASSIGN_OR_RETURN(auto ms, integer<std::int64_t>(p, 0, 3'600'000));
    o.drive.stateSaveInterval = ms * kNsPerMs;
  } else if (n == "drive.faultReactionTimeoutMs") {
    ECSIM_ASSIGN_OR_RETURN(auto ms, integer<std::int64_t>(p, 0, 3'600'000));
    o.drive.faultReactionTimeout = ms * kNsPerMs;
  } else if (n == "analog.conversionPeriodUs") {
    ECSIM_ASSIGN_OR_RETURN(auto us, integer<std::int64_t>(p, 1, 10'000'000));
    o.analog.conversionPeriod = us * 1000;
  } else {
    return false;
  }
  return true;
}

}  // namespace

Status applyDeviceParams(DeviceModelOptions& options, const std::vector<DeviceParam>& params,
                         const std::filesystem::path& baseDir) {
  double velocityHz = 100.0;
  double currentHz = 1000.0;
  bool anyGain = false;
  for (const DeviceParam& p : params) {
    if (p.name.rfind("signal.", 0) == 0) {
      const DeviceParam channelText{"", p.name.substr(7), p.line};
      auto channel = integer<unsigned>(channelText, 1, 64);
      if (!channel.ok()) return paramError(p, "the channel after 'signal.' must be 1..64");
      auto signal = parseSignal(p.value, baseDir);
      if (!signal.ok()) return paramError(p, signal.error().message());
      options.scripts.emplace_back(*channel, std::move(signal).value());
      continue;
    }
    if (p.name == "loopback.from") {
      if (p.value.empty()) return paramError(p, "needs the name of a slave");
      options.loopbackFrom = p.value;
      options.loopbackLine = p.line;
      continue;
    }
    if (p.name.rfind("gains.", 0) == 0) {
      anyGain = true;
      if (p.name == "gains.velocityHz") {
        ECSIM_ASSIGN_OR_RETURN(velocityHz, number(p, 0.1, 1e5));
      } else if (p.name == "gains.currentHz") {
        ECSIM_ASSIGN_OR_RETURN(currentHz, number(p, 1.0, 1e6));
      }
      continue;
    }
    ECSIM_ASSIGN_OR_RETURN(bool known, applyPlain(options, p));
    if (!known) return paramError(p, "unknown parameter (docs/topology.md lists them)");
  }
  if (!anyGain) return okStatus();
  ServoGains g = ServoGains::tuned(options.drive.motor, velocityHz, currentHz);
  struct Gain {
    std::string_view name;
    double* target;
  };
  const Gain gains[] = {
      {"gains.positionKp", &g.positionKp},
      {"gains.velocityKp", &g.velocityKp},
      {"gains.velocityTi", &g.velocityTi},
      {"gains.currentKp", &g.currentKp},
      {"gains.currentTi", &g.currentTi},
      {"gains.velocityFeedForward", &g.velocityFeedForward},
      {"gains.accelerationFeedForward", &g.accelerationFeedForward},
  };
  for (const DeviceParam& p : params) {
    if (p.name.rfind("gains.", 0) != 0 || p.name == "gains.velocityHz" ||
        p.name == "gains.currentHz") {
      continue;
    }
    bool known = false;
    for (const Gain& gain : gains) {
      if (p.name != gain.name) continue;
      ECSIM_ASSIGN_OR_RETURN(*gain.target, number(p, 0.0));
      known = true;
    }
    if (!known) return paramError(p, "unknown parameter (docs/topology.md lists them)");
  }
  options.drive.gains = g;
  return okStatus();
}

}  // namespace ecsim::slavesim::devices
