#include "slavesim/dc_clock.hpp"

#include <algorithm>
#include <cmath>

namespace ecsim::slavesim {
namespace {

// The ESC adjusts its clock by dropping or adding a nanosecond per 10 ns tick at most once in
// a number of ticks set by the speed counter: the correction is bounded. We bound it to
// +-1000 ppm, an order of magnitude above any quartz error the datasheet expects (25 ppm).
constexpr double kMaxCorrectionPpb = 1'000'000.0;
// A proportional-integral phase-locked loop with gains in continuous time, so the behaviour
// does not depend on how often the master distributes the reference time: a phase error of
// e ns changes the rate by -kP * e ppb (time constant 1/kP = 5 ms), and the frequency
// integrator learns the oscillator error at kI = kP^2 / 4 (critically damped).
constexpr double kP = 200.0;        // ppb per ns
constexpr double kI = kP * kP / 4;  // ppb per ns per second
}  // namespace

void DcClock::configure(SimTime offset, double driftPpm) {
  tBase_ = 0;
  localBase_ = offset;
  driftPpb_ = driftPpm * 1000.0;
  resetControl();
}

void DcClock::restart(SimTime global) {
  tBase_ = global;
  localBase_ = 0;
  resetControl();
}

void DcClock::resetControl() {
  correctionPpb_ = 0.0;
  integralPpb_ = 0.0;
  haveLastWrite_ = false;
}

SimTime DcClock::localTime(SimTime global) const {
  const double rate = (driftPpb_ + correctionPpb_) * 1e-9;
  const SimTime dt = global - tBase_;
  return localBase_ + dt + static_cast<SimTime>(static_cast<double>(dt) * rate);
}

SimTime DcClock::globalTime(SimTime local) const {
  const double rate = (driftPpb_ + correctionPpb_) * 1e-9;
  const double dl = static_cast<double>(local - localBase_);
  return tBase_ + static_cast<SimTime>(dl / (1.0 + rate));
}

void DcClock::rebase(SimTime global) {
  localBase_ = localTime(global);
  tBase_ = global;
}

std::int64_t DcClock::onSystemTimeWrite(SimTime global, SimTime localSystemTime, SimTime received,
                                        unsigned filterDepth) {
  // System time is a 64-bit counter: the difference wraps (and a master may write anything).
  const auto diff = static_cast<std::int64_t>(static_cast<std::uint64_t>(localSystemTime) -
                                              static_cast<std::uint64_t>(received));
  // The first write after a reset, or a difference beyond what drift can explain (an offset
  // not yet compensated), only measures: no frequency is learnt from it.
  if (!haveLastWrite_ || global <= lastWrite_ || (diff > 10'000'000 || diff < -10'000'000)) {
    haveLastWrite_ = true;
    lastWrite_ = global;
    return diff;
  }
  const double interval = static_cast<double>(global - lastWrite_) * 1e-9;  // seconds
  lastWrite_ = global;
  // 0x0934 sets a filter over the differences; the loop below is already a low-pass with a
  // few-ms time constant, so the register is kept but the loop uses the raw difference (documented
  // simplification, docs/timing.md).
  (void)filterDepth;
  const double e = static_cast<double>(diff);
  integralPpb_ =
      std::clamp(integralPpb_ - kI * e * interval, -kMaxCorrectionPpb, kMaxCorrectionPpb);
  rebase(global);
  correctionPpb_ = std::clamp(integralPpb_ - kP * e, -kMaxCorrectionPpb, kMaxCorrectionPpb);
  return diff;
}

std::uint32_t systemTimeDifferenceRegister(std::int64_t diff) {
  constexpr std::int64_t kMaxMagnitude = 0x7FFFFFFF;
  constexpr std::uint32_t kLocalSmaller = 0x80000000u;
  // Clamped before the sign is taken off: -INT64_MIN does not exist.
  const std::int64_t held = std::clamp(diff, -kMaxMagnitude, kMaxMagnitude);
  const auto magnitude = static_cast<std::uint32_t>(held < 0 ? -held : held);
  return diff < 0 ? (magnitude | kLocalSmaller) : magnitude;
}

}  // namespace ecsim::slavesim
