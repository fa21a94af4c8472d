// The drive and the IO terminals under DC SYNC0 (Application::syncActive() and sync(), called
// directly as the ESC's sync unit would), and the drive's faults: 0x603F, the error register
// and the CoE emergency for an injected fault, a following error, an encoder fault and the
// fault reset; the emergency reaching a master through the slave's CoE server.
#include <gtest/gtest.h>

#include <vector>

#include "slavesim/devices/device_models.hpp"
#include "slavesim/devices/io_terminals.hpp"
#include "tests/slavesim/drive_test_support.hpp"

namespace ecsim::testing {
namespace {

// ---- SYNC0 ------------------------------------------------------------------------------------

template <typename T>
std::vector<std::uint8_t> littleEndian(T v) {
  std::vector<std::uint8_t> out(sizeof(T));
  for (std::size_t i = 0; i < sizeof(T); ++i) out[i] = static_cast<std::uint8_t>(v >> (8 * i));
  return out;
}

TEST(DriveSync, WithSync0TheDriveRunsOnThePulsesOnly) {
  DriveBench b;
  b.tick();  // started, in Switch on disabled
  ASSERT_EQ(b.state(), State::kSwitchOnDisabled);
  b.drive->setSyncActive(true);
  b.controlword(0x0006);
  b.run(5 * kNsPerMs);  // firmware steps: no SYNC0 pulse, nothing taken
  EXPECT_EQ(b.state(), State::kSwitchOnDisabled) << "step() leaves a synchronised drive alone";
  b.drive->sync(*b.od, 1, b.al, b.now);  // SYNC1 is not the drive's cycle
  EXPECT_EQ(b.state(), State::kSwitchOnDisabled);
  b.drive->sync(*b.od, 0, b.al, b.now);
  EXPECT_EQ(b.state(), State::kReadyToSwitchOn) << "the SYNC0 pulse takes the controlword";
  // Without SYNC0 a pulse is ignored and step() runs the drive again.
  b.drive->setSyncActive(false);
  b.controlword(0x000F);
  b.drive->sync(*b.od, 0, b.al, b.now + kNsPerMs);
  EXPECT_EQ(b.state(), State::kReadyToSwitchOn);
  b.tick();
  EXPECT_EQ(b.state(), State::kOperationEnabled);
}

// Enabled in CSV, commanded one turn per second.
void turnInCsv(DriveBench& b) {
  b.tick();
  b.enable();
  b.mode(9);
  b.set<std::int32_t>(c402::obj::kTargetVelocity, 0, 131072);
}

TEST(DriveSync, InputsAreLatchedAtTheSync0PulseAndTheModelAdvancesToIt) {
  DriveBench b(benchParams());
  turnInCsv(b);
  b.tick();
  b.drive->setSyncActive(true);
  SimTime pulse = b.now;
  for (int k = 0; k < 300; ++k) {  // 300 pulses of 1 ms, with firmware steps in between
    pulse += kNsPerMs;
    b.drive->step(*b.od, b.al, pulse - 400'000);
    b.drive->sync(*b.od, 0, b.al, pulse);
    b.drive->step(*b.od, b.al, pulse + 300'000);
  }
  const std::int32_t latched = b.position();
  // Steps alone do not move the published position: it is the one latched at the last pulse.
  b.drive->step(*b.od, b.al, pulse + 900'000);
  EXPECT_EQ(b.position(), latched);
  // The model ran up to the pulse: at 1 rev/s the position is within a count or so of the
  // speed times the time, and the velocity is there.
  EXPECT_NEAR(b.velocity(), 131072, 1500);
  const std::int32_t before = latched;
  b.drive->sync(*b.od, 0, b.al, pulse + kNsPerMs);
  EXPECT_NEAR(b.position() - before, 131.072, 15.0) << "one pulse period of motion";
}

// Between the activation of SYNC0 and its first pulse (0x0990, 100 ms ahead for our master) the
// drive takes nothing, but its motor keeps turning under the commands it has: a motor does not
// wait for a pulse. Before, the model stood still for those 100 ms and integrated them all at
// the first pulse (1,600 substeps per drive in one firmware poll).
TEST(DriveSync, BeforeTheFirstPulseTheMotorMovesOnAndNothingIsTaken) {
  DriveBench b(benchParams());
  turnInCsv(b);
  b.run(200 * kNsPerMs);  // up to speed
  b.drive->setSyncActive(true);
  b.set<std::int32_t>(c402::obj::kTargetVelocity, 0, 0);  // not taken before a pulse
  const double angle = b.drive->axis().motor().angle();
  const std::int32_t published = b.position();
  b.run(100 * kNsPerMs);  // firmware steps, no pulse
  const double turned = (b.drive->axis().motor().angle() - angle) / (2.0 * 3.14159265358979);
  EXPECT_NEAR(turned, 0.1, 0.01) << "the motor kept its speed for 100 ms";
  EXPECT_EQ(b.position(), published) << "nothing published before the first pulse";
  b.drive->sync(*b.od, 0, b.al, b.now);
  EXPECT_NEAR(b.position() - published, 13107, 200) << "the pulse publishes where it is";
}

// Through the ESC: the master activates the cyclic unit (0x0990 start, 0x09A0 cycle, 0x0981)
// and from then on the drive takes its outputs only at the SYNC0 pulses the ESC generates.
TEST(DriveSync, TheEscsSync0PulsesRunTheDrive) {
  topology::Segment seg;
  seg.addSlave(makeExampleSlave(kEcs7201));
  auto op = bringToOp(seg, {{2, true, 13}, {3, false, 15}});
  dev::Cia402Drive* drive = dev::driveOf(seg.slave(0));
  ASSERT_NE(drive, nullptr);
  auto write = [&](std::uint16_t ado, std::vector<std::uint8_t> data, SimTime t) {
    one(seg, Command::kFpwr, phys(kStation, ado), std::move(data), t);
  };
  write(0x0990, littleEndian<std::uint64_t>(10 * kNsPerMs),
        kNsPerMs);  // first pulse at system time 10 ms
  write(0x09A0, littleEndian<std::uint32_t>(kNsPerMs), kNsPerMs);
  write(0x0981, {0x03}, kNsPerMs);  // cyclic unit and SYNC0 on
  ASSERT_TRUE(seg.slave(0).esc().syncActive(0));
  seg.pollSlaves(9 * kNsPerMs);
  EXPECT_EQ(seg.slave(0).syncPulses(), 0u);
  seg.pollSlaves(10 * kNsPerMs);  // the first pulse
  EXPECT_EQ(seg.slave(0).syncPulses(), 1u);
  EXPECT_EQ(drive->state(), State::kSwitchOnDisabled);
  // Shutdown arrives at 10.4 ms: firmware steps at 10.5 and 10.9 ms do not take it ...
  std::vector<std::uint8_t> image(13 + 15, 0);
  writeLe16(image, 0, 0x0006);
  EXPECT_EQ(one(seg, Command::kLrw, 0, image, 10'400'000).wkc, 3);
  const auto pulsesBefore = seg.slave(0).syncPulses();
  seg.pollSlaves(10'500'000);
  seg.pollSlaves(10'900'000);
  EXPECT_EQ(drive->state(), State::kSwitchOnDisabled);
  // ... the SYNC0 pulse at 11 ms does.
  seg.pollSlaves(11'000'000);
  EXPECT_EQ(drive->state(), State::kReadyToSwitchOn);
  EXPECT_EQ(seg.slave(0).syncPulses() - pulsesBefore, 1u);
  // The inputs in SM3 are those latched at the pulse: the statusword of Ready to switch on.
  auto in = one(seg, Command::kLrw, 0, image, 11'200'000);
  EXPECT_EQ(readLe16(in.data, 13) & 0x6F, 0x21) << std::hex << readLe16(in.data, 13);
  (void)op;
}

TEST(IoSync, DigitalInputsLatchAndOutputsApplyAtSync0) {
  auto slave = makeExampleSlave(0x00001008);
  auto* di = dev::digitalInputsOf(*slave);
  ASSERT_NE(di, nullptr);
  auto& od = *slavesim::objectDictionaryOf(*slave);
  di->setScript(1, dev::Signal::square(0.002, 0, 1));  // on for 1 ms, off for 1 ms
  di->setSyncActive(true);
  di->step(od, AlState::kOp, 500'000);
  EXPECT_FALSE(di->input(1)) << "not latched by a firmware step";
  di->sync(od, 0, AlState::kOp, 500'000);
  EXPECT_TRUE(di->input(1));
  di->step(od, AlState::kOp, 1'500'000);
  EXPECT_TRUE(di->input(1)) << "held until the next pulse";
  di->sync(od, 0, AlState::kOp, 1'500'000);
  EXPECT_FALSE(di->input(1));

  auto out = makeExampleSlave(0x00002008);
  auto* dout = dev::digitalOutputsOf(*out);
  ASSERT_NE(dout, nullptr);
  auto& odOut = *slavesim::objectDictionaryOf(*out);
  dout->setSyncActive(true);
  ASSERT_TRUE(odOut.set<std::uint8_t>(0x7000, 3, 1).ok());
  dout->step(odOut, AlState::kOp, 100);
  EXPECT_FALSE(dout->output(3)) << "outputs change at the pulse";
  dout->sync(odOut, 0, AlState::kOp, 200);
  EXPECT_TRUE(dout->output(3));
  dout->step(odOut, AlState::kSafeOp, 300);
  EXPECT_FALSE(dout->output(3)) << "leaving OP makes the outputs safe at once";
}

// ---- faults and emergencies -----------------------------------------------------------------

TEST(DriveFaults, ErrorRegisterByCodeGroup) {
  EXPECT_EQ(c402::errorRegisterFor(0x0000), 0x00);
  EXPECT_EQ(c402::errorRegisterFor(0x2310), 0x03);  // current
  EXPECT_EQ(c402::errorRegisterFor(0x3210), 0x05);  // voltage
  EXPECT_EQ(c402::errorRegisterFor(0x4310), 0x09);  // temperature
  EXPECT_EQ(c402::errorRegisterFor(0x8100), 0x11);  // communication
  EXPECT_EQ(c402::errorRegisterFor(0x8611), 0x21);  // device profile
  EXPECT_EQ(c402::errorRegisterFor(0x7305), 0x21);
  EXPECT_EQ(c402::errorRegisterFor(0x5000), 0x01);  // generic only
}

struct Captured {
  std::vector<Emergency> list;
  dev::EmergencySink sink() {
    return [this](const Emergency& e) { list.push_back(e); };
  }
};

TEST(DriveFaults, InjectedOvercurrentSetsErrorCodeRegisterAndSendsAnEmergency) {
  DriveBench b;
  Captured got;
  b.drive->setEmergencySink(got.sink());
  b.tick();
  b.enable();
  b.drive->injectFault(c402::kErrorOvercurrent);
  b.run(600 * kNsPerMs);  // fault reaction (at most 500 ms), then Fault
  EXPECT_EQ(b.state(), State::kFault);
  EXPECT_EQ(b.errorCode(), 0x2310);
  ASSERT_EQ(got.list.size(), 1u);
  EXPECT_EQ(got.list[0].errorCode, 0x2310);
  EXPECT_EQ(got.list[0].errorRegister, 0x03);
  EXPECT_EQ(got.list[0].data, (std::array<std::uint8_t, 5>{}));
  // Fault reset (rising edge of bit 7): Switch on disabled, 0x603F cleared, "error reset".
  b.controlword(0x0080);
  b.tick();
  EXPECT_EQ(b.state(), State::kSwitchOnDisabled);
  EXPECT_EQ(b.errorCode(), 0);
  ASSERT_EQ(got.list.size(), 2u);
  EXPECT_EQ(got.list[1].errorCode, 0x0000);
  EXPECT_EQ(got.list[1].errorRegister, 0);
}

TEST(DriveFaults, FollowingErrorBeyondTheWindowIs8611WithAnEmergency) {
  dev::DriveParams p = benchParams();
  p.followingErrorWindow = 100;  // counts
  p.followingErrorTimeoutMs = 2;
  DriveBench b(p);
  Captured got;
  b.drive->setEmergencySink(got.sink());
  EXPECT_EQ(b.get<std::uint32_t>(c402::obj::kFollowingErrorWindow), 100u) << "from DriveParams";
  b.tick();
  b.enable();
  b.mode(8);  // CSP: a jump of a quarter turn is far beyond 100 counts
  b.tick();
  b.set<std::int32_t>(c402::obj::kTargetPosition, 0, b.position() + 32768);
  b.run(20 * kNsPerMs);
  EXPECT_NE(b.statusword() & c402::sw::kFault, 0) << std::hex << b.statusword();
  EXPECT_EQ(b.errorCode(), 0x8611);
  ASSERT_FALSE(got.list.empty());
  EXPECT_EQ(got.list[0].errorCode, 0x8611);
  EXPECT_EQ(got.list[0].errorRegister, 0x21) << "generic + device profile";
}

TEST(DriveFaults, EncoderFaultFreezesThePositionAndFaultsUntilCleared) {
  DriveBench b;
  Captured got;
  b.drive->setEmergencySink(got.sink());
  b.tick();
  b.enable();
  b.mode(9);
  b.set<std::int32_t>(c402::obj::kTargetVelocity, 0, 131072);
  b.run(100 * kNsPerMs);
  b.drive->setEncoderFault(true);
  const std::int32_t frozen = b.position();
  b.run(600 * kNsPerMs);
  EXPECT_EQ(b.state(), State::kFault);
  EXPECT_EQ(b.errorCode(), 0x7305);
  EXPECT_EQ(b.position(), frozen);
  ASSERT_FALSE(got.list.empty());
  EXPECT_EQ(got.list[0].errorCode, 0x7305);
  // A reset while the encoder is still faulty faults again at the next substep.
  b.controlword(0x0080);
  b.tick();
  b.tick();
  EXPECT_EQ(b.state(), State::kFault);
  EXPECT_EQ(b.errorCode(), 0x7305);
  b.drive->setEncoderFault(false);
  b.controlword(0x0000);
  b.tick();
  b.controlword(0x0080);
  b.tick();
  EXPECT_EQ(b.state(), State::kSwitchOnDisabled);
  EXPECT_NE(b.position(), frozen) << "the encoder reads the shaft again";
}

TEST(DriveFaults, EmergencyReachesTheMasterThroughTheCoeServer) {
  topology::Segment seg;
  seg.addSlave(makeExampleSlave(kEcs7201));
  auto op = bringToOp(seg, {{2, true, 13}, {3, false, 15}});
  ASSERT_TRUE(op.mailbox);
  dev::Cia402Drive* drive = dev::driveOf(seg.slave(0));
  ASSERT_NE(drive, nullptr);
  drive->injectFault(c402::kErrorFollowing);
  seg.pollSlaves(kNsPerMs);
  auto* server = slavesim::coeServerOf(seg.slave(0));
  ASSERT_NE(server, nullptr);
  EXPECT_EQ(server->counters().emergenciesSent, 1u);
  auto message = op.mailbox->receive();
  ASSERT_TRUE(message.has_value());
  auto e = decodeEmergencyMailbox(*message);
  ASSERT_TRUE(e.ok()) << e.error().message();
  EXPECT_EQ(e->errorCode, 0x8611);
  EXPECT_EQ(e->errorRegister, 0x21);
}

}  // namespace
}  // namespace ecsim::testing
