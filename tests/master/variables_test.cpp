// Process data by name: the bit access helpers on hand-made bytes, then the names and typed
// access on the demo devices (examples/esi/ecsim_devices.xml) brought to OP by the master.
#include "master/variables.hpp"

#include <gtest/gtest.h>

#include "master/master.hpp"
#include "tests/master/bring_up.hpp"

namespace ecsim::testing {
namespace {

using master::readBits;
using master::VariableType;
using master::writeBits;

TEST(VariableBitsTest, ReadsAndWritesLittleEndianBitFields) {
  std::vector<std::uint8_t> image{0b1011'0100, 0xFF, 0x00, 0x80};
  EXPECT_EQ(readBits(image, 2, 3), 0b101u);
  EXPECT_EQ(readBits(image, 6, 4), 0b1110u);  // bits 6, 7 of byte 0, bits 0, 1 of byte 1
  EXPECT_EQ(readBits(image, 8, 16), 0x00FFu);
  EXPECT_EQ(readBits(image, 31, 1), 1u);
  writeBits(image, 3, 2, 0b11);
  EXPECT_EQ(image[0], 0b1011'1100);  // neighbours untouched
  writeBits(image, 12, 8, 0x5A);
  EXPECT_EQ(image[1], 0xAF);
  EXPECT_EQ(image[2], 0x05);
  writeBits(image, 30, 8, 0xFF);  // runs past the end: only what is inside is written
  EXPECT_EQ(image[3], 0xC0);
}

TEST(VariableBitsTest, TypesFromCoeDataTypeOrSize) {
  EXPECT_EQ(master::variableType(0x0003, 16), VariableType::kInt16);
  EXPECT_EQ(master::variableType(0x0004, 32), VariableType::kInt32);
  EXPECT_EQ(master::variableType(0x0008, 32), VariableType::kReal32);
  EXPECT_EQ(master::variableType(0, 1), VariableType::kBool);
  EXPECT_EQ(master::variableType(0, 16), VariableType::kUint16);
  EXPECT_EQ(master::variableType(0, 3), VariableType::kBits);
}

TEST(VariableBitsTest, SignedGetAndSetThroughAVariable) {
  std::vector<std::uint8_t> image(4, 0);
  master::VariableInfo info;
  info.name = "X.Velocity";
  info.bitOffset = 8;
  info.bitLength = 16;
  info.type = VariableType::kInt16;
  master::PdoVariable v(info, image);
  v.set<std::int32_t>(-2);
  EXPECT_EQ(image[1], 0xFE);
  EXPECT_EQ(image[2], 0xFF);
  EXPECT_EQ(v.get<std::int32_t>(), -2);
  EXPECT_EQ(v.get<std::uint16_t>(), 0xFFFE);
  EXPECT_EQ(v.format(), "-2");
  EXPECT_DOUBLE_EQ(v.get<double>(), -2.0);
  info.type = VariableType::kReal32;
  info.bitOffset = 0;
  info.bitLength = 32;
  master::PdoVariable r(info, image);
  r.set(1.5);
  EXPECT_EQ(readLe32(image, 0), 0x3FC00000u);  // IEEE 754 single 1.5
  EXPECT_DOUBLE_EQ(r.get<double>(), 1.5);
}

enum : std::size_t { kCoupler, kDi, kDo, kAi, kDrive, kDrive2, kCount };

class DemoVariablesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    addDemoSlaves(net_);
    net_.start();
    master_ = std::make_unique<master::Master>(net_.masterLink(), net_.bus());
  }
  std::string names() const {
    std::string s;
    for (const auto& v : master_->variables()) s += v.name + "\n";
    return s;
  }
  slavesim::Slave& sim(std::size_t i) { return net_.segment().slave(i); }

  SimNetwork net_;
  std::unique_ptr<master::Master> master_;
};

TEST_F(DemoVariablesTest, ConfiguredNamesGiveDi1Input3AndDrive1Statusword) {
  auto config = master::parseMasterConfig(R"(<?xml version="1.0"?>
<EcsimMaster>
  <Slave name="Coupler" vendor="#x00000E5C" product="#x00001100"/>
  <Slave name="DI1" vendor="#x00000E5C" product="#x00001008"/>
  <Slave name="DO1" vendor="#x00000E5C" product="#x00002008"/>
  <Slave name="AI1" vendor="#x00000E5C" product="#x00003102"/>
  <Slave name="Drive1" vendor="#x00000E5C" product="#x00007201"/>
  <Slave name="Drive2" vendor="#x00000E5C" product="#x00007201"/>
</EcsimMaster>)",
                                          "demo.xml");
  ASSERT_TRUE(config.ok()) << config.error().message();
  master_->setConfig(*config);
  auto status = master_->start();
  ASSERT_TRUE(status.ok()) << status.error().message();

  auto in3 = master_->variable("DI1.Input 3");
  ASSERT_TRUE(in3.ok()) << in3.error().message() << "\n" << names();
  EXPECT_EQ(in3->info().bitLength, 1);
  EXPECT_FALSE(in3->info().output);
  EXPECT_EQ(in3->info().type, VariableType::kBool);
  EXPECT_EQ(in3->info().index, 0x6000);
  EXPECT_EQ(in3->info().subindex, 3);

  auto statusword = master_->variable("Drive1.Statusword");
  ASSERT_TRUE(statusword.ok()) << statusword.error().message() << "\n" << names();
  EXPECT_EQ(statusword->info().bitLength, 16);
  EXPECT_EQ(statusword->info().index, 0x6041);
  // The same entry by its aliases.
  auto byIndex = master_->variable("Drive1.0x6041:00");
  ASSERT_TRUE(byIndex.ok()) << byIndex.error().message();
  EXPECT_EQ(byIndex->info().bitOffset, statusword->info().bitOffset);
  auto byPosition = master_->variable("4.Statusword");
  ASSERT_TRUE(byPosition.ok());
  EXPECT_EQ(byPosition->info().bitOffset, statusword->info().bitOffset);
  // Drive2 has its own statusword elsewhere in the image.
  auto other = master_->variable("Drive2.Statusword");
  ASSERT_TRUE(other.ok());
  EXPECT_NE(other->info().bitOffset, statusword->info().bitOffset);

  // Typed access reads the image the cycle filled ...
  ASSERT_TRUE(master_->exchange().ok());
  std::array<std::uint8_t, 2> raw{};
  ASSERT_TRUE(master_->readData(statusword->info().bitOffset / 8, raw).ok());
  EXPECT_EQ(statusword->get<std::uint16_t>(), readLe16(raw, 0));
  // ... and writes outputs the slave receives.
  auto out3 = master_->variable("DO1.Output 3");
  ASSERT_TRUE(out3.ok()) << out3.error().message() << "\n" << names();
  EXPECT_TRUE(out3->info().output);
  out3->set(true);
  ASSERT_TRUE(master_->exchange().ok());
  ConstBytes outputs = sim(kDo).esc().pdiOutputs(0);
  ASSERT_EQ(outputs.size(), 1u);
  EXPECT_EQ(outputs[0], 0b100);
  EXPECT_TRUE(out3->get<bool>());

  auto missing = master_->variable("DI1.Input 9");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().code, ErrorCode::kNotFound);
  EXPECT_NE(missing.error().context.find("DI1.Input 1"), std::string::npos)
      << missing.error().context;
}

// Issue #16 item 3: names by bus position (a topology's, topology/slave_names.hpp) name the
// variables and the slaves in messages, and win over a configuration's.
TEST_F(DemoVariablesTest, SlaveNamesNameVariablesAndLabels) {
  master_->setSlaveNames({"Coupler", "DI1", "DO1", "AI1", "Drive1", "Drive2"});
  ASSERT_TRUE(master_->start().ok());
  auto statusword = master_->variable("Drive1.Statusword");
  ASSERT_TRUE(statusword.ok()) << statusword.error().message() << "\n" << names();
  EXPECT_EQ(statusword->info().position, static_cast<std::size_t>(kDrive));
  EXPECT_TRUE(master_->variable("Drive2.Statusword").ok()) << names();
  EXPECT_FALSE(master_->variable("ECS7201_4.Statusword").ok()) << names();
  EXPECT_EQ(master_->slaves()[kDrive].label(), "slave 4 (0x1005 'Drive1')");
  EXPECT_EQ(master_->slaves()[kDrive].name, "ECS7201 CiA 402 servo drive");  // the SII's, kept
  EXPECT_EQ(master_->health().slaves[kDrive].name, "Drive1");
}

// An unknown variable lists the nearest names (edit distance), nearest first.
TEST_F(DemoVariablesTest, AnUnknownVariableListsTheClosestNames) {
  master_->setSlaveNames({"Coupler", "DI1", "DO1", "AI1", "Drive1", "Drive2"});
  ASSERT_TRUE(master_->start().ok());
  auto wrongCase = master_->variable("Drive1.StatusWord");
  ASSERT_FALSE(wrongCase.ok());
  EXPECT_EQ(wrongCase.error().code, ErrorCode::kNotFound);
  EXPECT_EQ(wrongCase.error().context.rfind("no process variable 'Drive1.StatusWord'; closest: "
                                            "Drive1.Statusword, Drive2.Statusword",
                                            0),
            0u)
      << wrongCase.error().context;
  auto wrongSlave = master_->variable("Drive3.Statusword");
  ASSERT_FALSE(wrongSlave.ok());
  EXPECT_NE(wrongSlave.error().context.find("closest: Drive1.Statusword, Drive2.Statusword"),
            std::string::npos)
      << wrongSlave.error().context;
}

TEST_F(DemoVariablesTest, WithoutConfigurationTheSiiNamesAreMadeUnique) {
  ASSERT_TRUE(master_->start().ok());
  // The SII order strings of examples/esi/ecsim_devices.xml (<Type>); the two drives share
  // theirs, so each gets "_<position>".
  EXPECT_TRUE(master_->variable("ECS1008.Input 3").ok()) << names();
  EXPECT_TRUE(master_->variable("ECS7201_4.Statusword").ok()) << names();
  EXPECT_TRUE(master_->variable("ECS7201_5.Statusword").ok()) << names();
  EXPECT_FALSE(master_->variable("ECS7201.Statusword").ok()) << names();
  EXPECT_TRUE(master_->variable("1.Input 3").ok()) << names();
  EXPECT_EQ(master::Master(net_.masterLink(), net_.bus()).variable("x").error().code,
            ErrorCode::kState);
}

}  // namespace
}  // namespace ecsim::testing
