#include "slavesim/devices/encoder.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace ecsim::slavesim::devices {
namespace {

// Beyond this the count would not fit the 64-bit reading (about 7e13 turns at 17 bits).
constexpr double kMaxCounts = 9.0e18;

// Floor division and modulo for a positive divisor.
std::int64_t floorDiv(std::int64_t a, std::int64_t b) {
  const std::int64_t q = a / b;
  return (a % b != 0 && a < 0) ? q - 1 : q;
}

}  // namespace

Encoder::Encoder(const EncoderParams& params) : params_(params), rng_(params.seed) {
  params_.countsPerRevolution = std::max<std::uint32_t>(params_.countsPerRevolution, 1);
  params_.quantisationStep = std::max<std::uint32_t>(params_.quantisationStep, 1);
  params_.multiTurnBits = std::min(params_.multiTurnBits, 40u);
}

void Encoder::powerOn(double shaftAngle) {
  zeroCounts_ = 0.0;
  if (params_.kind == EncoderKind::kIncremental) zeroCounts_ = exactCounts(shaftAngle);
}

double Encoder::exactCounts(double shaftAngle) const {
  return shaftAngle / (2.0 * std::numbers::pi) * params_.countsPerRevolution - zeroCounts_;
}

double Encoder::angleOf(double counts) const {
  return (counts + zeroCounts_) / params_.countsPerRevolution * (2.0 * std::numbers::pi);
}

EncoderReading Encoder::read(double shaftAngle) {
  if (faulted_) return last_;
  double c = exactCounts(shaftAngle);
  if (params_.noiseCounts > 0.0) c += params_.noiseCounts * noise_(rng_);
  c = std::clamp(c, -kMaxCounts, kMaxCounts);
  const auto step = static_cast<std::int64_t>(params_.quantisationStep);
  const auto whole = static_cast<std::int64_t>(std::floor(c));
  EncoderReading r;
  r.counts = floorDiv(whole, step) * step;
  const auto cpr = static_cast<std::int64_t>(params_.countsPerRevolution);
  r.turns = floorDiv(r.counts, cpr);
  r.singleTurn = static_cast<std::uint32_t>(r.counts - r.turns * cpr);
  switch (params_.kind) {
    case EncoderKind::kIncremental:
      r.reported = r.counts;
      break;
    case EncoderKind::kAbsoluteSingleTurn:
      r.reported = r.singleTurn;
      break;
    case EncoderKind::kAbsoluteMultiTurn: {
      const std::int64_t range = std::int64_t{1} << params_.multiTurnBits;
      const std::int64_t half = range / 2;
      // Turns into [-half, half): the counter wraps from the highest turn to the lowest.
      r.turns = floorDiv(r.turns + half, range) * -range + r.turns;
      r.reported = r.turns * cpr + r.singleTurn;
      break;
    }
  }
  last_ = r;
  return r;
}

}  // namespace ecsim::slavesim::devices
