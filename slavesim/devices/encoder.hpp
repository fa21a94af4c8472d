// A rotary position encoder as a drive reads it: a shaft angle becomes counts.
//
//   resolution     countsPerRevolution counts per shaft turn;
//   kind           incremental: counts from 0 at the position where it was switched on, no
//                  wrap of its own (the drive's 32-bit position wraps);
//                  absolute single-turn: the angle within one turn, 0 ... cpr - 1;
//                  absolute multi-turn: turns * cpr + angle within the turn, the turns counted
//                  in a signed range of multiTurnBits bits (wrapping from the highest turn to
//                  the lowest); the count is a function of the shaft angle alone, so it survives
//                  switching off (the shaft angle is what a state file keeps);
//   quantisation   the reading is floor(counts / step) * step (step = 1: every count);
//   noise          optional Gaussian noise (standard deviation in counts) from a seeded
//                  generator: the same seed gives the same sequence of readings;
//   fault          injected from outside (setFault): the reading freezes at its last value
//                  and the drive reading it faults with 0x7305 until the fault is cleared.
#pragma once

#include <cstdint>
#include <random>

namespace ecsim::slavesim::devices {

enum class EncoderKind : std::uint8_t { kIncremental, kAbsoluteSingleTurn, kAbsoluteMultiTurn };

struct EncoderParams {
  EncoderKind kind{EncoderKind::kAbsoluteMultiTurn};
  std::uint32_t countsPerRevolution{131072};  // 17 bits
  unsigned multiTurnBits{15};                 // 17 + 15 bits: the whole 32-bit position range
  std::uint32_t quantisationStep{1};          // counts
  double noiseCounts{0.0};                    // standard deviation, counts; 0: no noise
  std::uint64_t seed{1};
};

struct EncoderReading {
  // Continuous count (quantised, with noise) since the encoder's zero, never wrapped: what a
  // drive's position loop integrates.
  std::int64_t counts{0};
  // The value the encoder reports, wrapped as its kind wraps.
  std::int64_t reported{0};
  std::int64_t turns{0};        // multi-turn: the (wrapped) turn count; otherwise whole turns
  std::uint32_t singleTurn{0};  // position within the turn, 0 ... cpr - 1
};

class Encoder {
 public:
  explicit Encoder(const EncoderParams& params);

  const EncoderParams& params() const { return params_; }
  bool absolute() const { return params_.kind != EncoderKind::kIncremental; }
  // Switching on: an incremental encoder takes the present angle as its zero.
  void powerOn(double shaftAngle);
  // Counts for a shaft angle (rad) without quantisation or noise (zero applied).
  double exactCounts(double shaftAngle) const;
  // One reading of the shaft at `shaftAngle` (draws noise when configured).
  EncoderReading read(double shaftAngle);
  // Shaft angle (rad) at which the encoder would read `counts` (inverse of exactCounts).
  double angleOf(double counts) const;

  // Fault injection: a faulted encoder reports the last reading it took before the fault.
  void setFault(bool faulted) { faulted_ = faulted; }
  bool faulted() const { return faulted_; }

 private:
  EncoderParams params_;
  bool faulted_{false};
  EncoderReading last_{};
  double zeroCounts_{0.0};
  std::mt19937_64 rng_;
  std::normal_distribution<double> noise_{0.0, 1.0};
};

}  // namespace ecsim::slavesim::devices
