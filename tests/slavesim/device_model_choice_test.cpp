// Which model a device gets (issue #17 item 1, CiA 402 part): any device whose ESI says
// ProfileNo 402, or says no profile and has 0x6040/0x6041, gets ecsim's CiA 402 drive; a
// multi-axis device (ETG.6010: axis n at 0x6040 + n * 0x800) one drive per axis; the topology's
// model="cia402|none" overrides the choice, strictly (unknown values are errors naming file,
// line and the closest name).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "config/topology_file.hpp"
#include "slavesim/coe/data_types.hpp"
#include "slavesim/devices/device_models.hpp"
#include "tests/slavesim/drive_test_support.hpp"
#include "tests/slavesim/one_slave_topology.hpp"
#include "topology/network_builder.hpp"

namespace ecsim::testing {
namespace {

namespace dt = slavesim::coe::data_type;
namespace acc = slavesim::coe::access;

constexpr std::uint32_t kVendor = 0x0000ABCD;  // a third party
constexpr std::uint32_t kProduct = 0x1234;

TEST(DeviceModelChoice, ProfileAndObjectsChooseTheDriveForAnyVendor) {
  using dev::DeviceModelKind;
  EXPECT_EQ(dev::deviceModelFor(kVendor, kProduct, 402u), DeviceModelKind::kCia402Drive);
  EXPECT_EQ(dev::deviceModelFor(kVendor, kProduct, std::nullopt, true),
            DeviceModelKind::kCia402Drive);
  EXPECT_EQ(dev::deviceModelFor(kVendor, kProduct, std::nullopt, false), DeviceModelKind::kNone);
  // A modular device profile (5001) may use 0x6040 for a channel of its own (Beckhoff EL7xxx).
  EXPECT_EQ(dev::deviceModelFor(kVendor, kProduct, 5001u, true), DeviceModelKind::kNone);
  EXPECT_EQ(dev::deviceModelByName("cia402"), DeviceModelKind::kCia402Drive);
  EXPECT_EQ(dev::deviceModelByName("none"), DeviceModelKind::kNone);
  EXPECT_FALSE(dev::deviceModelByName("cia-402").has_value());
}

// Adds axis n's mandatory objects (controlword, statusword, modes, position actual value).
void addAxis(slavesim::coe::ObjectDictionary& od, unsigned n) {
  const auto at = [n](std::uint16_t index) {
    return static_cast<std::uint16_t>(index + n * 0x800);
  };
  od.addVar(at(c402::obj::kControlword), "Controlword", dt::kUnsigned16, 16, acc::kReadWrite);
  od.addVar(at(c402::obj::kStatusword), "Statusword", dt::kUnsigned16, 16, acc::kReadOnly);
  od.addVar(at(c402::obj::kModesOfOperation), "Mode", dt::kInteger8, 8, acc::kReadWrite);
  od.addVar(at(c402::obj::kModesOfOperationDisplay), "Mode display", dt::kInteger8, 8,
            acc::kReadOnly);
  od.addVar(at(c402::obj::kPositionActualValue), "Position", dt::kInteger32, 32, acc::kReadOnly);
}

TEST(DeviceModelChoice, EachAxisOfAMultiAxisDeviceGetsItsOwnDrive) {
  auto od = std::make_shared<slavesim::coe::ObjectDictionary>();
  addAxis(*od, 0);
  addAxis(*od, 1);
  EXPECT_EQ(dev::cia402AxisCount(*od), 2u);
  slavesim::ProcessDataDevice device(od);
  ASSERT_TRUE(dev::attachDeviceModel(device, dev::DeviceModelKind::kCia402Drive).ok());
  auto* axes = dynamic_cast<dev::MultiAxisDrive*>(device.application());
  ASSERT_NE(axes, nullptr);
  ASSERT_EQ(axes->axes(), 2u);

  // Shutdown on axis 1 only (0x6840): axis 1 goes to Ready to switch on (statusword 0x6841
  // xxxx xxxx x01x 0001, IEC 61800-7-201 statusword table), axis 0 stays Switch on disabled.
  ASSERT_TRUE(od->set<std::uint16_t>(0x6840, 0, 0x0006).ok());
  for (SimTime t = kNsPerMs; t <= 5 * kNsPerMs; t += kNsPerMs) {
    device.application()->step(*od, AlState::kOp, t);
  }
  EXPECT_EQ(*od->get<std::uint16_t>(0x6841, 0) & 0x6F, 0x21);
  EXPECT_EQ(*od->get<std::uint16_t>(0x6041, 0) & 0x4F, 0x40);
  EXPECT_EQ(axes->axis(1).state(), c402::State::kReadyToSwitchOn);
  EXPECT_EQ(axes->axis(0).state(), c402::State::kSwitchOnDisabled);
}

class ModelAttribute : public OneSlaveTopology {
 protected:
  std::filesystem::path write(const std::string& attributes, const std::string& body = "",
                              std::uint32_t product = kEcs7201) {
    return writeTopology(attributes, body, product);
  }
};

TEST_F(ModelAttribute, AnUnknownModelIsAnErrorWithFileLineAndClosestName) {
  const auto path = write("model=\"cia40\"");
  auto net = build(path);
  ASSERT_FALSE(net.ok());
  const std::string m = net.error().message();
  EXPECT_NE(m.find(path.string()), std::string::npos) << m;
  EXPECT_NE(m.find("line 2"), std::string::npos) << m;
  EXPECT_NE(m.find("did you mean 'cia402'"), std::string::npos) << m;
}

TEST_F(ModelAttribute, NoneKeepsTheStaticDeviceAndRefusesParams) {
  auto net = build(write("model=\"none\""));
  ASSERT_TRUE(net.ok()) << net.error().message();
  EXPECT_EQ(dev::driveOf(net->segment->slave(0)), nullptr);
  auto withParam =
      build(write("model=\"none\"", "    <Param name=\"motor.inertia\" value=\"1e-4\"/>\n"));
  ASSERT_FALSE(withParam.ok());
  EXPECT_NE(withParam.error().message().find("line 2"), std::string::npos)
      << withParam.error().message();
  EXPECT_NE(withParam.error().message().find("model=\"none\""), std::string::npos)
      << withParam.error().message();
}

TEST_F(ModelAttribute, Cia402OnADeviceWithoutTheObjectsIsAnErrorNamingTheLine) {
  // The ECS1008 (digital inputs) has no 0x6040.
  const auto path = write("model=\"cia402\"", "", 0x00001008);
  auto net = build(path);
  ASSERT_FALSE(net.ok());
  const std::string m = net.error().message();
  EXPECT_NE(m.find(path.string()), std::string::npos) << m;
  EXPECT_NE(m.find("line 2"), std::string::npos) << m;
  EXPECT_NE(m.find("0x6040"), std::string::npos) << m;
}

}  // namespace
}  // namespace ecsim::testing
