#include "slavesim/devices/robot_drive.hpp"

namespace ecsim::slavesim::devices {

using cia402::State;

namespace {

constexpr std::uint16_t kRobotInputs = 0x6000;
constexpr std::uint16_t kRobotOutputs = 0x7000;
constexpr std::uint16_t kAbsolutePosition = 0x2010;
constexpr std::uint16_t kEncoderResolution = 0x2011;

constexpr std::uint16_t kShutdown = 0x0006;
constexpr std::uint16_t kEnableOperation = 0x000F;

}  // namespace

RobotDrive::RobotDrive(coe::ObjectDictionary& od, const DriveParams& params,
                       const RobotDriveOptions& options)
    : Cia402Drive(od, params),
      options_(options),
      alarm_(od, kRobotInputs, 1),
      limit_(od, kRobotInputs, 2),
      input_(od, kRobotInputs, 3),
      ready_(od, kRobotInputs, 4),
      servoOn_(od, kRobotOutputs, 1),
      clear_(od, kRobotOutputs, 2),
      outputRef_(od, kRobotOutputs, 3),
      request_(od, kRobotOutputs, 4),
      absolute_(od, kAbsolutePosition, 0),
      resolution_(od, kEncoderResolution, 0) {}

Result<std::unique_ptr<RobotDrive>> RobotDrive::create(coe::ObjectDictionary& od,
                                                       const DriveParams& params,
                                                       const RobotDriveOptions& options) {
  std::unique_ptr<RobotDrive> drive(new RobotDrive(od, params, options));
  ECSIM_TRY(drive->init());
  drive->resolution_.set(drive->encoder().params().countsPerRevolution);
  drive->latchAbsolute();
  drive->publishExtra(0);
  return drive;
}

void RobotDrive::latchAbsolute() {
  absolutePosition_ = static_cast<std::int32_t>(
      static_cast<std::uint32_t>(static_cast<std::uint64_t>(encoderReported())));
  absolute_.set(absolutePosition_);
  absoluteReady_ = true;
}

std::uint16_t RobotDrive::effectiveControlword(std::uint16_t fromMaster) {
  const bool clear = clear_.get() != 0;
  const bool clearEdge = clear && !previousClear_;
  previousClear_ = clear;
  std::uint16_t controlword = fromMaster;
  if (fromMaster == 0 && servoOn_.get() != 0) {
    switch (state()) {
      case State::kSwitchOnDisabled:
        controlword = kShutdown;
        break;
      case State::kReadyToSwitchOn:
      case State::kSwitchedOn:
      case State::kOperationEnabled:
      case State::kQuickStopActive:
        controlword = kEnableOperation;
        break;
      default:
        controlword = 0;
        break;
    }
  }
  if (clearEdge) controlword |= cia402::cw::kFaultReset;
  return controlword;
}

void RobotDrive::publishExtra(SimTime now) {
  const State s = state();
  alarm_.set(s == State::kFault || s == State::kFaultReactionActive ? 1 : 0);
  limit_.set(internalLimit() ? 1 : 0);
  input_.set(homeSwitch() ? 1 : 0);
  output_ = alState() == AlState::kOp && outputRef_.get() != 0;
  const bool request = request_.get() != 0;
  if (request && !previousRequest_) {
    latching_ = true;
    absoluteReady_ = false;
    latchDue_ = now + options_.latchTime;
  }
  previousRequest_ = request;
  if (latching_ && now >= latchDue_) {
    latching_ = false;
    latchAbsolute();
  }
  ready_.set(absoluteReady_ ? 1 : 0);
}

}  // namespace ecsim::slavesim::devices
