// Scripted signals of issue #17 item 2: the step and the seeded noise (slavesim/devices/
// signal.hpp), their text form and its strictness (an unknown parameter names the closest).
#include "slavesim/devices/signal.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace ecsim {
namespace {

namespace dev = slavesim::devices;

SimTime ms(double v) {
  return static_cast<SimTime>(v * kNsPerMs);
}

dev::Signal parsed(const std::string& text) {
  auto s = dev::parseSignal(text);
  EXPECT_TRUE(s.ok()) << text << ": " << (s.ok() ? "" : s.error().message());
  return s.ok() ? *s : dev::Signal{};
}

TEST(StepSignal, JumpsAtItsTime) {
  const auto s = parsed("step at=0.5 before=-2 after=3");
  EXPECT_EQ(s.value(0), -2.0);
  EXPECT_EQ(s.value(ms(499.999)), -2.0);
  EXPECT_EQ(s.value(ms(500)), 3.0) << "the jump belongs to t = at";
  EXPECT_EQ(s.value(ms(10000)), 3.0);
  // Counted from its origin, as every signal (a scenario's action sets it at its own time).
  const auto later = s.startingAt(ms(1000));
  EXPECT_EQ(later.value(ms(1400)), -2.0);
  EXPECT_EQ(later.value(ms(1500)), 3.0);
  EXPECT_EQ(parsed("step").value(0), 1.0) << "defaults: at=0 before=0 after=1";
}

TEST(NoiseSignal, SameSeedSameSequenceHeldForAPeriod) {
  const auto a = parsed("noise mean=1 sigma=0.5 seed=7 period=0.001");
  const auto b = parsed("noise mean=1 sigma=0.5 seed=7 period=0.001");
  const auto other = parsed("noise mean=1 sigma=0.5 seed=8 period=0.001");
  int differing = 0;
  for (int k = 0; k < 1000; ++k) {
    const SimTime t = ms(k) + ms(0.25);
    EXPECT_EQ(a.value(t), b.value(t)) << "sample " << k;
    // A sample holds for its period, and value(t) is pure: the same t, the same value.
    EXPECT_EQ(a.value(ms(k)), a.value(ms(k) + ms(0.999)));
    EXPECT_EQ(a.value(t), a.value(t));
    if (a.value(t) != other.value(t)) ++differing;
  }
  EXPECT_EQ(differing, 1000) << "another seed is another sequence";
  // Values of seed 7 (splitmix64 + Box-Muller, signal.cpp): the sequence must not change
  // between builds or machines, so a scenario's noise is the same run after run.
  const auto unit = parsed("noise mean=0 sigma=1 seed=7 period=0.001");
  EXPECT_NEAR(unit.value(0), 0.107574157532081, 1e-12);
  EXPECT_NEAR(unit.value(ms(1)), -0.705639900320886, 1e-12);
  EXPECT_NEAR(unit.value(ms(999)), -0.0639657835624915, 1e-12);
}

TEST(NoiseSignal, MeanAndSigmaOf100kSamples) {
  // 100000 samples of N(2, 0.3): the sample mean is within 4 standard errors (0.3/sqrt(1e5) =
  // 0.00095) of 2, the sample standard deviation within 4 of its standard errors (about
  // 0.3/sqrt(2e5) = 0.00067) of 0.3. A skewed or clipped deviate (the sum of uniforms) would
  // also show in the share beyond 2 sigma, 4.55 % for a normal distribution.
  const auto s = parsed("noise mean=2 sigma=0.3 seed=12345 period=0.001");
  constexpr int kSamples = 100000;
  double sum = 0.0, sumSq = 0.0;
  int beyondTwoSigma = 0;
  for (int k = 0; k < kSamples; ++k) {
    const double v = s.value(static_cast<SimTime>(k) * kNsPerMs);
    sum += v;
    sumSq += v * v;
    if (std::abs(v - 2.0) > 0.6) ++beyondTwoSigma;
  }
  const double mean = sum / kSamples;
  const double sigma = std::sqrt(sumSq / kSamples - mean * mean);
  EXPECT_NEAR(mean, 2.0, 0.0038);
  EXPECT_NEAR(sigma, 0.3, 0.0027);
  EXPECT_NEAR(beyondTwoSigma / double(kSamples), 0.0455, 0.0027);  // 4 binomial standard errors
}

TEST(NoiseSignal, ZeroSigmaIsTheMean) {
  EXPECT_EQ(parsed("noise mean=4 sigma=0").value(ms(3)), 4.0);
}

TEST(SignalText, BadStepAndNoiseAreRefusedNamingTheClosestParameter) {
  struct Bad {
    const char* text;
    const char* expected;
  };
  const Bad cases[] = {
      {"step at=1 afte=2", "unknown parameter 'afte' of step; did you mean 'after'?"},
      {"noise sigm=1", "unknown parameter 'sigm' of noise; did you mean 'sigma'?"},
      {"sine amplitud=1", "unknown parameter 'amplitud' of sine; did you mean 'amplitude'?"},
      {"noise sigma=-1", "sigma must be >= 0"},
      {"noise period=0", "period must be >= 1e-9"},
      {"noise period=1e-10", "period must be >= 1e-9"},
      {"noise seed=1.5", "seed must be an integer in [0, 2^53)"},
      {"noise seed=-1", "seed must be an integer in [0, 2^53)"},
      {"step at=x", "at=x"},
      {"nois sigma=1", "did you mean 'noise'?"},
  };
  for (const Bad& c : cases) {
    auto s = dev::parseSignal(c.text);
    ASSERT_FALSE(s.ok()) << c.text;
    EXPECT_EQ(s.error().code, ErrorCode::kParse) << c.text;
    EXPECT_NE(s.error().context.find(c.expected), std::string::npos)
        << c.text << ": " << s.error().context;
  }
}

}  // namespace
}  // namespace ecsim
