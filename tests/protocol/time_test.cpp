// Saturating arithmetic on simulated time (issue #21): sums and products that leave SimTime's
// range stick at its end instead of wrapping; doubles convert with rounding and clamping.
#include "protocol/time.hpp"

#include <gtest/gtest.h>

#include <limits>

namespace ecsim {
namespace {

TEST(SimTimeArithmetic, AddSaturatesAtBothEnds) {
  EXPECT_EQ(saturatingAdd(1'000, 2'000), 3'000);
  EXPECT_EQ(saturatingAdd(kSimTimeMax, 1), kSimTimeMax);
  EXPECT_EQ(saturatingAdd(kSimTimeMax - 5, kSimTimeMax), kSimTimeMax);
  EXPECT_EQ(saturatingAdd(kSimTimeMin, -1), kSimTimeMin);
  EXPECT_EQ(saturatingAdd(kSimTimeMax, kSimTimeMin), -1);
}

TEST(SimTimeArithmetic, MulSaturatesWithTheSignOfTheProduct) {
  EXPECT_EQ(saturatingMul(1'000, kNsPerMs), 1'000'000'000);
  EXPECT_EQ(saturatingMul(kSimTimeMax / 2 + 1, 2), kSimTimeMax);
  EXPECT_EQ(saturatingMul(-(kSimTimeMax / 2) - 2, 2), kSimTimeMin);
  EXPECT_EQ(saturatingMul(kSimTimeMin, -1), kSimTimeMax);
  EXPECT_EQ(saturatingMul(kSimTimeMax, -1), -kSimTimeMax);
}

TEST(SimTimeArithmetic, DoublesRoundAndClamp) {
  EXPECT_EQ(saturatingTime(1.5), 2);
  EXPECT_EQ(saturatingTime(-1.5), -2);
  EXPECT_EQ(saturatingTime(1e300), kSimTimeMax);
  EXPECT_EQ(saturatingTime(-1e300), kSimTimeMin);
  EXPECT_EQ(saturatingTime(std::numeric_limits<double>::infinity()), kSimTimeMax);
  EXPECT_EQ(saturatingTime(0x1.0p63), kSimTimeMax);
  EXPECT_EQ(saturatingTime(std::numeric_limits<double>::quiet_NaN()), 0);
}

}  // namespace
}  // namespace ecsim
