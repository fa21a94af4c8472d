// The free-running local clock of an ESC and its drift control loop (ESC datasheet section I
// §9.1: local time from the ESC's own oscillator; system time = local time + offset 0x0920;
// a write of the reference system time to 0x0910 (ARMW/FRMW, or BWR/FPWR) is compared with
// the local copy, and the filtered difference slows down or speeds up the local clock).
//
// The clock is a piecewise-linear function of global (simulation) time: local(t) =
// base + (t - tBase) * (1 + rate), where rate = physical drift + control correction. It is a
// pure function between corrections, so times can be asked out of order within a frame.
#pragma once

#include <cstdint>

#include "protocol/time.hpp"

namespace ecsim::slavesim {

class DcClock {
 public:
  // offset: local time at global time 0; driftPpm: the oscillator's error (+ runs fast).
  void configure(SimTime offset, double driftPpm);

  SimTime localTime(SimTime global) const;
  // Global time at which the local clock reads `local` (inverse of localTime).
  SimTime globalTime(SimTime local) const;

  // A system time was written to 0x0910 at global time `global`. `localSystemTime` is the
  // ESC's own system time (local + offset) at that moment, `received` the written value plus
  // the propagation delay 0x0928. Runs one step of the control loop and returns the
  // difference local - received (what 0x092C reports).
  std::int64_t onSystemTimeWrite(SimTime global, SimTime localSystemTime, SimTime received,
                                 unsigned filterDepth);
  // 0x0930 write: resets the control loop (speed counter start).
  void resetControl();
  // Power-up at global time `global`: the local time starts again from 0 (the oscillator's
  // drift stays what it is), the control loop from scratch.
  void restart(SimTime global);

  double ratePpm() const { return (driftPpb_ + correctionPpb_) * 1e-3; }
  double correctionPpm() const { return correctionPpb_ * 1e-3; }

 private:
  void rebase(SimTime global);

  SimTime tBase_{0};
  SimTime localBase_{0};
  double driftPpb_{0.0};
  double correctionPpb_{0.0};
  double integralPpb_{0.0};
  SimTime lastWrite_{0};
  bool haveLastWrite_{false};
};

// The system time difference register 0x092C for a difference `diff` (local copy minus
// received time): bit 31 set when the local copy is smaller, bits 30-0 the magnitude, held at
// 0x7FFFFFFF beyond it (datasheet section II, 0x092C). Any 64-bit difference, INT64_MIN
// included: a master may write any time.
std::uint32_t systemTimeDifferenceRegister(std::int64_t diff);

}  // namespace ecsim::slavesim
