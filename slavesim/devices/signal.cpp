#include "slavesim/devices/signal.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <numbers>
#include <sstream>

#include "protocol/closest_name.hpp"
#include "protocol/read_file.hpp"

namespace ecsim::slavesim::devices {
namespace {

double seconds(SimTime t) {
  return static_cast<double>(t) / static_cast<double>(kNsPerSecond);
}

// Fractional part of x / period in [0, 1).
double phaseOf(double x, double period) {
  const double f = x / period - std::floor(x / period);
  return f >= 1.0 ? 0.0 : f;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r')) {
    s.remove_prefix(1);
  }
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) {
    s.remove_suffix(1);
  }
  return s;
}

bool parseDouble(std::string_view s, double& out) {
  s = trim(s);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  const char* end = s.data() + s.size();
  auto [ptr, ec] = std::from_chars(s.data(), end, out);
  return ec == std::errc() && ptr == end && std::isfinite(out);
}

// splitmix64's finaliser (Steele, Lea, Flood, "Fast splittable pseudorandom number generators",
// OOPSLA 2014): a bijective mix of a 64-bit counter, the hash of a counter-based generator.
std::uint64_t mix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

// The top 53 bits of a hash as a double in [0, 1).
double unitInterval(std::uint64_t h) {
  constexpr double kTwoToMinus53 = 1.0 / 9007199254740992.0;
  return static_cast<double>(h >> 11) * kTwoToMinus53;
}

}  // namespace

Signal Signal::constant(double value) {
  Signal s;
  s.kind_ = Kind::kConstant;
  s.a_ = value;
  return s;
}

Signal Signal::step(double at, double before, double after) {
  Signal s;
  s.kind_ = Kind::kStep;
  s.a_ = before;
  s.b_ = after;
  s.c_ = at;
  return s;
}

Signal Signal::noise(double mean, double sigma, std::uint64_t seed, double period) {
  Signal s;
  s.kind_ = Kind::kNoise;
  s.a_ = mean;
  s.b_ = sigma;
  s.seed_ = seed;
  s.period_ = period;
  return s;
}

Signal Signal::square(double period, double low, double high, double duty, double phase) {
  Signal s;
  s.kind_ = Kind::kSquare;
  s.period_ = period;
  s.a_ = low;
  s.b_ = high;
  s.c_ = std::clamp(duty, 0.0, 1.0);
  s.d_ = phase;
  return s;
}

Signal Signal::sine(double amplitude, double frequencyHz, double offset, double phase) {
  Signal s;
  s.kind_ = Kind::kSine;
  s.a_ = amplitude;
  s.b_ = frequencyHz;
  s.c_ = offset;
  s.d_ = phase;
  return s;
}

Signal Signal::ramp(double start, double slope, double min, double max, double period) {
  Signal s;
  s.kind_ = Kind::kRamp;
  s.a_ = start;
  s.b_ = slope;
  s.c_ = min;
  s.d_ = max;
  s.period_ = period;
  return s;
}

Signal Signal::table(std::vector<Point> points, bool loop, bool step) {
  Signal s;
  s.kind_ = Kind::kTable;
  s.points_ = std::move(points);
  s.loop_ = loop;
  s.step_ = step;
  return s;
}

Signal Signal::output(std::string slave, unsigned channel) {
  Signal s;
  s.kind_ = Kind::kOutput;
  s.a_ = channel;
  s.outputSlave_ = std::move(slave);
  return s;
}

Result<Signal> Signal::fromCsv(const std::filesystem::path& path, bool loop, bool step) {
  // Read whole and at once: a FIFO or a device here would hold the serve loop (ecsim ctl input).
  ECSIM_ASSIGN_OR_RETURN(const std::string content, readRegularFile(path, kMaxTextFileBytes));
  std::istringstream in(content);
  std::vector<Point> points;
  std::string line;
  int lineNo = 0;
  while (std::getline(in, line)) {
    ++lineNo;
    std::string_view text = trim(line);
    if (text.empty() || text.front() == '#') continue;
    const std::size_t comma = text.find_first_of(",;");
    Point p;
    const bool ok = comma != std::string_view::npos && parseDouble(text.substr(0, comma), p.time) &&
                    parseDouble(text.substr(comma + 1), p.value);
    if (!ok) {
      if (points.empty() && lineNo == 1) continue;  // a header line
      return makeError(ErrorCode::kParse, path.string() + ":" + std::to_string(lineNo) +
                                              ": expected \"time,value\" (seconds, number)");
    }
    if (!points.empty() && p.time < points.back().time) {
      return makeError(ErrorCode::kParse,
                       path.string() + ":" + std::to_string(lineNo) + ": time goes backwards");
    }
    points.push_back(p);
  }
  if (points.empty()) {
    return makeError(ErrorCode::kParse, path.string() + ": no \"time,value\" rows");
  }
  return table(std::move(points), loop, step);
}

double Signal::tableValue(double t) const {
  if (points_.empty()) return 0.0;
  const double first = points_.front().time;
  const double last = points_.back().time;
  if (loop_ && last > first && t > last)
    t = first + phaseOf(t - first, last - first) * (last - first);
  if (t <= first) return points_.front().value;
  if (t >= last) return points_.back().value;
  auto next = std::upper_bound(points_.begin(), points_.end(), t,
                               [](double x, const Point& p) { return x < p.time; });
  const Point& b = *next;
  const Point& a = *(next - 1);
  if (step_ || b.time <= a.time) return a.value;
  return a.value + (b.value - a.value) * (t - a.time) / (b.time - a.time);
}

double Signal::noiseValue(SimTime elapsed) const {
  // Sample k counted in whole nanoseconds: t / period in doubles puts t = k periods now and
  // then just below k (1 ms / 0.001).
  const auto periodNs = static_cast<SimTime>(std::llround(period_ * kNsPerSecond));
  if (periodNs <= 0) return a_;
  const auto k = static_cast<std::uint64_t>(elapsed / periodNs);
  // Sample k's two uniform numbers: the hash of (seed, 2k) and of (seed, 2k + 1).
  const std::uint64_t stream = mix64(seed_);
  const double u1 = 1.0 - unitInterval(mix64(stream ^ (2 * k)));  // (0, 1]: log(u1) finite
  const double u2 = unitInterval(mix64(stream ^ (2 * k + 1)));
  // Box-Muller: sqrt(-2 ln u1) cos(2 pi u2) is a standard normal deviate.
  const double z = std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  return a_ + b_ * z;
}

double Signal::value(SimTime t) const {
  const double s = seconds(saturatingSub(t, origin_));
  switch (kind_) {
    case Kind::kConstant:
      return a_;
    case Kind::kStep:
      return s < c_ ? a_ : b_;
    case Kind::kSquare:
      if (period_ <= 0.0) return a_;
      return phaseOf(s - d_, period_) < c_ ? b_ : a_;
    case Kind::kSine:
      return c_ + a_ * std::sin(2.0 * std::numbers::pi * b_ * (s - d_));
    case Kind::kRamp: {
      const double x = period_ > 0.0 ? phaseOf(s, period_) * period_ : s;
      return std::clamp(a_ + b_ * x, c_, d_);
    }
    case Kind::kNoise:
      return noiseValue(saturatingSub(t, origin_));
    case Kind::kTable:
      return tableValue(s);
    case Kind::kOutput:
      return source_ ? source_->value(t) : 0.0;
  }
  return 0.0;
}

Result<Signal> parseSignal(std::string_view text, const std::filesystem::path& baseDir) {
  text = trim(text);
  double number = 0.0;
  if (parseDouble(text, number)) return Signal::constant(number);
  const std::size_t space = text.find(' ');
  const std::string kind(text.substr(0, space));
  std::map<std::string, std::string, std::less<>> args;
  std::string_view rest = space == std::string_view::npos ? "" : text.substr(space + 1);
  while (!(rest = trim(rest)).empty()) {
    const std::size_t end = rest.find(' ');
    std::string_view item = rest.substr(0, end);
    rest = end == std::string_view::npos ? "" : rest.substr(end + 1);
    const std::size_t eq = item.find('=');
    if (eq == std::string_view::npos || eq == 0) {
      return makeError(ErrorCode::kParse, "signal \"" + std::string(text) + "\": '" +
                                              std::string(item) + "' is not name=value");
    }
    args[std::string(item.substr(0, eq))] = std::string(item.substr(eq + 1));
  }
  std::string problem;
  std::vector<std::string_view> known;  // the kind's parameters, for the closest to a misspelt one
  auto num = [&](const char* name, double fallback) {
    known.emplace_back(name);
    auto it = args.find(name);
    if (it == args.end()) return fallback;
    double v = 0.0;
    if (!parseDouble(it->second, v)) problem = std::string(name) + "=" + it->second;
    args.erase(it);
    return v;
  };
  Signal out;
  if (kind == "constant") {
    out = Signal::constant(num("value", 0.0));
  } else if (kind == "step") {
    const double at = num("at", 0.0);
    const double before = num("before", 0.0);
    out = Signal::step(at, before, num("after", 1.0));
  } else if (kind == "noise") {
    constexpr double kMaxSeed = 9007199254740992.0;  // 2^53: every integer below is exact
    const double mean = num("mean", 0.0);
    const double sigma = num("sigma", 1.0);
    const double seed = num("seed", 0.0);
    const double period = num("period", 0.001);
    out = Signal::noise(mean, sigma, static_cast<std::uint64_t>(seed >= 0.0 ? seed : 0.0), period);
    if (problem.empty() && sigma < 0.0) problem = "sigma must be >= 0";
    if (problem.empty() && !(period * kNsPerSecond >= 1.0)) problem = "period must be >= 1e-9";
    if (problem.empty() && (seed < 0.0 || seed >= kMaxSeed || seed != std::floor(seed))) {
      problem = "seed must be an integer in [0, 2^53)";
    }
  } else if (kind == "square") {
    const double period = num("period", 1.0);
    const double low = num("low", 0.0);
    const double high = num("high", 1.0);
    const double duty = num("duty", 0.5);
    out = Signal::square(period, low, high, duty, num("phase", 0.0));
    if (period <= 0.0) problem = "period must be > 0";
  } else if (kind == "sine") {
    const double amplitude = num("amplitude", 1.0);
    const double frequency = num("frequency", 1.0);
    const double offset = num("offset", 0.0);
    out = Signal::sine(amplitude, frequency, offset, num("phase", 0.0));
  } else if (kind == "ramp") {
    const double start = num("start", 0.0);
    const double slope = num("slope", 1.0);
    const double min = num("min", -1e300);
    const double max = num("max", 1e300);
    out = Signal::ramp(start, slope, min, max, num("period", 0.0));
    if (min > max) problem = "min > max";
  } else if (kind == "csv") {
    auto file = args.find("file");
    if (file == args.end()) {
      return makeError(ErrorCode::kParse, "signal \"" + std::string(text) + "\": csv needs file=");
    }
    known.emplace_back("file");
    std::filesystem::path path = file->second;
    args.erase(file);
    if (path.is_relative() && !baseDir.empty()) path = baseDir / path;
    const bool loop = num("loop", 0.0) != 0.0;
    const bool step = num("step", 0.0) != 0.0;
    if (problem.empty() && args.empty()) return Signal::fromCsv(path, loop, step);
  } else if (kind == "output") {
    known.emplace_back("slave");
    auto slave = args.find("slave");
    const double channel = num("channel", 0.0);
    if (slave == args.end() || slave->second.empty() || channel < 1 || channel > 255 ||
        channel != std::floor(channel)) {
      return makeError(ErrorCode::kParse, "signal \"" + std::string(text) +
                                              "\": output needs slave=NAME and channel=1..255");
    }
    out = Signal::output(slave->second, static_cast<unsigned>(channel));
    args.erase(slave);
  } else {
    return makeError(ErrorCode::kParse,
                     "signal \"" + std::string(text) + "\": unknown kind '" + kind +
                         "' (constant, step, square, sine, ramp, noise, csv, output or a number)" +
                         didYouMean(kind, {"constant", "step", "square", "sine", "ramp", "noise",
                                           "csv", "output"}));
  }
  if (problem.empty() && !args.empty()) {
    problem = unknownNameText("parameter", args.begin()->first, known, " of " + kind);
  }
  if (!problem.empty()) {
    return makeError(ErrorCode::kParse, "signal \"" + std::string(text) + "\": " + problem);
  }
  return out;
}

}  // namespace ecsim::slavesim::devices
