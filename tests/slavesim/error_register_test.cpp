// The CiA 301 error register 0x1001 (slavesim/devices/error_register.hpp) in the CoE devices of
// examples/esi: declared once per device as real ESI files declare it (the SOES-based
// ../shared/esi/STMBL_ECAT.xml writes USINT, BitSize 8, DefaultValue 0, ro), read by SDO upload
// through frames: 0 at power-up, the fault's bits while a fault is present, 0 again when it is
// reset or gone, and 0 after a power cycle. The SSI encoder terminal sets it too when its
// dictionary has the object (the ECS5001 has no mailbox and the real EJ5002 no 0x1001, so the
// tests add the object).
#include <gtest/gtest.h>

#include <filesystem>
#include <set>

#include "slavesim/devices/device_models.hpp"
#include "slavesim/devices/error_register.hpp"
#include "tests/slavesim/drive_test_support.hpp"
#include "tests/support/test_network.hpp"

namespace ecsim::testing {
namespace {

namespace er = dev::error_register;
constexpr std::uint16_t kErrorRegister = 0x1001;
constexpr std::uint32_t kEcs3102 = 0x00003102;
constexpr std::uint32_t kEcs5001 = 0x00005001;

void powerCycle(slavesim::Slave& slave) {
  slave.powerOff();
  slave.powerOn(0);
  EXPECT_TRUE(slave.coldStartStatus().ok()) << slave.coldStartStatus().error().message();
}

std::uint8_t errorRegisterOf(slavesim::Slave& slave) {
  auto v = slavesim::objectDictionaryOf(slave)->get<std::uint8_t>(kErrorRegister, 0);
  EXPECT_TRUE(v.ok()) << "0x1001 in the dictionary";
  return v.ok() ? *v : 0xFF;
}

// The error-register byte of each emergency the mailbox master skipped while waiting for SDO
// answers (byte 3 of the CoE body, after the 6-byte mailbox and 2-byte CoE headers).
std::vector<std::uint8_t> emergencyRegisters(const MailboxMaster& m) {
  std::vector<std::uint8_t> out;
  for (const auto& e : m.emergencies) {
    auto decoded = decodeEmergencyMailbox(e);
    EXPECT_TRUE(decoded.ok());
    if (decoded.ok()) out.push_back(decoded->errorRegister);
  }
  return out;
}

std::filesystem::path examplesDir() {
  return std::filesystem::path(ECSIM_SOURCE_DIR) / "examples" / "esi";
}

// ---- the ESI files ------------------------------------------------------------------------------

TEST(ErrorRegisterEsi, EveryCoeDeviceOfTheExamplesDeclaresItOnce) {
  unsigned coeDevices = 0;
  for (const auto& entry : std::filesystem::directory_iterator(examplesDir())) {
    if (entry.path().extension() != ".xml") continue;
    auto file = loadEsiFile(entry.path());
    ASSERT_TRUE(file.ok()) << entry.path() << ": " << file.error().message();
    for (const EsiDevice& d : file->devices) {
      if (!d.mailbox.coe) {
        EXPECT_EQ(d.dictionary.findObject(kErrorRegister), nullptr) << d.type << ": no CoE";
        continue;
      }
      ++coeDevices;
      unsigned count = 0, usint = 0;
      for (const auto& o : d.dictionary.objects) count += o.index == kErrorRegister ? 1 : 0;
      for (const auto& t : d.dictionary.dataTypes) usint += t.name == "USINT" ? 1 : 0;
      EXPECT_EQ(count, 1u) << d.type;
      EXPECT_EQ(usint, 1u) << d.type << ": its data type declared once";
      const EsiObject* o = d.dictionary.findObject(kErrorRegister);
      ASSERT_NE(o, nullptr) << d.type;
      EXPECT_EQ(o->name(), "Error register") << d.type;
      EXPECT_EQ(o->type, "USINT") << d.type;
      EXPECT_EQ(o->bitSize, 8u) << d.type;
      EXPECT_EQ(o->info.defaultValue.value_or("?"), "0") << d.type;
      EXPECT_EQ(o->flags.access, EsiAccess::kReadOnly) << d.type;
      EXPECT_EQ(o->flags.pdoMapping, "T") << d.type;
    }
  }
  EXPECT_EQ(coeDevices, 4u) << "ECS3102, ECS7201, ECS7211, ECS6010";
}

// ---- drives: through frames ---------------------------------------------------------------------

// ECS7201: 0 at power-up; an injected over current (0x2310) sets generic + current (0x03) and
// sends it in the emergency; the fault reset (controlword bit 7 by process data) clears it; a
// power cycle in Fault comes back with 0.
TEST(ErrorRegister, Ecs7201ShowsTheFaultUntilResetAndIsZeroAfterAPowerCycle) {
  topology::Segment seg;
  seg.addSlave(makeExampleSlave(kEcs7201));
  slavesim::Slave& slave = seg.slave(0);
  SimTime now = kNsPerMs;
  seg.pollSlaves(now);
  std::uint8_t atStart = 0xFF;
  OpSlave op = bringToOp(seg, {{2, true, 13}, {3, false, 15}}, now, [&](MailboxMaster& m) {
    atStart = m.uploadValue<std::uint8_t>(kErrorRegister, 0);
  });
  ASSERT_TRUE(op.mailbox);
  EXPECT_EQ(atStart, 0);
  CyclicExchange x{seg, op.outBytes, op.inBytes, now};
  x.cycle();

  dev::driveOf(slave)->injectFault(c402::kErrorOvercurrent);
  for (int i = 0; i < 5; ++i) x.cycle();
  EXPECT_EQ(op.mailbox->uploadValue<std::uint8_t>(kErrorRegister, 0), er::kGeneric | er::kCurrent);
  EXPECT_EQ(op.mailbox->uploadValue<std::uint16_t>(c402::obj::kErrorCode, 0), 0x2310u);
  EXPECT_EQ(emergencyRegisters(*op.mailbox), (std::vector<std::uint8_t>{0x03}))
      << "the emergency carries the same byte";

  x.put16(0, 0x0080);  // fault reset: rising edge of bit 7
  for (int i = 0; i < 3; ++i) x.cycle();
  EXPECT_EQ(op.mailbox->uploadValue<std::uint8_t>(kErrorRegister, 0), 0);
  EXPECT_EQ(op.mailbox->uploadValue<std::uint16_t>(c402::obj::kErrorCode, 0), 0u);
  EXPECT_EQ(emergencyRegisters(*op.mailbox), (std::vector<std::uint8_t>{0x03, 0x00}))
      << "then the error reset emergency with 0";

  dev::driveOf(slave)->injectFault(c402::kErrorFollowing);
  for (int i = 0; i < 3; ++i) x.cycle();
  ASSERT_EQ(errorRegisterOf(slave), er::kGeneric | er::kDeviceProfile);
  powerCycle(slave);
  EXPECT_EQ(errorRegisterOf(slave), 0) << "the power-up value, before the firmware runs";
  std::uint8_t afterPowerCycle = 0xFF;
  bringToOp(seg, {{2, true, 13}, {3, false, 15}}, x.now + kNsPerMs, [&](MailboxMaster& m) {
    afterPowerCycle = m.uploadValue<std::uint8_t>(kErrorRegister, 0);
  });
  EXPECT_EQ(afterPowerCycle, 0);
}

// ECS7211: the robot drive's fault goes through the same path; its Clear output (0x7000:02,
// byte 14 of the default SM2 image) resets it.
TEST(ErrorRegister, Ecs7211ClearResetsIt) {
  topology::Segment seg;
  seg.addSlave(makeExampleSlave(kEcs7211));
  slavesim::Slave& slave = seg.slave(0);
  SimTime now = kNsPerMs;
  seg.pollSlaves(now);
  OpSlave op = bringToOp(seg, {{2, true, 17}, {3, false, 19}}, now);
  ASSERT_TRUE(op.mailbox);
  CyclicExchange x{seg, op.outBytes, op.inBytes, now};
  x.cycle();
  EXPECT_EQ(op.mailbox->uploadValue<std::uint8_t>(kErrorRegister, 0), 0);
  dev::robotDriveOf(slave)->injectFault(0x4310);  // over temperature
  for (int i = 0; i < 3; ++i) x.cycle();
  EXPECT_EQ(op.mailbox->uploadValue<std::uint8_t>(kErrorRegister, 0),
            er::kGeneric | er::kTemperature);
  x.put8(14, 1);  // Clear
  for (int i = 0; i < 3; ++i) x.cycle();
  EXPECT_EQ(op.mailbox->uploadValue<std::uint8_t>(kErrorRegister, 0), 0);
}

// ---- analog input terminal ----------------------------------------------------------------------

// ECS3102: channel 2 beyond +10 V is overrange (status bit 1, error bit 6): generic + voltage
// while it lasts. A power cycle gives 0 at power-up; the input is still too high (the signal
// is outside the terminal), so the first conversion sets the bits again.
TEST(ErrorRegister, Ecs3102OverrangeSetsGenericAndVoltageWhileItLasts) {
  topology::Segment seg;
  seg.addSlave(makeExampleSlave(kEcs3102));
  slavesim::Slave& slave = seg.slave(0);
  auto* ai = dev::analogInputsOf(slave);
  ASSERT_NE(ai, nullptr);
  ai->setScript(2, dev::Signal::constant(4.0));
  SimTime now = kNsPerMs;
  seg.pollSlaves(now);
  OpSlave op = bringToOp(seg, {{3, false, 8}}, now);
  ASSERT_TRUE(op.mailbox);
  CyclicExchange x{seg, op.outBytes, op.inBytes, now};
  x.cycle();
  EXPECT_EQ(op.mailbox->uploadValue<std::uint8_t>(kErrorRegister, 0), 0);

  ai->setScript(2, dev::Signal::constant(12.5));
  for (int i = 0; i < 3; ++i) x.cycle();
  EXPECT_EQ(x.in16(4) & 0x0042, 0x0042) << "channel 2 status: overrange + error";
  EXPECT_EQ(op.mailbox->uploadValue<std::uint8_t>(kErrorRegister, 0), er::kGeneric | er::kVoltage);

  ai->setScript(2, dev::Signal::constant(-3.0));
  for (int i = 0; i < 3; ++i) x.cycle();
  EXPECT_EQ(x.in16(4) & 0x0043, 0);
  EXPECT_EQ(op.mailbox->uploadValue<std::uint8_t>(kErrorRegister, 0), 0);

  ai->setScript(1, dev::Signal::constant(-11.0));  // underrange on channel 1
  for (int i = 0; i < 3; ++i) x.cycle();
  EXPECT_EQ(op.mailbox->uploadValue<std::uint8_t>(kErrorRegister, 0), er::kGeneric | er::kVoltage);
  powerCycle(slave);
  EXPECT_EQ(errorRegisterOf(slave), 0) << "the power-up value";
  seg.pollSlaves(x.now + kNsPerMs);
  EXPECT_EQ(errorRegisterOf(slave), er::kGeneric | er::kVoltage)
      << "the input is still below -10 V after the restart";
}

// ---- SSI encoder terminal -----------------------------------------------------------------------

// The ECS5001 as shipped is SII-only (no mailbox): no 0x1001. Given one (as a CoE variant of it
// would declare it), the terminal keeps it: generic for a data or frame error, voltage too for
// a failed encoder supply, 0 when cleared; through a power cycle the fault (outside the
// terminal) stays and shows again after the power-up value 0.
TEST(ErrorRegister, EncoderTerminalSetsItWhenItsDictionaryHasIt) {
  auto file = loadEsiFile(examplesDir() / "ecsim_encoders.xml");
  ASSERT_TRUE(file.ok()) << file.error().message();
  ASSERT_EQ(file->devices.size(), 1u);
  EsiDevice device = file->devices[0];
  ASSERT_EQ(device.productCode, kEcs5001);
  ASSERT_FALSE(device.mailbox.coe);
  ASSERT_EQ(device.dictionary.findObject(kErrorRegister), nullptr);
  {
    auto plain = slavesim::makeSlaveFromEsi(*file, device, "Encoder1");
    ASSERT_TRUE(plain.ok()) << plain.error().message();
    EXPECT_EQ(slavesim::objectDictionaryOf(**plain)->findEntry(kErrorRegister, 0), nullptr);
  }
  EsiObject reg;
  reg.index = kErrorRegister;
  reg.names.push_back({1033, "Error register"});
  reg.type = "USINT";
  reg.bitSize = 8;
  reg.info.defaultValue = "0";
  reg.flags.access = EsiAccess::kReadOnly;
  device.dictionary.objects.push_back(reg);
  auto made = slavesim::makeSlaveFromEsi(*file, device, "Encoder1");
  ASSERT_TRUE(made.ok()) << made.error().message();
  topology::Segment seg;
  seg.addSlave(std::move(made).value());
  slavesim::Slave& slave = seg.slave(0);
  SimTime now = 0;
  auto poll = [&] {
    now += kNsPerMs;
    seg.pollSlaves(now);
  };
  poll();
  EXPECT_EQ(errorRegisterOf(slave), 0);
  struct Case {
    std::uint8_t faults;
    std::uint8_t reg;
  };
  for (const Case c : {Case{dev::encoder_fault::kData, er::kGeneric},
                       Case{dev::encoder_fault::kFrame, er::kGeneric},
                       Case{dev::encoder_fault::kPower, er::kGeneric | er::kVoltage},
                       Case{dev::encoder_fault::kNone, 0}}) {
    dev::encoderTerminalOf(slave)->setFault(1, c.faults);
    poll();
    EXPECT_EQ(errorRegisterOf(slave), c.reg) << "faults " << int(c.faults);
    EXPECT_EQ(dev::encoderTerminalOf(slave)->errorRegister(), c.reg);
  }
  dev::encoderTerminalOf(slave)->setFault(1, dev::encoder_fault::kPower);
  poll();
  powerCycle(slave);
  EXPECT_EQ(errorRegisterOf(slave), 0) << "the power-up value";
  poll();
  EXPECT_EQ(errorRegisterOf(slave), er::kGeneric | er::kVoltage) << "the supply is still off";
  dev::encoderTerminalOf(slave)->setFault(1, dev::encoder_fault::kNone);
  poll();
  EXPECT_EQ(errorRegisterOf(slave), 0);
}

// The real EJ5002 (../shared/esi/Beckhoff_EJ5xxx.xml, revision 0x00110000) is a CoE device
// whose dictionary has no 0x1001, like Beckhoff's other terminals: an upload is aborted with
// "object does not exist". With the object added (as the AX2000's ESI in the same corpus
// declares it: USINT, DefaultData 00) a master reads the encoder faults there by SDO.
TEST(ErrorRegister, RealEj5002HasNoneAndWithOneAddedShowsItsChannelsFaults) {
  const auto path = sharedDir() / "esi" / "Beckhoff_EJ5xxx.xml";
  ECSIM_REQUIRE_SHARED(path);
  auto file = loadEsiFile(path);
  ASSERT_TRUE(file.ok()) << file.error().message();
  const EsiDevice* found = nullptr;
  for (const auto& d : file->devices) {
    if (d.productCode == 0x138A2852 && d.revision == 0x00110000) found = &d;
  }
  ASSERT_NE(found, nullptr) << "EJ5002 revision 0x00110000";
  ASSERT_TRUE(found->mailbox.coe);
  EXPECT_EQ(found->dictionary.findObject(kErrorRegister), nullptr);
  for (const bool added : {false, true}) {
    EsiDevice device = *found;
    if (added) {
      EsiObject reg;
      reg.index = kErrorRegister;
      reg.names.push_back({1033, "Error Register"});
      reg.type = "USINT";
      reg.bitSize = 8;
      reg.info.defaultData = {0x00};
      reg.flags.access = EsiAccess::kReadOnly;
      device.dictionary.objects.push_back(reg);
    }
    auto made = slavesim::makeSlaveFromEsi(*file, device, "EJ5002");
    ASSERT_TRUE(made.ok()) << made.error().message();
    topology::Segment seg;
    seg.addSlave(std::move(made).value());
    slavesim::Slave& slave = seg.slave(0);
    SimTime now = kNsPerMs;
    seg.pollSlaves(now);
    one(seg, Command::kApwr, phys(0, reg::kConfiguredStationAddress.address), le16(kStation));
    const auto& mbx = *slave.profile().mailbox;
    MailboxMaster m(seg, kStation, mbx.outStart, mbx.outSize, mbx.inStart, mbx.inSize);
    m.configureSyncManagers();
    requestState(seg, kStation, 0x0002);
    ASSERT_EQ(alStatus(seg, kStation), 0x0002);
    if (!added) {
      EXPECT_EQ(m.upload(kErrorRegister, 0).abort, 0x06020000u) << "object does not exist";
      continue;
    }
    EXPECT_EQ(m.uploadValue<std::uint8_t>(kErrorRegister, 0), 0);
    dev::encoderTerminalOf(slave)->setFault(2, dev::encoder_fault::kPower);
    seg.pollSlaves(now += kNsPerMs);
    EXPECT_EQ(m.uploadValue<std::uint8_t>(kErrorRegister, 0), er::kGeneric | er::kVoltage)
        << "channel 2's supply";
    dev::encoderTerminalOf(slave)->setFault(2, dev::encoder_fault::kNone);
    seg.pollSlaves(now += kNsPerMs);
    EXPECT_EQ(m.uploadValue<std::uint8_t>(kErrorRegister, 0), 0);
  }
}

}  // namespace
}  // namespace ecsim::testing
