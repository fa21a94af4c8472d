// Simulation time and clocks. SimTime is signed 64-bit nanoseconds. Core code never reads the
// system clock: it is handed a Clock (virtual in tests and fast mode, real when pacing).
#pragma once

#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>

namespace ecsim {

using SimTime = std::int64_t;  // nanoseconds

constexpr SimTime kNsPerUs = 1'000;
constexpr SimTime kNsPerMs = 1'000'000;
constexpr SimTime kNsPerSecond = 1'000'000'000;

// Nanoseconds between the Unix epoch and 2000-01-01T00:00:00Z, the EtherCAT DC epoch
// (ESC datasheet section I, §9.1: "system time starts 1 Jan 2000 00:00, unit 1 ns").
constexpr std::int64_t kDcEpochUnixNs = 946'684'800LL * kNsPerSecond;

constexpr SimTime kSimTimeMax = std::numeric_limits<SimTime>::max();
constexpr SimTime kSimTimeMin = std::numeric_limits<SimTime>::min();

// Saturating arithmetic for times that input controls (delay spikes, durations, scenario
// times, paced return times): a sum or product beyond the range of SimTime sticks at its end
// (about 292 years either side of 0) instead of wrapping, so "late" stays late.
constexpr SimTime saturatingAdd(SimTime a, SimTime b) {
  SimTime sum = 0;
  if (__builtin_add_overflow(a, b, &sum)) return b > 0 ? kSimTimeMax : kSimTimeMin;
  return sum;
}
constexpr SimTime saturatingSub(SimTime a, SimTime b) {
  SimTime difference = 0;
  if (__builtin_sub_overflow(a, b, &difference)) return b < 0 ? kSimTimeMax : kSimTimeMin;
  return difference;
}
constexpr SimTime saturatingMul(SimTime a, SimTime b) {
  SimTime product = 0;
  if (__builtin_mul_overflow(a, b, &product)) {
    return (a < 0) == (b < 0) ? kSimTimeMax : kSimTimeMin;
  }
  return product;
}
// A count of nanoseconds given as a double, rounded to the nearest and clamped to SimTime's
// range; NaN gives 0 (callers reject NaN where it is read: this only keeps the cast defined).
inline SimTime saturatingTime(double ns) {
  if (std::isnan(ns)) return 0;
  // 2^63 is exactly representable; anything at or above it does not fit.
  if (ns >= 0x1.0p63) return kSimTimeMax;
  if (ns <= -0x1.0p63) return kSimTimeMin;
  return static_cast<SimTime>(std::llround(ns));
}

class Clock {
 public:
  virtual ~Clock() = default;
  virtual SimTime now() const = 0;
};

// Time that moves only when told to. Deterministic; used by tests and fast mode.
class VirtualClock final : public Clock {
 public:
  explicit VirtualClock(SimTime start = 0) : now_(start) {}
  SimTime now() const override { return now_; }
  void advance(SimTime delta) { now_ += delta; }
  void set(SimTime t) { now_ = t; }

 private:
  SimTime now_;
};

// Monotonic system clock, read only where a real clock is injected (paced mode, links).
class RealClock final : public Clock {
 public:
  SimTime now() const override {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
  }
};

// Wall-clock time in nanoseconds since the Unix epoch, for pcap timestamps of live captures.
class WallClock final : public Clock {
 public:
  SimTime now() const override {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::system_clock::now().time_since_epoch())
        .count();
  }
};

}  // namespace ecsim
