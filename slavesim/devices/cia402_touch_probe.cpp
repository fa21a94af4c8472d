#include "slavesim/devices/cia402_touch_probe.hpp"

#include <cmath>

namespace ecsim::slavesim::devices {
namespace {

constexpr std::uint16_t kFunction = 0x60B8;
constexpr std::uint16_t kStatus = 0x60B9;
constexpr std::uint16_t kFirstPosition = 0x60BA;  // 0x60BA-0x60BD
constexpr unsigned kProbeShift = 8;               // probe 2's bits in 0x60B8 / 0x60B9

// 0x60B8 bits of one probe (shifted by kProbeShift for probe 2).
constexpr std::uint16_t kEnable = 1u << 0;
constexpr std::uint16_t kContinuous = 1u << 1;
constexpr std::uint16_t kSourceMask = 3u << 2;
constexpr std::uint16_t kSourceInput = 0u << 2;
constexpr std::uint16_t kSourceZeroImpulse = 1u << 2;
constexpr std::uint16_t kSamplePositive = 1u << 4;
constexpr std::uint16_t kSampleNegative = 1u << 5;
// 0x60B9 bits of one probe.
constexpr std::uint16_t kStatusEnabled = 1u << 0;
constexpr std::uint16_t kStatusPositive = 1u << 1;
constexpr std::uint16_t kStatusNegative = 1u << 2;

std::int64_t floorDiv(std::int64_t a, std::int64_t b) {
  const std::int64_t q = a / b;
  return (a % b != 0 && (a < 0) != (b < 0)) ? q - 1 : q;
}

std::int32_t wrap32(std::int64_t v) {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(static_cast<std::uint64_t>(v)));
}

}  // namespace

void TouchProbe::bind(coe::ObjectDictionary& od,
                      const std::function<std::uint16_t(std::uint16_t)>& at) {
  function_ = ObjectRef(od, at(kFunction), 0);
  status_ = ObjectRef(od, at(kStatus), 0);
  for (unsigned i = 0; i < positions_.size(); ++i) {
    positions_[i] = ObjectRef(od, at(static_cast<std::uint16_t>(kFirstPosition + i)), 0);
  }
}

void TouchProbe::takeFunction() {
  if (!present()) return;
  functionWord_ = static_cast<std::uint16_t>(function_.getUnsigned());
  for (unsigned n = 0; n < probes_.size(); ++n) {
    Probe& p = probes_[n];
    const auto f = static_cast<std::uint16_t>(functionWord_ >> (kProbeShift * n));
    const auto rising = static_cast<std::uint16_t>(f & ~p.previousFunction & 0xFF);
    p.previousFunction = f;
    p.enabled = (f & kEnable) != 0;
    if (!p.enabled || (rising & kEnable) != 0) {
      p.stored[0] = p.stored[1] = false;  // disabled, or (re-)enabled: nothing stored yet
      continue;
    }
    // Clearing an edge's sample bit clears what it stored (the master's handshake); setting it
    // again re-arms it.
    if ((f & kSamplePositive) == 0) p.stored[0] = false;
    if ((f & kSampleNegative) == 0) p.stored[1] = false;
  }
}

void TouchProbe::edge(unsigned n, bool positive, double counts) {
  Probe& p = probes_[n];
  const auto f = static_cast<std::uint16_t>(functionWord_ >> (kProbeShift * n));
  if (!p.enabled || (f & (positive ? kSamplePositive : kSampleNegative)) == 0) return;
  const unsigned e = positive ? 0 : 1;
  if (p.stored[e] && (f & kContinuous) == 0) return;  // first event only
  p.stored[e] = true;
  p.position[e] = counts;
}

void TouchProbe::sense(bool switchBefore, bool switchAfter, double switchCounts,
                       std::int64_t countsBefore, std::int64_t countsAfter,
                       std::uint32_t countsPerTurn) {
  if (!present() || (!probes_[0].enabled && !probes_[1].enabled)) return;
  for (unsigned n = 0; n < probes_.size(); ++n) {
    const auto source = static_cast<std::uint16_t>((functionWord_ >> (kProbeShift * n)) &
                                                   kSourceMask);
    if (source == kSourceInput) {
      // Probe 1's input is the home switch; probe 2's is not wired.
      if (n == 0 && switchBefore != switchAfter) edge(n, switchAfter, switchCounts);
    } else if (source == kSourceZeroImpulse && countsPerTurn > 0) {
      const std::int64_t turn = countsPerTurn;
      const std::int64_t before = floorDiv(countsBefore, turn);
      const std::int64_t after = floorDiv(countsAfter, turn);
      if (before == after) continue;
      // The pulse at the turn boundary passed (both its edges, at the same place).
      const double at = static_cast<double>((after > before ? after : before) * turn);
      edge(n, true, at);
      edge(n, false, at);
    }
  }
}

std::uint16_t TouchProbe::status() const {
  std::uint16_t s = 0;
  for (unsigned n = 0; n < probes_.size(); ++n) {
    const Probe& p = probes_[n];
    std::uint16_t bits = p.enabled ? kStatusEnabled : 0;
    if (p.enabled && p.stored[0]) bits |= kStatusPositive;
    if (p.enabled && p.stored[1]) bits |= kStatusNegative;
    s = static_cast<std::uint16_t>(s | (bits << (kProbeShift * n)));
  }
  return s;
}

void TouchProbe::publish(double offset, double countsPerUnit) {
  if (!present()) return;
  status_.set(status());
  for (unsigned n = 0; n < probes_.size(); ++n) {
    for (unsigned e = 0; e < 2; ++e) {
      if (!probes_[n].stored[e]) continue;
      positions_[2 * n + e].set(
          wrap32(std::llround((probes_[n].position[e] + offset) / countsPerUnit)));
    }
  }
}

}  // namespace ecsim::slavesim::devices
