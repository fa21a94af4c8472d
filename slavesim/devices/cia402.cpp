#include "slavesim/devices/cia402.hpp"

#include <iterator>

#include "slavesim/devices/error_register.hpp"

namespace ecsim::slavesim::devices::cia402 {

std::uint32_t supportedModeBit(std::int8_t mode) {
  // 0x6502: bit 0 PP, 1 VL, 2 PV, 3 TQ, 5 HM, 6 IP, 7 CSP, 8 CSV, 9 CST.
  switch (mode) {
    case 1:
      return 1u << 0;
    case 2:
      return 1u << 1;
    case 3:
      return 1u << 2;
    case 4:
      return 1u << 3;
    case 6:
      return 1u << 5;
    case 7:
      return 1u << 6;
    case 8:
      return 1u << 7;
    case 9:
      return 1u << 8;
    case 10:
      return 1u << 9;
    default:
      return 0;
  }
}

namespace {

// Modes of operation 1..10 (CiA 402 / IEC 61800-7-201 object 0x6060) and their abbreviations;
// 5 is reserved.
constexpr std::string_view kModeAbbreviations[] = {"",   "PP", "VL",  "PV",  "TQ", "",
                                                   "HM", "IP", "CSP", "CSV", "CST"};

}  // namespace

std::uint32_t runnableModes(std::optional<std::uint64_t> supported) {
  if (!supported || *supported == 0) return kModelledModes;
  return static_cast<std::uint32_t>(*supported) & kModelledModes;
}

bool startsIn(std::int8_t mode, std::uint32_t runnable) {
  return mode == 0 || (supportedModeBit(mode) & runnable) != 0;
}

std::string describeModes(std::uint32_t modes) {
  std::string text = "0 (no mode)";
  for (std::int8_t mode = 1; mode < static_cast<std::int8_t>(std::size(kModeAbbreviations));
       ++mode) {
    if ((supportedModeBit(mode) & modes) == 0) continue;
    text += ", " + std::to_string(mode) + " (" +
            std::string(kModeAbbreviations[static_cast<std::size_t>(mode)]) + ")";
  }
  return text;
}

std::string_view toString(Mode mode) {
  switch (mode) {
    case Mode::kNone:
      return "none";
    case Mode::kProfilePosition:
      return "profile position";
    case Mode::kProfileVelocity:
      return "profile velocity";
    case Mode::kHoming:
      return "homing";
    case Mode::kCyclicSyncPosition:
      return "cyclic synchronous position";
    case Mode::kCyclicSyncVelocity:
      return "cyclic synchronous velocity";
    case Mode::kCyclicSyncTorque:
      return "cyclic synchronous torque";
  }
  return "?";
}

std::string_view toString(State state) {
  switch (state) {
    case State::kNotReadyToSwitchOn:
      return "Not ready to switch on";
    case State::kSwitchOnDisabled:
      return "Switch on disabled";
    case State::kReadyToSwitchOn:
      return "Ready to switch on";
    case State::kSwitchedOn:
      return "Switched on";
    case State::kOperationEnabled:
      return "Operation enabled";
    case State::kQuickStopActive:
      return "Quick stop active";
    case State::kFaultReactionActive:
      return "Fault reaction active";
    case State::kFault:
      return "Fault";
  }
  return "?";
}

std::string_view toString(Command command) {
  switch (command) {
    case Command::kNone:
      return "none";
    case Command::kShutdown:
      return "shutdown";
    case Command::kSwitchOn:
      return "switch on / disable operation";
    case Command::kEnableOperation:
      return "enable operation";
    case Command::kDisableVoltage:
      return "disable voltage";
    case Command::kQuickStop:
      return "quick stop";
    case Command::kFaultReset:
      return "fault reset";
  }
  return "?";
}

std::uint8_t errorRegisterFor(std::uint16_t code) {
  namespace er = error_register;
  if (code == kErrorReset) return 0;
  std::uint8_t reg = er::kGeneric;
  switch (code >> 12) {
    case 0x2:
      reg |= er::kCurrent;
      break;
    case 0x3:
      reg |= er::kVoltage;
      break;
    case 0x4:
      reg |= er::kTemperature;
      break;
    case 0x6:
    case 0x7:
    case 0x8:
      reg |= (code >> 8) == 0x81 ? er::kCommunication : er::kDeviceProfile;
      break;
    default:
      break;
  }
  return reg;
}

Command decodeControlword(std::uint16_t controlword, std::uint16_t previous) {
  if ((controlword & cw::kFaultReset) != 0) {
    return (previous & cw::kFaultReset) == 0 ? Command::kFaultReset : Command::kNone;
  }
  if ((controlword & cw::kEnableVoltage) == 0) return Command::kDisableVoltage;
  if ((controlword & cw::kQuickStop) == 0) return Command::kQuickStop;
  if ((controlword & cw::kSwitchOn) == 0) return Command::kShutdown;
  if ((controlword & cw::kEnableOperation) == 0) return Command::kSwitchOn;
  return Command::kEnableOperation;
}

State nextState(State state, Command command, int quickStopOption) {
  switch (state) {
    case State::kNotReadyToSwitchOn:
    case State::kFaultReactionActive:
      return state;
    case State::kSwitchOnDisabled:
      return command == Command::kShutdown ? State::kReadyToSwitchOn : state;  // 2
    case State::kReadyToSwitchOn:
      switch (command) {
        case Command::kSwitchOn:
          return State::kSwitchedOn;  // 3
        case Command::kEnableOperation:
          return State::kOperationEnabled;  // 3 + 4
        case Command::kDisableVoltage:
        case Command::kQuickStop:
          return State::kSwitchOnDisabled;  // 7
        default:
          return state;
      }
    case State::kSwitchedOn:
      switch (command) {
        case Command::kEnableOperation:
          return State::kOperationEnabled;  // 4
        case Command::kShutdown:
          return State::kReadyToSwitchOn;  // 6
        case Command::kDisableVoltage:
        case Command::kQuickStop:
          return State::kSwitchOnDisabled;  // 10
        default:
          return state;
      }
    case State::kOperationEnabled:
      switch (command) {
        case Command::kSwitchOn:
          return State::kSwitchedOn;  // 5
        case Command::kShutdown:
          return State::kReadyToSwitchOn;  // 8
        case Command::kDisableVoltage:
          return State::kSwitchOnDisabled;  // 9
        case Command::kQuickStop:
          return State::kQuickStopActive;  // 11
        default:
          return state;
      }
    case State::kQuickStopActive:
      if (command == Command::kDisableVoltage) return State::kSwitchOnDisabled;  // 12
      if (command == Command::kEnableOperation && quickStopOption >= 5 && quickStopOption <= 8) {
        return State::kOperationEnabled;  // 16
      }
      return state;
    case State::kFault:
      return command == Command::kFaultReset ? State::kSwitchOnDisabled : state;  // 15
  }
  return state;
}

std::uint16_t statusBits(State state) {
  constexpr std::uint16_t kOn = sw::kVoltageEnabled | sw::kRemote;
  switch (state) {
    case State::kNotReadyToSwitchOn:
      return 0x0000;
    case State::kSwitchOnDisabled:
      return kOn | sw::kSwitchOnDisabled;  // 0x0250
    case State::kReadyToSwitchOn:
      return kOn | sw::kQuickStop | sw::kReadyToSwitchOn;  // 0x0231
    case State::kSwitchedOn:
      return kOn | sw::kQuickStop | sw::kReadyToSwitchOn | sw::kSwitchedOn;  // 0x0233
    case State::kOperationEnabled:
      return kOn | sw::kQuickStop | sw::kReadyToSwitchOn | sw::kSwitchedOn |
             sw::kOperationEnabled;  // 0x0237
    case State::kQuickStopActive:
      return kOn | sw::kReadyToSwitchOn | sw::kSwitchedOn | sw::kOperationEnabled;  // 0x0217
    case State::kFaultReactionActive:
      return kOn | sw::kReadyToSwitchOn | sw::kSwitchedOn | sw::kOperationEnabled |
             sw::kFault;  // 0x021F
    case State::kFault:
      return kOn | sw::kFault;  // 0x0218
  }
  return 0;
}

std::optional<State> stateFromStatusword(std::uint16_t s) {
  switch (s & 0x004F) {
    case 0x0000:
      return State::kNotReadyToSwitchOn;
    case 0x0040:
      return State::kSwitchOnDisabled;
    case 0x000F:
      return State::kFaultReactionActive;
    case 0x0008:
      return State::kFault;
    default:
      break;
  }
  switch (s & 0x006F) {
    case 0x0021:
      return State::kReadyToSwitchOn;
    case 0x0023:
      return State::kSwitchedOn;
    case 0x0027:
      return State::kOperationEnabled;
    case 0x0007:
      return State::kQuickStopActive;
    default:
      return std::nullopt;
  }
}

}  // namespace ecsim::slavesim::devices::cia402
