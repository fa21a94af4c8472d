// The CiA 402 power state machine of the simulated drive, through its dictionary: every state
// against every command, legal and illegal (CiA 402 / IEC 61800-7-201 state machine figure and
// command table, as summarised in slavesim/devices/cia402.hpp), plus the statusword codings,
// the fault-reset edge, power-up and the effect of the AL state.
#include <gtest/gtest.h>

#include <cstdio>
#include <ostream>
#include <string>

#include "tests/slavesim/drive_test_support.hpp"

namespace ecsim::testing {
namespace {

// ---- pure functions ---------------------------------------------------------------------------

TEST(Cia402, StatuswordCodingsOfEveryState) {
  // Bits 0-6 as the profile defines them; bit 4 voltage enabled and bit 9 remote set by this
  // drive in every state after power-up (0x0250 is the familiar "switch on disabled").
  const std::pair<State, std::uint16_t> cases[] = {
      {State::kNotReadyToSwitchOn, 0x0000},  {State::kSwitchOnDisabled, 0x0250},
      {State::kReadyToSwitchOn, 0x0231},     {State::kSwitchedOn, 0x0233},
      {State::kOperationEnabled, 0x0237},    {State::kQuickStopActive, 0x0217},
      {State::kFaultReactionActive, 0x021F}, {State::kFault, 0x0218},
  };
  for (const auto& [state, word] : cases) {
    EXPECT_EQ(c402::statusBits(state), word) << c402::toString(state);
    EXPECT_EQ(c402::stateFromStatusword(word), state) << c402::toString(state);
    // Bits outside the state masks (warning, target reached, ...) do not change the state.
    EXPECT_EQ(c402::stateFromStatusword(word | 0xFC80), state) << c402::toString(state);
  }
  EXPECT_EQ(c402::stateFromStatusword(0x0001), std::nullopt) << "no state codes x0xx 0001";
}

TEST(Cia402, ControlwordDecoding) {
  using C = c402::Command;
  const std::tuple<std::uint16_t, std::uint16_t, C> cases[] = {
      {0x0006, 0, C::kShutdown},        {0x000E, 0, C::kShutdown},
      {0x0007, 0, C::kSwitchOn},        {0x000F, 0, C::kEnableOperation},
      {0x0000, 0, C::kDisableVoltage},  {0x000D, 0, C::kDisableVoltage},
      {0x0004, 0, C::kDisableVoltage},  {0x0002, 0, C::kQuickStop},
      {0x000B, 0, C::kQuickStop},       {0x0080, 0x0000, C::kFaultReset},
      {0x008F, 0x000F, C::kFaultReset}, {0x0080, 0x0080, C::kNone},
      {0x010F, 0, C::kEnableOperation},  // halt and mode bits do not change the command
      {0x007F, 0, C::kEnableOperation},
  };
  for (const auto& [word, previous, command] : cases) {
    EXPECT_EQ(c402::decodeControlword(word, previous), command)
        << std::hex << word << " after " << previous;
  }
}

// ---- every state x every command, through the dictionary ----------------------------------------

struct TransitionCase {
  State from;
  std::uint16_t controlword;
  State expected;
  const char* what;
};

void PrintTo(const TransitionCase& c, std::ostream* os) {
  *os << c402::toString(c.from) << " + 0x" << std::hex << c.controlword << " -> "
      << c402::toString(c.expected) << " (" << c.what << ")";
}

constexpr std::uint16_t kShutdown = 0x0006;
constexpr std::uint16_t kSwitchOn = 0x0007;
constexpr std::uint16_t kEnable = 0x000F;
constexpr std::uint16_t kDisableVoltage = 0x0000;
constexpr std::uint16_t kQuickStop = 0x0002;
constexpr std::uint16_t kFaultReset = 0x0080;

// Brings a fresh drive into `from` through legal transitions.
void reach(DriveBench& b, State from) {
  switch (from) {
    case State::kNotReadyToSwitchOn:
      b.tick();  // initTime is long in this case
      break;
    case State::kSwitchOnDisabled:
      b.tick();
      break;
    case State::kReadyToSwitchOn:
      b.tick();
      b.controlword(kShutdown);
      b.tick();
      break;
    case State::kSwitchedOn:
      b.tick();
      b.controlword(kShutdown);
      b.tick();
      b.controlword(kSwitchOn);
      b.tick();
      break;
    case State::kOperationEnabled:
      b.tick();
      b.enable();
      break;
    case State::kQuickStopActive:
      // Option 6: stop on the quick-stop ramp, then stay in Quick stop active.
      b.set<std::int16_t>(c402::obj::kQuickStopOptionCode, 0, 6);
      b.tick();
      b.enable();
      b.controlword(kQuickStop);
      b.run(5 * kNsPerMs);
      break;
    case State::kFaultReactionActive:
      // Moving fast with a slow quick-stop ramp, so the fault reaction lasts.
      b.tick();
      b.mode(9);  // CSV
      b.enable();
      b.set<std::int32_t>(c402::obj::kTargetVelocity, 0, 1'000'000);
      b.run(200 * kNsPerMs);
      b.drive->injectFault(0x5555);
      b.tick();
      break;
    case State::kFault:
      b.tick();
      b.drive->injectFault(0x5555);
      b.tick();
      break;
  }
  ASSERT_EQ(b.state(), from) << "setting up " << c402::toString(from);
}

class Transitions : public ::testing::TestWithParam<TransitionCase> {};

TEST_P(Transitions, FollowTheProfile) {
  const TransitionCase& c = GetParam();
  dev::DriveParams params = benchParams();
  if (c.from == State::kNotReadyToSwitchOn) params.initTime = kNsPerSecond;
  params.quickStopDeceleration = 2.0e6;  // counts/s^2: 0.5 s from 1e6 counts/s
  DriveBench b(params);
  reach(b, c.from);
  if (HasFatalFailure()) return;
  b.controlword(c.controlword);
  b.tick();
  EXPECT_EQ(b.state(), c.expected) << "statusword 0x" << std::hex << b.statusword();
  EXPECT_EQ(b.drive->state(), c.expected);
}

const TransitionCase kCases[] = {
    // Not ready to switch on: every command waits for the end of initialisation.
    {State::kNotReadyToSwitchOn, kShutdown, State::kNotReadyToSwitchOn, "ignored"},
    {State::kNotReadyToSwitchOn, kSwitchOn, State::kNotReadyToSwitchOn, "ignored"},
    {State::kNotReadyToSwitchOn, kEnable, State::kNotReadyToSwitchOn, "ignored"},
    {State::kNotReadyToSwitchOn, kQuickStop, State::kNotReadyToSwitchOn, "ignored"},
    {State::kNotReadyToSwitchOn, kFaultReset, State::kNotReadyToSwitchOn, "ignored"},
    // Switch on disabled
    {State::kSwitchOnDisabled, kShutdown, State::kReadyToSwitchOn, "2"},
    {State::kSwitchOnDisabled, kSwitchOn, State::kSwitchOnDisabled, "illegal"},
    {State::kSwitchOnDisabled, kEnable, State::kSwitchOnDisabled, "illegal"},
    {State::kSwitchOnDisabled, kDisableVoltage, State::kSwitchOnDisabled, "no change"},
    {State::kSwitchOnDisabled, kQuickStop, State::kSwitchOnDisabled, "no change"},
    {State::kSwitchOnDisabled, kFaultReset, State::kSwitchOnDisabled, "no fault"},
    // Ready to switch on
    {State::kReadyToSwitchOn, kShutdown, State::kReadyToSwitchOn, "no change"},
    {State::kReadyToSwitchOn, kSwitchOn, State::kSwitchedOn, "3"},
    {State::kReadyToSwitchOn, kEnable, State::kOperationEnabled, "3 + 4"},
    {State::kReadyToSwitchOn, kDisableVoltage, State::kSwitchOnDisabled, "7"},
    {State::kReadyToSwitchOn, kQuickStop, State::kSwitchOnDisabled, "7"},
    {State::kReadyToSwitchOn, kFaultReset, State::kReadyToSwitchOn, "no fault"},
    // Switched on
    {State::kSwitchedOn, kShutdown, State::kReadyToSwitchOn, "6"},
    {State::kSwitchedOn, kSwitchOn, State::kSwitchedOn, "no change"},
    {State::kSwitchedOn, kEnable, State::kOperationEnabled, "4"},
    {State::kSwitchedOn, kDisableVoltage, State::kSwitchOnDisabled, "10"},
    {State::kSwitchedOn, kQuickStop, State::kSwitchOnDisabled, "10"},
    {State::kSwitchedOn, kFaultReset, State::kSwitchedOn, "no fault"},
    // Operation enabled
    {State::kOperationEnabled, kShutdown, State::kReadyToSwitchOn, "8"},
    {State::kOperationEnabled, kSwitchOn, State::kSwitchedOn, "5 (disable operation)"},
    {State::kOperationEnabled, kEnable, State::kOperationEnabled, "no change"},
    {State::kOperationEnabled, kDisableVoltage, State::kSwitchOnDisabled, "9"},
    {State::kOperationEnabled, kQuickStop, State::kQuickStopActive, "11"},
    {State::kOperationEnabled, kFaultReset, State::kOperationEnabled, "no fault"},
    // Quick stop active (option code 6: stays after stopping)
    {State::kQuickStopActive, kShutdown, State::kQuickStopActive, "illegal"},
    {State::kQuickStopActive, kSwitchOn, State::kQuickStopActive, "illegal"},
    {State::kQuickStopActive, kEnable, State::kOperationEnabled, "16"},
    {State::kQuickStopActive, kDisableVoltage, State::kSwitchOnDisabled, "12"},
    {State::kQuickStopActive, kQuickStop, State::kQuickStopActive, "no change"},
    {State::kQuickStopActive, kFaultReset, State::kQuickStopActive, "no fault"},
    // Fault reaction active: nothing interrupts it.
    {State::kFaultReactionActive, kShutdown, State::kFaultReactionActive, "ignored"},
    {State::kFaultReactionActive, kSwitchOn, State::kFaultReactionActive, "ignored"},
    {State::kFaultReactionActive, kEnable, State::kFaultReactionActive, "ignored"},
    {State::kFaultReactionActive, kDisableVoltage, State::kFaultReactionActive, "ignored"},
    {State::kFaultReactionActive, kQuickStop, State::kFaultReactionActive, "ignored"},
    {State::kFaultReactionActive, kFaultReset, State::kFaultReactionActive, "ignored"},
    // Fault: only the fault-reset edge leaves it.
    {State::kFault, kShutdown, State::kFault, "illegal"},
    {State::kFault, kSwitchOn, State::kFault, "illegal"},
    {State::kFault, kEnable, State::kFault, "illegal"},
    {State::kFault, kDisableVoltage, State::kFault, "no change"},
    {State::kFault, kQuickStop, State::kFault, "no change"},
    {State::kFault, kFaultReset, State::kSwitchOnDisabled, "15"},
};

INSTANTIATE_TEST_SUITE_P(EveryStateEveryCommand, Transitions, ::testing::ValuesIn(kCases),
                         [](const ::testing::TestParamInfo<TransitionCase>& param) {
                           std::string name(c402::toString(param.param.from));
                           std::erase(name, ' ');
                           char cw[16];
                           std::snprintf(cw, sizeof cw, "_cw%04X", param.param.controlword);
                           return name + cw;
                         });

// ---- around the table ---------------------------------------------------------------------------

TEST(Cia402Drive, PowerUpPassesNotReadyToSwitchOnAfterTheInitTime) {
  dev::DriveParams params = benchParams();
  params.initTime = 5 * kNsPerMs;
  DriveBench b(params);
  EXPECT_EQ(b.statusword(), 0x0000) << "before the first step";
  b.run(3 * kNsPerMs);
  EXPECT_EQ(b.state(), State::kNotReadyToSwitchOn);
  b.run(3 * kNsPerMs);
  EXPECT_EQ(b.state(), State::kSwitchOnDisabled) << "transition 1";
  EXPECT_EQ(b.statusword(), 0x0250);
}

TEST(Cia402Drive, FaultResetNeedsARisingEdge) {
  DriveBench b;
  b.tick();
  b.controlword(0x0080);  // bit 7 already high when the fault comes
  b.tick();
  b.drive->injectFault(0x1234);
  b.tick();
  ASSERT_EQ(b.state(), State::kFault);
  EXPECT_EQ(b.errorCode(), 0x1234);
  b.run(3 * kNsPerMs);
  EXPECT_EQ(b.state(), State::kFault) << "bit 7 held high is no reset";
  b.controlword(0x0000);
  b.tick();
  EXPECT_EQ(b.state(), State::kFault);
  b.controlword(0x0080);
  b.tick();
  EXPECT_EQ(b.state(), State::kSwitchOnDisabled) << "rising edge: transition 15";
  EXPECT_EQ(b.errorCode(), 0) << "the error code is cleared with the reset";
}

TEST(Cia402Drive, QuickStopWithOptionTwoEndsInSwitchOnDisabled) {
  dev::DriveParams params = benchParams();
  params.quickStopDeceleration = 1.0e7;
  DriveBench b(params);
  b.tick();
  b.mode(9);
  b.enable();
  b.set<std::int32_t>(c402::obj::kTargetVelocity, 0, 1'000'000);
  b.run(300 * kNsPerMs);
  ASSERT_NEAR(b.velocity(), 1'000'000, 5'000);
  b.controlword(kQuickStop);
  b.tick();
  EXPECT_EQ(b.state(), State::kQuickStopActive) << "11";
  EXPECT_EQ(b.statusword() & c402::sw::kQuickStop, 0) << "bit 5 low while stopping";
  b.controlword(kEnable);  // option 2: no way back while it stops (16 needs 5-8)
  b.tick();
  EXPECT_EQ(b.state(), State::kQuickStopActive);
  b.controlword(kQuickStop);
  b.run(200 * kNsPerMs);  // 1e6 counts/s at 1e7 counts/s^2: 100 ms
  EXPECT_EQ(b.state(), State::kSwitchOnDisabled) << "12 once stopped";
  EXPECT_LT(std::abs(b.velocity()), 2'000);
}

TEST(Cia402Drive, LeavingOpWhileEnabledIsACommunicationFault) {
  DriveBench b;
  b.tick();
  b.enable();
  b.al = AlState::kSafeOp;
  b.run(5 * kNsPerMs);
  EXPECT_EQ(b.state(), State::kFault);
  EXPECT_EQ(b.errorCode(), c402::kErrorCommunication);
  b.controlword(0x0080);
  b.tick();
  EXPECT_EQ(b.state(), State::kFault) << "no commands outside OP";
  b.al = AlState::kOp;
  b.controlword(0x0000);
  b.tick();
  b.controlword(0x0080);
  b.tick();
  EXPECT_EQ(b.state(), State::kSwitchOnDisabled);
}

TEST(Cia402Drive, ControlwordIsIgnoredOutsideOp) {
  DriveBench b;
  b.al = AlState::kPreOp;
  b.tick();
  b.controlword(kShutdown);
  b.run(3 * kNsPerMs);
  EXPECT_EQ(b.state(), State::kSwitchOnDisabled);
  b.al = AlState::kOp;
  b.tick();
  EXPECT_EQ(b.state(), State::kReadyToSwitchOn);
}

}  // namespace
}  // namespace ecsim::testing
