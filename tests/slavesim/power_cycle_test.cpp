// A simulated power cycle forgets what a real device forgets (Slave::powerOn, issue #9): the
// object dictionary back to its power-up values (PDO assignment and mapping included), the
// device model re-created; kept are the EEPROM, a drive's multi-turn position (with and without
// a state file) and input terminals' scripts. Slaves from examples/esi/ecsim_devices.xml.
#include <gtest/gtest.h>

#include <functional>
#include <numbers>

#include "slavesim/devices/device_models.hpp"
#include "slavesim/devices/signal.hpp"
#include "tests/slavesim/drive_test_support.hpp"

namespace ecsim::testing {
namespace {

constexpr double kTurn = 2.0 * std::numbers::pi;
constexpr std::uint32_t kEcs1008 = 0x00001008;
constexpr std::uint16_t kFollowingErrorWindow = 0x6065;  // default 10000 in the ESI
constexpr std::uint16_t kAssignSm2 = 0x1C12;

// ECS7201 images (examples/README.md): SM2 13 bytes, SM3 15 bytes.
constexpr std::size_t kOutTargetPosition = 2, kOutMode = 12;

std::vector<std::uint8_t> le32v(std::uint32_t v) {
  std::vector<std::uint8_t> b(4);
  writeLe32(b, 0, v);
  return b;
}

void powerCycle(slavesim::Slave& slave) {
  slave.powerOff();
  slave.powerOn(0);  // these tests look at values, not at the clock
  EXPECT_TRUE(slave.coldStartStatus().ok()) << slave.coldStartStatus().error().message();
}

TEST(ObjectDictionaryPowerUp, RestoreWritesTheCapturedImageAndDefaultsForLaterEntries) {
  slavesim::coe::ObjectDictionary od;
  od.addVar(0x2000, "a", slavesim::coe::data_type::kUnsigned32, 32,
            slavesim::coe::access::kReadWrite);
  ASSERT_TRUE(od.set<std::uint32_t>(0x2000, 0, 7).ok());  // set up by a builder: power-up
  EXPECT_FALSE(od.hasPowerUpValues());
  od.capturePowerUpValues();
  EXPECT_TRUE(od.hasPowerUpValues());
  auto& late = od.addVar(0x2001, "b", slavesim::coe::data_type::kUnsigned16, 16,
                         slavesim::coe::access::kReadWrite);
  late.entries[0].defaultValue = {0x34, 0x12};
  ASSERT_TRUE(od.set<std::uint32_t>(0x2000, 0, 99).ok());
  ASSERT_TRUE(od.set<std::uint16_t>(0x2001, 0, 5).ok());
  od.restorePowerUpValues();
  EXPECT_EQ(*od.get<std::uint32_t>(0x2000, 0), 7u) << "the captured value, not the default 0";
  EXPECT_EQ(*od.get<std::uint16_t>(0x2001, 0), 0x1234u) << "not captured: its default";
}

// Through frames: what a master downloads by SDO, and what it sends as process data, is gone
// after the power cycle; the absolute multi-turn position is not.
TEST(PowerCycle, DriveForgetsSdoAndPdoValuesButKeepsItsMultiTurnPosition) {
  topology::Segment seg;
  seg.addSlave(makeExampleSlave(kEcs7201));
  slavesim::Slave& slave = seg.slave(0);
  dev::Cia402Drive* drive = dev::driveOf(slave);
  ASSERT_NE(drive, nullptr);
  drive->axis().motor().setAngle(-7.3 * kTurn);  // the shaft 7.3 turns backwards
  SimTime now = 2 * kNsPerMs;
  seg.pollSlaves(kNsPerMs);  // the model starts
  seg.pollSlaves(now);
  const std::int32_t before = *slavesim::objectDictionaryOf(slave)->get<std::int32_t>(0x6064, 0);
  EXPECT_NEAR(before, -7.3 * 131072, 2.0);

  OpSlave op = bringToOp(seg, {{2, true, 13}, {3, false, 15}}, now, [](MailboxMaster& m) {
    EXPECT_EQ(m.uploadValue<std::uint32_t>(kFollowingErrorWindow, 0), 10000u);
    EXPECT_EQ(m.download(kFollowingErrorWindow, 0, le32v(2500)), 0u);
    EXPECT_EQ(m.uploadValue<std::uint32_t>(kFollowingErrorWindow, 0), 2500u);
  });
  ASSERT_EQ(op.outBytes, 13);
  CyclicExchange x{seg, op.outBytes, op.inBytes, now};
  x.put32(kOutTargetPosition, 987654);
  x.put8(kOutMode, 9);  // CSV: the target position is not acted on
  for (int i = 0; i < 5; ++i) x.cycle();
  auto* od = slavesim::objectDictionaryOf(slave);
  ASSERT_EQ(*od->get<std::int32_t>(c402::obj::kTargetPosition, 0), 987654);
  ASSERT_EQ(*od->get<std::int8_t>(c402::obj::kModesOfOperation, 0), 9);

  powerCycle(slave);
  EXPECT_EQ(slave.state(), AlState::kInit);
  std::int32_t target = -1, position = 0;
  std::int8_t mode = 0;
  std::uint32_t window = 0;
  bringToOp(seg, {{2, true, 13}, {3, false, 15}}, x.now + kNsPerMs, [&](MailboxMaster& m) {
    target = m.uploadValue<std::int32_t>(c402::obj::kTargetPosition, 0);
    mode = m.uploadValue<std::int8_t>(c402::obj::kModesOfOperation, 0);
    window = m.uploadValue<std::uint32_t>(kFollowingErrorWindow, 0);
    position = m.uploadValue<std::int32_t>(0x6064, 0);
  });
  EXPECT_EQ(target, 0) << "0x607A back to its default";
  EXPECT_EQ(mode, 8) << "0x6060 back to its ESI default (CSP)";
  EXPECT_EQ(window, 10000u) << "0x6065 downloaded by SDO: back to its default";
  EXPECT_EQ(position, before) << "the multi-turn position survives (no state file)";
}

// CiA 301 0x1010 "store parameters" / 0x1011 "restore default parameters" (added here: the
// ECS7201's ESI has neither): what was stored survives the power cycle, until restored.
TEST(PowerCycle, StoredParametersSurviveUntilDefaultsAreRestored) {
  topology::Segment seg;
  seg.addSlave(makeExampleSlave(kEcs7201));
  slavesim::Slave& slave = seg.slave(0);
  auto* od = slavesim::objectDictionaryOf(slave);
  for (std::uint16_t index :
       {slavesim::coe::kStoreParametersIndex, slavesim::coe::kRestoreDefaultsIndex}) {
    od->addArray(index, "Store/restore", slavesim::coe::data_type::kUnsigned32, 32, 1,
                 slavesim::coe::access::kReadWrite);
    ASSERT_TRUE(od->set<std::uint32_t>(index, 1, 1).ok());  // "on command"
  }
  const std::vector<std::uint8_t> save = {'s', 'a', 'v', 'e'}, load = {'l', 'o', 'a', 'd'};
  SimTime now = kNsPerMs;
  seg.pollSlaves(now);
  auto inPreOp = [&](const std::function<void(MailboxMaster&)>& f) {
    bringToOp(seg, {{2, true, 13}, {3, false, 15}}, now, f);
    powerCycle(slave);
    now += kNsPerMs;
  };
  inPreOp([&](MailboxMaster& m) {
    EXPECT_EQ(m.download(kFollowingErrorWindow, 0, le32v(2500)), 0u);
    EXPECT_EQ(m.download(slavesim::coe::kStoreParametersIndex, 1, load), 0x08000020u)
        << "only \"save\" stores";
    EXPECT_EQ(m.download(slavesim::coe::kStoreParametersIndex, 3, save), 0x06090011u)
        << "sub 3 (application parameters) does not exist here";
    EXPECT_EQ(m.download(slavesim::coe::kStoreParametersIndex, 1, save), 0u);
    EXPECT_EQ(m.uploadValue<std::uint32_t>(slavesim::coe::kStoreParametersIndex, 1), 1u)
        << "the entry keeps reading the device's capability";
    EXPECT_EQ(m.download(kFollowingErrorWindow, 0, le32v(3000)), 0u);  // not stored
  });
  inPreOp([&](MailboxMaster& m) {
    EXPECT_EQ(m.uploadValue<std::uint32_t>(kFollowingErrorWindow, 0), 2500u) << "stored";
    EXPECT_EQ(m.download(slavesim::coe::kRestoreDefaultsIndex, 1, load), 0u);
    EXPECT_EQ(m.uploadValue<std::uint32_t>(kFollowingErrorWindow, 0), 2500u)
        << "restored only at the next power-up";
  });
  inPreOp([&](MailboxMaster& m) {
    EXPECT_EQ(m.uploadValue<std::uint32_t>(kFollowingErrorWindow, 0), 10000u) << "default";
  });
}

TEST(PowerCycle, DriveFaultAndCiA402StateAreForgotten) {
  topology::Segment seg;
  seg.addSlave(makeExampleSlave(kEcs7201));
  slavesim::Slave& slave = seg.slave(0);
  seg.pollSlaves(kNsPerMs);
  dev::driveOf(slave)->injectFault(c402::kErrorOvercurrent);
  for (int i = 2; i < 20; ++i) seg.pollSlaves(i * kNsPerMs);
  auto* od = slavesim::objectDictionaryOf(slave);
  ASSERT_EQ(*od->get<std::uint16_t>(c402::obj::kErrorCode, 0), c402::kErrorOvercurrent);
  powerCycle(slave);
  for (int i = 20; i < 40; ++i) seg.pollSlaves(i * kNsPerMs);
  EXPECT_EQ(*od->get<std::uint16_t>(c402::obj::kErrorCode, 0), 0u);
  EXPECT_NE(c402::stateFromStatusword(*od->get<std::uint16_t>(c402::obj::kStatusword, 0)),
            State::kFault);
}

// PDO assignment (0x1C12) and mapping (0x1600) objects as a master reconfigured them in PREOP:
// back to the ESI's after the power cycle, and the process-data layout with them.
TEST(PowerCycle, PdoAssignmentAndMappingGoBackToPowerUp) {
  topology::Segment seg;
  seg.addSlave(makeExampleSlave(kEcs7201));
  slavesim::Slave& slave = seg.slave(0);
  seg.pollSlaves(kNsPerMs);
  auto* od = slavesim::objectDictionaryOf(slave);
  ASSERT_EQ(*od->get<std::uint16_t>(kAssignSm2, 1), 0x1600u);
  const std::uint8_t mapped = *od->get<std::uint8_t>(0x1600, 0);
  ASSERT_TRUE(od->set<std::uint16_t>(kAssignSm2, 1, 0x1601).ok());  // the CSV PDO instead
  ASSERT_TRUE(od->set<std::uint8_t>(0x1600, 0, 1).ok());            // and 0x1600 cut down
  slave.profile().processData.clear();
  slavesim::processDataDeviceOf(slave)->updateProfile(slave.profile());
  const auto smLength = [&slave](unsigned sm) {
    for (const auto& pd : slave.profile().processData) {
      if (pd.index == sm) return static_cast<int>(pd.length);
    }
    return -1;
  };
  ASSERT_NE(smLength(2), 13);
  powerCycle(slave);
  EXPECT_EQ(*od->get<std::uint16_t>(kAssignSm2, 1), 0x1600u);
  EXPECT_EQ(*od->get<std::uint8_t>(0x1600, 0), mapped);
  slavesim::processDataDeviceOf(slave)->updateProfile(slave.profile());
  EXPECT_EQ(smLength(2), 13) << "SM2 expects the default RxPDO again";
  EXPECT_TRUE(slavesim::processDataDeviceOf(slave)->bindStatus().ok());
}

// Values set before the firmware first ran (a topology <Input>) are power-up values; a script
// is the world outside the terminal and keeps driving it.
TEST(PowerCycle, InputTerminalKeepsTopologyValuesAndScripts) {
  topology::Segment seg;
  seg.addSlave(makeExampleSlave(kEcs1008));
  slavesim::Slave& slave = seg.slave(0);
  auto* od = slavesim::objectDictionaryOf(slave);
  const std::uint8_t on[] = {1};
  ASSERT_TRUE(od->setBytes(0x6000, 3, on).ok());  // as network_builder sets an <Input>
  auto* di = dev::digitalInputsOf(slave);
  ASSERT_NE(di, nullptr);
  di->setScript(5, dev::Signal::constant(1.0));
  seg.pollSlaves(kNsPerMs);
  ASSERT_EQ(*od->get<std::uint8_t>(0x6000, 5), 1u);
  ASSERT_TRUE(od->setBytes(0x6000, 2, on).ok());  // written after power-up: forgotten
  powerCycle(slave);
  di = dev::digitalInputsOf(slave);
  ASSERT_NE(di, nullptr);
  EXPECT_TRUE(di->script(5).has_value());
  seg.pollSlaves(2 * kNsPerMs);
  EXPECT_EQ(*od->get<std::uint8_t>(0x6000, 3), 1u);
  EXPECT_EQ(*od->get<std::uint8_t>(0x6000, 2), 0u);
  EXPECT_EQ(*od->get<std::uint8_t>(0x6000, 5), 1u);
}

}  // namespace
}  // namespace ecsim::testing
