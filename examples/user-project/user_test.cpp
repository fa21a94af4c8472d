// A user's test of "their" application logic against a simulated EtherCAT network: the demo
// network installed with ecsim, in-process on virtual time, driven by ecsim's master.
#include <gtest/gtest.h>

#include <optional>

#include <ecsim/embed/testing/network_fixture.hpp>
#include <ecsim/master/process_image.hpp>

namespace {

class DemoLine : public ecsim::testing::NetworkFixture {
 protected:
  void SetUp() override {
    ASSERT_TRUE(startInProcess(USER_TOPOLOGY_DIR "/demo.xml").ok());
    auto started = master().start();
    ASSERT_TRUE(started.ok()) << started.error().message();
  }

  // The process-image byte of a digital terminal's channels :01-:08 (1 bit each; AI1's
  // 0x6000:01 is a 16-bit value).
  std::optional<std::size_t> byteOf(std::uint16_t index, bool output) {
    for (const auto& v : ecsim::master::processVariables(master().layout())) {
      if (v.index == index && v.subindex == 1 && v.bitLength == 1 && v.output == output) {
        return v.bitOffset / 8;
      }
    }
    return std::nullopt;
  }
};

TEST_F(DemoLine, EverySlaveIsInOp) {
  EXPECT_EQ(master().slaves().size(), network().slaveCount());
  for (std::size_t i = 0; i < network().slaveCount(); ++i) {
    EXPECT_EQ(network().slave(i)->state(), ecsim::AlState::kOp) << network().slave(i)->name();
  }
}

TEST_F(DemoLine, OutputsReachTheSlaveAndInputsReachTheMaster) {
  const auto doByte = byteOf(0x7000, true);
  const auto diByte = byteOf(0x6000, false);
  ASSERT_TRUE(doByte && diByte);

  const std::uint8_t lamp = 0x81;  // channels 1 and 8 of DO1
  ASSERT_TRUE(master().writeData(*doByte, ecsim::ConstBytes(&lamp, 1)).ok());
  ASSERT_TRUE(network().slave("DI1")->write<bool>(0x6000, 8, true).ok());  // a sensor turns on
  for (int cycle = 0; cycle < 3; ++cycle) {
    ASSERT_TRUE(master().exchange().ok());
    ASSERT_TRUE(advance(ecsim::kNsPerMs).ok());
  }
  auto do1 = network().slave("DO1");
  ASSERT_TRUE(do1.ok());
  EXPECT_TRUE(do1->read<bool>(0x7000, 1).valueOr(false));
  EXPECT_FALSE(do1->read<bool>(0x7000, 2).valueOr(true));
  EXPECT_TRUE(do1->read<bool>(0x7000, 8).valueOr(false));

  std::uint8_t inputs = 0;
  ASSERT_TRUE(master().readData(*diByte, ecsim::Bytes(&inputs, 1)).ok());
  EXPECT_EQ(inputs, 0x85);  // channels 1 and 3 set by demo.xml, 8 by this test
  EXPECT_TRUE(master().stop().ok());
}

}  // namespace
