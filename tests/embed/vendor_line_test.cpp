// examples/topologies/vendor-line.xml (issue #17 item 4) with our master in process: a line of
// real vendor devices read from ../shared/esi in place. The EL1004 looped to the EL2004 shows
// what the master wrote one cycle later, the EL1008's and EL3102's inputs follow their scripts
// (a 0.5 s square, a step at 1 s, a 1 Hz sine of 5 V), and the Ingenia EVS-NET-01 behind the
// EK1110 runs the CiA 402 enable sequence and follows a CSP ramp of one turn.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "embed/testing/network_fixture.hpp"
#include "slavesim/devices/device_models.hpp"
#include "support/cia402_steps.hpp"
#include "support/test_network.hpp"

namespace ecsim::testing {
namespace {

namespace dev = slavesim::devices;

class VendorLine : public NetworkFixture {
 protected:
  void TearDown() override { stopNetwork(); }
  // One exchange per millisecond, on an exact 1 ms grid of simulated time.
  Status cycle() {
    ECSIM_TRY(master().exchange());
    const SimTime now = network().now();
    return advance((now / kNsPerMs + 1) * kNsPerMs - now);
  }
  std::vector<master::VariableInfo> vars(const std::string& slave, bool output) {
    std::vector<master::VariableInfo> out;
    for (const auto& v : master().variables()) {
      if (v.slave == slave && v.output == output && v.bitLength == 1) out.push_back(v);
    }
    std::sort(out.begin(), out.end(),
              [](const auto& a, const auto& b) { return a.bitOffset < b.bitOffset; });
    return out;
  }
};

TEST_F(VendorLine, LoopSignalsAndACspTurnOfTheVendorDrive) {
  ECSIM_REQUIRE_SHARED(sharedDir() / "esi" / "ingenia_esi.xml");
  ASSERT_TRUE(startInProcess(std::filesystem::path(ECSIM_SOURCE_DIR) /
                             "examples/topologies/vendor-line.xml")
                  .ok());
  ASSERT_TRUE(master().scan().ok());
  ASSERT_TRUE(master().bringTo(AlState::kPreOp).ok());
  constexpr std::size_t kAxis = 6;
  // The interpolation period 0x60C2 is the master's 1 ms cycle, as a CSP master sets it.
  const std::uint8_t one[] = {1};
  const std::uint8_t milli[] = {static_cast<std::uint8_t>(-3)};
  ASSERT_TRUE(master().sdoDownload(kAxis, 0x60C2, 1, one).ok());
  ASSERT_TRUE(master().sdoDownload(kAxis, 0x60C2, 2, milli).ok());
  auto op = master().bringTo(AlState::kOp);
  ASSERT_TRUE(op.ok()) << op.error().message();

  // The loop: 4 outputs of the EL2004 to the 4 inputs of the EL1004.
  const auto outs = vars("DO1", true);
  const auto ins = vars("DI1", false);
  ASSERT_EQ(outs.size(), 4u);
  ASSERT_EQ(ins.size(), 4u);
  auto di2 = master().variable("DI2.Channel 1.Input");
  auto di2Step = master().variable("DI2.Channel 2.Input");
  ASSERT_TRUE(di2.ok() && di2Step.ok());
  std::vector<std::uint8_t> written;
  std::vector<bool> square, step;
  int loopMatches = 0;
  std::int16_t aiMin = 0, aiMax = 0;
  auto ai = master().variable("AI1.Channel #1.Value");
  ASSERT_TRUE(ai.ok()) << ai.error().message();
  for (int c = 0; c < 1500; ++c) {
    const auto pattern = static_cast<std::uint8_t>((c * 7 + 3) & 0x0F);
    for (unsigned k = 0; k < 4; ++k) {
      auto v = master().variable(outs[k].name);
      ASSERT_TRUE(v.ok());
      v->set<bool>(((pattern >> k) & 1u) != 0);
    }
    written.push_back(pattern);
    ASSERT_TRUE(cycle().ok());
    std::uint8_t got = 0;
    for (unsigned k = 0; k < 4; ++k) {
      auto v = master().variable(ins[k].name);
      if (v->get<bool>()) got = static_cast<std::uint8_t>(got | (1u << k));
    }
    // The inputs this exchange brought were latched after the previous exchange's outputs.
    if (c > 0 && got == written[static_cast<std::size_t>(c - 1)]) ++loopMatches;
    square.push_back(di2->get<bool>());
    step.push_back(di2Step->get<bool>());
    aiMin = std::min(aiMin, ai->get<std::int16_t>());
    aiMax = std::max(aiMax, ai->get<std::int16_t>());
  }
  EXPECT_EQ(loopMatches, 1499) << "the EL1004 shows the EL2004's outputs one cycle later";
  int edges = 0;
  for (std::size_t c = 1; c < square.size(); ++c) edges += square[c] != square[c - 1] ? 1 : 0;
  EXPECT_GE(edges, 5) << "a 0.5 s square over 1.5 s";
  EXPECT_LE(edges, 7);
  EXPECT_FALSE(step[900]) << "before the step at 1 s (OP was reached before 0.1 s)";
  EXPECT_TRUE(step.back()) << "after it";
  // 5 V of +/-10 V full scale is 16384 counts (docs/devices.md).
  EXPECT_NEAR(aiMax, 16384, 200);
  EXPECT_NEAR(aiMin, -16384, 200);

  // The drive: enable, then CSP one turn through the Ingenia's own PDOs.
  dev::Cia402Drive* drive = dev::driveOf(network().segment().slave(kAxis));
  ASSERT_NE(drive, nullptr);
  const std::string axis = std::to_string(kAxis);
  auto controlword = master().variable(axis + ".0x6040:00");
  auto statusword = master().variable(axis + ".0x6041:00");
  auto target = master().variable(axis + ".0x607A:00");
  auto actual = master().variable(axis + ".0x6064:00");
  auto mode = master().variable(axis + ".0x6060:00");
  ASSERT_TRUE(controlword.ok() && statusword.ok() && target.ok() && actual.ok() && mode.ok());
  mode->set<std::int8_t>(8);
  auto runUntil = [&](std::uint16_t cw, std::uint16_t mask, std::uint16_t want) {
    return cia402RunUntil(
        *controlword, *statusword, *target, *actual, [&] { return cycle(); }, cw, mask, want);
  };
  ASSERT_TRUE(runUntil(0x0006, 0x6F, 0x21)) << "Ready to switch on";
  ASSERT_TRUE(runUntil(0x0007, 0x6F, 0x23)) << "Switched on";
  ASSERT_TRUE(runUntil(0x000F, 0x6F, 0x27)) << "Operation enabled";
  const double turn = drive->encoder().params().countsPerRevolution;
  const std::int32_t start = actual->get<std::int32_t>();
  for (int i = 1; i <= 1200; ++i) {
    const double s = std::min(1.0, i / 1000.0);
    target->set<std::int32_t>(
        static_cast<std::int32_t>(start + std::lround(turn * s * s * (3 - 2 * s))));
    ASSERT_TRUE(cycle().ok());
  }
  EXPECT_LE(std::abs(actual->get<std::int32_t>() - (start + turn)),
            dev::DriveParams{}.positionWindow);
  EXPECT_EQ(statusword->get<std::uint16_t>() & 0x6F, 0x27) << "still Operation enabled";
}

}  // namespace
}  // namespace ecsim::testing
