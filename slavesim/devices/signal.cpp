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

}  // namespace

Signal Signal::constant(double value) {
  Signal s;
  s.kind_ = Kind::kConstant;
  s.a_ = value;
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

double Signal::value(SimTime t) const {
  const double s = seconds(saturatingSub(t, origin_));
  switch (kind_) {
    case Kind::kConstant:
      return a_;
    case Kind::kSquare:
      if (period_ <= 0.0) return a_;
      return phaseOf(s - d_, period_) < c_ ? b_ : a_;
    case Kind::kSine:
      return c_ + a_ * std::sin(2.0 * std::numbers::pi * b_ * (s - d_));
    case Kind::kRamp: {
      const double x = period_ > 0.0 ? phaseOf(s, period_) * period_ : s;
      return std::clamp(a_ + b_ * x, c_, d_);
    }
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
  auto num = [&](const char* name, double fallback) {
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
    std::filesystem::path path = file->second;
    args.erase(file);
    if (path.is_relative() && !baseDir.empty()) path = baseDir / path;
    const bool loop = num("loop", 0.0) != 0.0;
    const bool step = num("step", 0.0) != 0.0;
    if (problem.empty() && args.empty()) return Signal::fromCsv(path, loop, step);
  } else if (kind == "output") {
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
                         "' (constant, square, sine, ramp, csv, output or a number)" +
                         didYouMean(kind, {"constant", "square", "sine", "ramp", "csv", "output"}));
  }
  if (problem.empty() && !args.empty()) problem = "unknown parameter '" + args.begin()->first + "'";
  if (!problem.empty()) {
    return makeError(ErrorCode::kParse, "signal \"" + std::string(text) + "\": " + problem);
  }
  return out;
}

}  // namespace ecsim::slavesim::devices
