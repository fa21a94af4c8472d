// Device models configured from a topology file: <Param> names reach the drive's motor, loops,
// encoder and dictionary defaults (unknown names and bad values are errors naming file and
// line), and stateFile= keeps a drive's multi-turn absolute position across a power cycle and
// across a process restart of a network built from the file.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <numbers>

#include "config/topology_file.hpp"
#include "slavesim/devices/device_models.hpp"
#include "slavesim/devices/device_params.hpp"
#include "slavesim/devices/io_terminals.hpp"
#include "tests/slavesim/drive_test_support.hpp"
#include "tests/slavesim/one_slave_topology.hpp"
#include "topology/network_builder.hpp"

namespace ecsim::testing {
namespace {

constexpr double kTurn = 2.0 * std::numbers::pi;

class DriveTopology : public OneSlaveTopology {
 protected:
  // A topology with one slave of the examples ESI and `body` inside its <Slave> element.
  std::filesystem::path write(const std::string& attributes, const std::string& body,
                              std::uint32_t product = kEcs7211) {
    return writeTopology(attributes, body, product);
  }
};

TEST_F(DriveTopology, ParamsReachTheDriveModel) {
  auto net = build(write("",
                         "    <Param name=\"gains.velocityKp\" value=\"0.5\"/>\n"
                         "    <Param name=\"motor.inertia\" value=\"2.5e-5\"/>\n"
                         "    <Param name=\"motor.coulombFriction\" value=\"0\"/>\n"
                         "    <Param name=\"encoder.resolution\" value=\"8192\"/>\n"
                         "    <Param name=\"encoder.noise\" value=\"0.5\"/>\n"
                         "    <Param name=\"drive.followingErrorWindow\" value=\"777\"/>\n"
                         "    <Param name=\"drive.torqueLimit\" value=\"1500\"/>\n"));
  ASSERT_TRUE(net.ok()) << net.error().message();
  dev::Cia402Drive* drive = dev::driveOf(net->segment->slave(0));
  ASSERT_NE(drive, nullptr);
  EXPECT_DOUBLE_EQ(drive->params().motor.inertia, 2.5e-5);
  EXPECT_DOUBLE_EQ(drive->params().motor.coulombFriction, 0.0);
  EXPECT_EQ(drive->encoder().params().countsPerRevolution, 8192u);
  EXPECT_DOUBLE_EQ(drive->encoder().params().noiseCounts, 0.5);
  // Gains: tuned for the inertia given after them, with the one override.
  const dev::ServoGains tuned = dev::ServoGains::tuned(drive->params().motor);
  EXPECT_DOUBLE_EQ(drive->axis().gains().velocityKp, 0.5);
  EXPECT_DOUBLE_EQ(drive->axis().gains().positionKp, tuned.positionKp);
  auto* od = slavesim::objectDictionaryOf(net->segment->slave(0));
  ASSERT_NE(od, nullptr);
  EXPECT_EQ(*od->get<std::uint32_t>(0x2011, 0), 8192u) << "0x2011 says the resolution";
  EXPECT_EQ(*od->get<std::uint32_t>(c402::obj::kFollowingErrorWindow, 0), 777u);
  EXPECT_EQ(*od->get<std::uint16_t>(c402::obj::kMaxTorque, 0), 1500u);
}

TEST_F(DriveTopology, UnknownParamIsAnErrorNamingFileAndLine) {
  const auto path = write("",
                          "    <Param name=\"motor.inertia\" value=\"1e-4\"/>\n"
                          "    <Param name=\"motor.inertai\" value=\"1e-4\"/>\n");
  auto net = build(path);
  ASSERT_FALSE(net.ok());
  const std::string m = net.error().message();
  EXPECT_NE(m.find(path.string()), std::string::npos) << m;
  EXPECT_NE(m.find("line 4"), std::string::npos) << m;
  EXPECT_NE(m.find("motor.inertai"), std::string::npos) << m;
}

TEST_F(DriveTopology, BadValuesAndParamsOnModellessDevicesAreErrors) {
  for (const char* bad : {"<Param name=\"motor.inertia\" value=\"heavy\"/>",
                          "<Param name=\"motor.inertia\" value=\"-1\"/>",
                          "<Param name=\"encoder.kind\" value=\"optical\"/>",
                          "<Param name=\"gains.positionKq\" value=\"1\"/>",
                          "<Param name=\"encoder.multiTurnBits\" value=\"2.5\"/>",
                          "<Param name=\"motor.inertia\"/>"}) {
    auto net = build(write("", std::string("    ") + bad + "\n"));
    ASSERT_FALSE(net.ok()) << bad;
    EXPECT_NE(net.error().message().find("line 3"), std::string::npos)
        << bad << ": " << net.error().message();
  }
  auto coupler =
      build(write("", "    <Param name=\"motor.inertia\" value=\"1e-4\"/>\n", 0x00001100));
  ASSERT_FALSE(coupler.ok());
  EXPECT_NE(coupler.error().message().find("no model"), std::string::npos)
      << coupler.error().message();
}

TEST_F(DriveTopology, SignalParamsScriptTheInputTerminals) {
  std::ofstream(dir_ / "trace.csv") << "time,value\n0,0\n0.010,10\n";
  auto di = build(write("",
                        "    <Param name=\"signal.2\" value=\"square period=0.004\"/>\n"
                        "    <Param name=\"signal.8\" value=\"1\"/>\n",
                        0x00001008));
  ASSERT_TRUE(di.ok()) << di.error().message();
  dev::DigitalInputTerminal* inputs = dev::digitalInputsOf(di->segment->slave(0));
  ASSERT_NE(inputs, nullptr);
  di->segment->pollSlaves(1 * kNsPerMs);
  EXPECT_TRUE(inputs->input(2)) << "first half of the square period";
  EXPECT_TRUE(inputs->input(8));
  EXPECT_FALSE(inputs->input(1)) << "no script";
  di->segment->pollSlaves(3 * kNsPerMs);
  EXPECT_FALSE(inputs->input(2)) << "second half";

  auto ai =
      build(write("", "    <Param name=\"signal.1\" value=\"csv file=trace.csv\"/>\n", 0x00003102));
  ASSERT_TRUE(ai.ok()) << ai.error().message();
  dev::AnalogInputTerminal* analog = dev::analogInputsOf(ai->segment->slave(0));
  ASSERT_NE(analog, nullptr);
  ai->segment->pollSlaves(0);
  ai->segment->pollSlaves(5 * kNsPerMs);
  auto* od = slavesim::objectDictionaryOf(ai->segment->slave(0));
  // 5 V of the CSV ramp (relative to the topology's folder), filtered (10 ms default) below it.
  const auto raw = *od->get<std::int16_t>(0x6000, 0x11);
  EXPECT_GT(raw, 0);
  EXPECT_LE(raw, analog->rawValue(5.0));

  for (const char* bad : {"<Param name=\"signal.x\" value=\"1\"/>",
                          "<Param name=\"signal.1\" value=\"triangle period=1\"/>"}) {
    auto net = build(write("", std::string("    ") + bad + "\n", 0x00001008));
    ASSERT_FALSE(net.ok()) << bad;
    EXPECT_NE(net.error().message().find("line 3"), std::string::npos) << net.error().message();
  }
  auto channel = build(write("", "    <Param name=\"signal.9\" value=\"1\"/>\n", 0x00001008));
  ASSERT_FALSE(channel.ok());
  EXPECT_NE(channel.error().message().find("channels 1..8"), std::string::npos)
      << channel.error().message();
  auto drive = build(write("", "    <Param name=\"signal.1\" value=\"1\"/>\n"));
  ASSERT_FALSE(drive.ok()) << "a drive has no scripted inputs";
}

TEST(DeviceParams, AnalogAndAxisParameters) {
  dev::DeviceModelOptions o;
  ASSERT_TRUE(dev::applyDeviceParams(o, {{"analog.fullScaleVolts", "5", 0},
                                         {"analog.conversionPeriodUs", "250", 0},
                                         {"axis.idealCurrentLoop", "1", 0},
                                         {"encoder.kind", "incremental", 0},
                                         {"drive.initTimeMs", "20", 0}})
                  .ok());
  EXPECT_DOUBLE_EQ(o.analog.fullScaleVolts, 5.0);
  EXPECT_EQ(o.analog.conversionPeriod, 250'000);
  EXPECT_TRUE(o.drive.axis.idealCurrentLoop);
  EXPECT_EQ(o.drive.encoder.kind, dev::EncoderKind::kIncremental);
  EXPECT_EQ(o.drive.initTime, 20 * kNsPerMs);
  EXPECT_FALSE(o.drive.gains.has_value()) << "no gains given: tuned at creation";
}

// The multi-turn position (several turns, negative too) through stateFile= of the topology.
TEST_F(DriveTopology, StateFileKeepsTheAbsolutePositionAcrossPowerCycleAndRestart) {
  const auto path = write("stateFile=\"axis.state\"", "");
  const double angle = -7.3 * kTurn;  // 7.3 turns backwards
  std::int32_t before = 0;
  {
    auto net = build(path);
    ASSERT_TRUE(net.ok()) << net.error().message();
    slavesim::Slave& slave = net->segment->slave(0);
    dev::Cia402Drive* drive = dev::driveOf(slave);
    ASSERT_NE(drive, nullptr);
    EXPECT_EQ(drive->params().stateFile, dir_ / "axis.state");
    drive->axis().motor().setAngle(angle);  // the shaft turned (by hand, or by moves)
    net->segment->pollSlaves(kNsPerMs);     // the model starts
    net->segment->pollSlaves(2 * kNsPerMs);
    before =
        *slavesim::objectDictionaryOf(slave)->get<std::int32_t>(c402::obj::kPositionActualValue, 0);
    EXPECT_NEAR(before, -7.3 * 131072, 2.0);
    // Power cycle: ESC reset, dictionary defaults, the model re-created from the state file.
    slave.esc().powerOnReset();
    auto* pd = slavesim::processDataDeviceOf(slave);
    pd->dictionary().resetToDefaults();
    dev::DeviceModelOptions options;
    options.stateFile = dir_ / "axis.state";
    ASSERT_TRUE(attachDeviceModel(*pd, dev::DeviceModelKind::kRobotDrive, options).ok());
    net->segment->pollSlaves(2 * kNsPerMs);
    EXPECT_EQ(*pd->dictionary().get<std::int32_t>(c402::obj::kPositionActualValue, 0), before);
    EXPECT_EQ(*pd->dictionary().get<std::int32_t>(0x2010, 0), before) << "robot absolute";
  }  // the process "exits"
  ASSERT_TRUE(std::filesystem::exists(dir_ / "axis.state"));
  auto net = build(path);
  ASSERT_TRUE(net.ok()) << net.error().message();
  net->segment->pollSlaves(kNsPerMs);
  auto* od = slavesim::objectDictionaryOf(net->segment->slave(0));
  EXPECT_EQ(*od->get<std::int32_t>(c402::obj::kPositionActualValue, 0), before);
  EXPECT_EQ(*od->get<std::int32_t>(0x2010, 0), before);
}

}  // namespace
}  // namespace ecsim::testing
