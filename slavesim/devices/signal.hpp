// Scripted input signals for simulated IO terminals: a value as a function of simulation time.
// A Signal is a plain value (constant, step, square, sine, ramp, seeded noise or a table read
// from a CSV file);
// value(t) is pure and never allocates, so terminals evaluate it on the cyclic path.
//
// Text form (parseSignal), for topology files and command lines:
//   "1.5"                                    constant
//   "constant value=1.5"
//   "step at=0.5 before=0 after=1"                           (after from t = at on)
//   "square period=0.5 low=0 high=1 duty=0.5 phase=0"
//   "sine amplitude=5 frequency=2 offset=0 phase=0"          (phase in seconds, like square)
//   "ramp start=0 slope=1 min=-10 max=10 period=0"           (period > 0: sawtooth)
//   "noise mean=0 sigma=0.1 seed=1 period=0.001"             (Gaussian, a new sample each period)
//   "csv file=path/to/trace.csv loop=0 step=0"
//   "output slave=DO1 channel=3"             another slave's digital output channel (1/0);
//                                            0 until the topology builder binds it
// Times are seconds of simulation time. A CSV file has one "time,value" row per line (seconds,
// ascending; blank lines, '#' comments and a non-numeric header line are skipped); values are
// interpolated linearly (step=1: held until the next row), held after the last row or repeated
// (loop=1, period = last time). An unknown parameter is an error naming the closest valid one.
//
// Noise is a pure function of time: sample k = floor(t / period) (in whole nanoseconds) is a normal deviate made from
// a counter-based hash (splitmix64) of k and the seed by the Box-Muller transform, so a seed
// gives the same sequence in every run and on every machine (no library distribution whose
// output differs between standard library versions) and value(t) keeps no state.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/result.hpp"
#include "protocol/time.hpp"

namespace ecsim::slavesim::devices {

// Where a kOutput signal reads its value (another slave's output channel), bound once the whole
// network is built (topology/network_builder.cpp). value() must not allocate.
class SignalSource {
 public:
  virtual ~SignalSource() = default;
  virtual double value(SimTime t) const = 0;
};

class Signal {
 public:
  enum class Kind : std::uint8_t {
    kConstant, kStep, kSquare, kSine, kRamp, kNoise, kTable, kOutput
  };
  struct Point {
    double time{0.0};  // seconds
    double value{0.0};
  };

  Signal() = default;
  static Signal constant(double value);
  // `before` until t = at (seconds), `after` from then on.
  static Signal step(double at, double before, double after);
  // mean + sigma * N(0, 1), a new sample each `period` seconds (at least 1 ns), sample k the same
  // for the same seed.
  static Signal noise(double mean, double sigma, std::uint64_t seed, double period);
  // `high` for the first `duty` fraction of each period, `low` for the rest; periods start at
  // t = phase (seconds).
  static Signal square(double period, double low, double high, double duty = 0.5,
                       double phase = 0.0);
  // offset + amplitude * sin(2 pi f (t - phase)).
  static Signal sine(double amplitude, double frequencyHz, double offset = 0.0, double phase = 0.0);
  // start + slope * t, clamped to [min, max]; with period > 0 it restarts every period.
  static Signal ramp(double start, double slope, double min = -1e300, double max = 1e300,
                     double period = 0.0);
  // Points must be ascending in time (checked by fromCsv; here the caller's duty).
  static Signal table(std::vector<Point> points, bool loop = false, bool step = false);
  // Output channel `channel` (1-based) of the slave named `slave`; unbound until bind().
  static Signal output(std::string slave, unsigned channel);
  // A kOutput signal reading `source`.
  Signal bind(std::shared_ptr<const SignalSource> source) const {
    Signal s = *this;
    s.source_ = std::move(source);
    return s;
  }
  const std::string& outputSlave() const { return outputSlave_; }
  unsigned outputChannel() const { return static_cast<unsigned>(a_); }
  // Reads a "time,value" CSV file; errors name the file and line.
  static Result<Signal> fromCsv(const std::filesystem::path& path, bool loop = false,
                                bool step = false);

  Kind kind() const { return kind_; }
  // The value at simulation time t. Time counts from the signal's origin: the simulation's
  // start for a signal of the topology, the instant a scenario or control command set it.
  double value(SimTime t) const;
  // This signal with its time counted from `origin`.
  Signal startingAt(SimTime origin) const {
    Signal s = *this;
    s.origin_ = origin;
    return s;
  }
  const std::vector<Point>& points() const { return points_; }

 private:
  double tableValue(double seconds) const;

  Kind kind_{Kind::kConstant};
  double noiseValue(SimTime elapsed) const;

  double a_{0.0};  // constant: value; step: before; square: low; sine: amplitude; ramp: start;
                   // noise: mean
  double b_{0.0};  // step: after; square: high; sine: frequency; ramp: slope; noise: sigma
  double c_{0.0};  // step: at; square: duty; sine: offset; ramp: min
  double d_{0.0};  // square/sine: phase; ramp: max
  double period_{0.0};
  std::uint64_t seed_{0};  // noise
  SimTime origin_{0};
  bool loop_{false};
  bool step_{false};
  std::vector<Point> points_;
  std::string outputSlave_;                        // kOutput
  std::shared_ptr<const SignalSource> source_;     // kOutput, once bound
};

// Parses the text form above. Relative CSV paths are resolved against `baseDir`.
Result<Signal> parseSignal(std::string_view text, const std::filesystem::path& baseDir = {});

}  // namespace ecsim::slavesim::devices
