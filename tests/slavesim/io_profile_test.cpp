// Issue #17 item 1 (IO part): which IO profile a vendor device gets from its ESI
// (slavesim/devices/io_profile.hpp), the channels it is bound to, and the topology errors of
// model="io|analog|loopback" and of inputs that follow another slave's outputs. The devices
// are the vendors' own ESI files in ../shared/esi, read in place; the MDP 5001 analog layout,
// of which ../shared has no ESI, is written here after Beckhoff's EL31xx documentation
// (object 0x6000 "AI Standard Ch.1": :01 Underrange, :02 Overrange, :07 Error, :10 TxPDO
// Toggle, :11 Value).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "slavesim/devices/device_models.hpp"
#include "slavesim/devices/io_profile.hpp"
#include "slavesim/esi_slave.hpp"
#include "support/test_network.hpp"
#include "tests/slavesim/one_slave_topology.hpp"
#include "tests/support/ci_mode.hpp"

namespace ecsim::testing {
namespace {

namespace dev = slavesim::devices;

struct Device {
  const char* file;
  std::uint32_t product;
  std::uint32_t revision;
};
// Beckhoff_EtherCAT_Terminals.xml (2006): old layout 0x3101 (inputs) / 0x3001 (outputs).
constexpr Device kEk1100{"Beckhoff_EtherCAT_Terminals.xml", 0x044C2C52, 0x270B0000};
constexpr Device kEl1004{"Beckhoff_EtherCAT_Terminals.xml", 0x03EC3052, 0x270B0000};
constexpr Device kEl2004{"Beckhoff_EtherCAT_Terminals.xml", 0x07D43052, 0x270B0000};
constexpr Device kEl3102{"Beckhoff_EtherCAT_Terminals.xml", 0x0C1E3052, 0x270B0000};
constexpr Device kEl4102{"Beckhoff_EtherCAT_Terminals.xml", 0x10063052, 0x270B0000};
constexpr Device kEl6001{"Beckhoff_EtherCAT_Terminals.xml", 0x17713052, 0x270B0000};
constexpr Device kStmbl{"STMBL_ECAT.xml", 0x00020192, 0x00000001};

class IoProfile : public OneSlaveTopology {
 protected:
  static std::string slave(const std::string& name, const Device& d, const std::string& extra = {},
                           const std::string& body = {}) {
    std::ostringstream s;
    s << "  <Slave name=\"" << name << "\" esi=\"" << (sharedDir() / "esi" / d.file).string()
      << "\" product=\"" << d.product << "\" revision=\"" << d.revision << "\"" << extra << ">\n"
      << body << "  </Slave>\n";
    return s.str();
  }
  std::filesystem::path write(const std::string& slaves) {
    const auto path = dir_ / "net.xml";
    std::ofstream(path) << "<Topology name=\"t\">\n" << slaves << "</Topology>\n";
    return path;
  }
  void SetUp() override {
    OneSlaveTopology::SetUp();
    if (!std::filesystem::exists(sharedDir() / "esi" / kEl1004.file)) {
      if (ciMode()) FAIL() << "../shared/esi is missing";
      GTEST_SKIP() << "../shared/esi is missing";
    }
  }
};

TEST_F(IoProfile, ChosenFromTheDevicesOwnPdos) {
  auto net = build(write(slave("Coupler", kEk1100) + slave("DI", kEl1004) + slave("DO", kEl2004) +
                         slave("AI", kEl3102) + slave("AO", kEl4102) + slave("Serial", kEl6001) +
                         slave("Drive", kStmbl)));
  ASSERT_TRUE(net.ok()) << net.error().message();
  auto& seg = *net->segment;
  EXPECT_EQ(dev::deviceModelOf(seg.slave(0)), nullptr) << "EK1100: no PDOs, no model";
  ASSERT_NE(dev::digitalInputsOf(seg.slave(1)), nullptr);
  EXPECT_EQ(dev::digitalInputsOf(seg.slave(1))->channels(), 4u);  // 0x3101:01-04
  EXPECT_EQ(dev::digitalOutputsOf(seg.slave(1)), nullptr);
  ASSERT_NE(dev::digitalOutputsOf(seg.slave(2)), nullptr);
  EXPECT_EQ(dev::digitalOutputsOf(seg.slave(2))->channels(), 4u);  // 0x3001:01-04
  ASSERT_NE(dev::analogInputsOf(seg.slave(3)), nullptr);
  EXPECT_EQ(dev::analogInputsOf(seg.slave(3))->channels(), 2u);  // 0x3101:02, 0x3102:02
  ASSERT_NE(dev::analogOutputsOf(seg.slave(4)), nullptr);
  EXPECT_EQ(dev::analogOutputsOf(seg.slave(4))->channels(), 2u);  // 0x6411:01-02
  // EL6001: 22 data bytes each way are serial data, not 176 digital channels.
  EXPECT_EQ(dev::deviceModelOf(seg.slave(5)), nullptr);
  EXPECT_NE(dev::driveOf(seg.slave(6)), nullptr) << "a CiA 402 device keeps its drive";
}

TEST_F(IoProfile, EcsimsOwnDevicesKeepTheirModels) {
  auto net = build(writeTopology("", "", 0x00001008));  // ECS1008
  ASSERT_TRUE(net.ok()) << net.error().message();
  auto* model = dev::deviceModelOf(net->segment->slave(0));
  EXPECT_NE(dynamic_cast<dev::DigitalInputTerminal*>(model), nullptr);
}

TEST_F(IoProfile, OldLayoutStatusByteShowsRangeBits) {
  auto net = build(write(
      slave("AI", kEl3102, {}, "    <Param name=\"signal.2\" value=\"constant value=-11\"/>\n")));
  ASSERT_TRUE(net.ok()) << net.error().message();
  auto& s = net->segment->slave(0);
  auto* od = slavesim::objectDictionaryOf(s);
  ASSERT_NE(od, nullptr);
  dev::deviceModelOf(s)->step(*od, AlState::kOp, 0);  // one conversion
  // Channel 2 = 0x3102: :01 Status (BYTE), :02 Value (INT); bit 0 underrange, bit 6 error.
  EXPECT_EQ(*od->get<std::int16_t>(0x3102, 2), -32768);
  EXPECT_EQ(*od->get<std::uint8_t>(0x3102, 1) & 0x43, 0x41);
  EXPECT_EQ(*od->get<std::uint8_t>(0x3101, 1), 0) << "channel 1 unscripted: untouched";
}

TEST_F(IoProfile, MdpAnalogLayoutSetsItsStatusBits) {
  const auto esi = dir_ / "mdp-ai.xml";
  std::ofstream(esi) << R"(<?xml version="1.0"?>
<EtherCATInfo Version="1.2">
  <Vendor><Id>2</Id><Name>Test</Name></Vendor>
  <Descriptions><Groups><Group><Type>AI</Type><Name>AI</Name></Group></Groups><Devices>
    <Device Physics="YY">
      <Type ProductCode="#x7E570001" RevisionNo="#x1">MDP-AI1</Type>
      <Name>MDP analog input, EL31xx layout</Name>
      <Profile><ProfileNo>5001</ProfileNo></Profile>
      <GroupType>AI</GroupType>
      <Sm StartAddress="#x1000" ControlByte="#x20" Enable="1">Inputs</Sm>
      <TxPdo Fixed="1" Mandatory="1" Sm="0"><Index>#x1a00</Index><Name>AI Standard Channel 1</Name>
        <Entry><Index>#x6000</Index><SubIndex>1</SubIndex><BitLen>1</BitLen><Name>Underrange</Name><DataType>BOOL</DataType></Entry>
        <Entry><Index>#x6000</Index><SubIndex>2</SubIndex><BitLen>1</BitLen><Name>Overrange</Name><DataType>BOOL</DataType></Entry>
        <Entry><Index>#x0</Index><BitLen>4</BitLen></Entry>
        <Entry><Index>#x6000</Index><SubIndex>7</SubIndex><BitLen>1</BitLen><Name>Error</Name><DataType>BOOL</DataType></Entry>
        <Entry><Index>#x0</Index><BitLen>8</BitLen></Entry>
        <Entry><Index>#x6000</Index><SubIndex>16</SubIndex><BitLen>1</BitLen><Name>TxPDO Toggle</Name><DataType>BOOL</DataType></Entry>
        <Entry><Index>#x6000</Index><SubIndex>17</SubIndex><BitLen>16</BitLen><Name>Value</Name><DataType>INT</DataType></Entry>
      </TxPdo>
    </Device>
  </Devices></Descriptions>
</EtherCATInfo>
)";
  const auto path = dir_ / "net.xml";
  std::ofstream(path) << "<Topology name=\"t\">\n  <Slave name=\"AI\" esi=\"mdp-ai.xml\" "
                         "product=\"#x7E570001\">\n    <Param name=\"signal.1\" value=\"12\"/>\n"
                         "  </Slave>\n</Topology>\n";
  auto net = build(path);
  ASSERT_TRUE(net.ok()) << net.error().message();
  auto& s = net->segment->slave(0);
  ASSERT_NE(dev::analogInputsOf(s), nullptr) << "analog chosen, though the PDO has 1-bit entries";
  auto* od = slavesim::objectDictionaryOf(s);
  dev::deviceModelOf(s)->step(*od, AlState::kOp, 0);  // one conversion
  EXPECT_EQ(*od->get<std::int16_t>(0x6000, 0x11), 32767);
  EXPECT_EQ(*od->get<bool>(0x6000, 1), false);
  EXPECT_EQ(*od->get<bool>(0x6000, 2), true);
  EXPECT_EQ(*od->get<bool>(0x6000, 7), true);
}

struct ErrorCase {
  const char* what;
  std::string slaves;
  std::vector<std::string> expected;  // substrings of the message
};

TEST_F(IoProfile, BadModelsAndWiringAreErrorsWithFileAndLine) {
  const std::string loopFrom = "    <Param name=\"loopback.from\" value=\"";
  const std::vector<ErrorCase> cases = {
      {"unknown slave, closest name",
       slave("DO1", kEl2004) + slave("DI", kEl1004, " model=\"loopback\"", loopFrom + "DO2\"/>\n"),
       {"net.xml", "line 5", "unknown slave 'DO2'; did you mean 'DO1'?"}},
      {"a slave without outputs",
       slave("DO1", kEl2004) + slave("DI", kEl1004, " model=\"loopback\"", loopFrom + "DI\"/>\n"),
       {"net.xml", "line 5", "slave 'DI' has no digital outputs"}},
      {"channel out of range",
       slave("DO1", kEl2004) +
           slave("DI", kEl1004, {},
                 "    <Param name=\"signal.1\" value=\"output slave=DO1 channel=9\"/>\n"),
       {"net.xml", "line 5", "has output channels 1..4, not 9"}},
      {"loopback without loopback.from",
       slave("DI", kEl1004, " model=\"loopback\""),
       {"line 2", "loopback.from"}},
      {"loopback.from on another model",
       slave("DO1", kEl2004) + slave("DI", kEl1004, " model=\"io\"", loopFrom + "DO1\"/>\n"),
       {"line 5", "loopback.from needs model=\"loopback\""}},
      {"io on a coupler",
       slave("C", kEk1100, " model=\"io\""),
       {"net.xml", "line 2", "profile io", "no digital entries"}},
      {"analog on a digital input terminal",
       slave("DI", kEl1004, " model=\"analog\""),
       {"line 2", "profile analog"}},
      {"misspelt model",
       slave("DI", kEl1004, " model=\"loopbak\""),
       {"line 2", "did you mean 'loopback'?"}},
  };
  for (const ErrorCase& c : cases) {
    auto net = build(write(c.slaves));
    ASSERT_FALSE(net.ok()) << c.what;
    for (const std::string& part : c.expected) {
      EXPECT_NE(net.error().message().find(part), std::string::npos)
          << c.what << ": '" << part << "' not in: " << net.error().message();
    }
  }
}

// A power cycle re-creates both models (devices::restartDeviceModel): the wiring is outside
// the devices and survives, and follows the new output terminal.
TEST_F(IoProfile, LoopbackSurvivesPowerCyclesOfBothSlaves) {
  auto net = build(
      write(slave("DO", kEl2004) + slave("DI", kEl1004, " model=\"loopback\"",
                                         "    <Param name=\"loopback.from\" value=\"DO\"/>\n")));
  ASSERT_TRUE(net.ok()) << net.error().message();
  auto& out = net->segment->slave(0);
  auto& in = net->segment->slave(1);
  for (auto* s : {&out, &in}) {
    s->powerOff();
    s->powerOn(0);
    ASSERT_TRUE(s->coldStartStatus().ok()) << s->coldStartStatus().error().message();
  }
  auto* outOd = slavesim::objectDictionaryOf(out);
  auto* inOd = slavesim::objectDictionaryOf(in);
  for (bool on : {true, false, true}) {
    ASSERT_TRUE(outOd->set<bool>(0x3001, 3, on).ok());  // EL2004 output 3
    dev::deviceModelOf(out)->step(*outOd, AlState::kOp, 0);
    dev::deviceModelOf(in)->step(*inOd, AlState::kOp, 0);
    EXPECT_EQ(*inOd->get<bool>(0x3101, 3), on);  // EL1004 input 3
    EXPECT_EQ(*inOd->get<bool>(0x3101, 1), false);
  }
}

}  // namespace
}  // namespace ecsim::testing
