// The touch probe of a CiA 402 drive (ETG.6010 / IEC 61800-7-201 objects 0x60B8-0x60BD): two
// probes, each latching the position at the positive and/or negative edge of its trigger signal.
//
//   0x60B8 touch probe function (per probe n = 1, 2 at bit offset 8 (n - 1)):
//     bit 0 enable, bit 1 0: first event / 1: continuous, bits 2-3 trigger source (00 the
//     probe's external input, 01 the encoder's zero impulse), bit 4 sample at the positive
//     edge, bit 5 at the negative edge
//   0x60B9 touch probe status: bit 0 enabled, bit 1 positive edge stored, bit 2 negative edge
//     stored (probe 2: bits 8-10)
//   0x60BA / 0x60BB probe 1 position at the positive / negative edge, 0x60BC / 0x60BD probe 2
//
// ecsim wires probe 1's external input to the drive's home switch; probe 2 has none (only its
// zero-impulse source triggers). The zero impulse comes once per motor turn, where the encoder
// count passes a multiple of its resolution. A latched position is where the edge happened
// (the switch position, the turn boundary), in the drive's position units. First-event mode
// stores each edge once; clearing the edge's sample bit (or the probe's enable bit) clears what
// was stored and setting it again re-arms it. Continuous mode stores every edge.
#pragma once

#include <array>
#include <cstdint>
#include <functional>

#include "slavesim/coe/object_dictionary.hpp"
#include "slavesim/devices/object_ref.hpp"

namespace ecsim::slavesim::devices {

class TouchProbe {
 public:
  // `at` moves an index to the drive's axis (ETG.6010 multi-axis layout).
  void bind(coe::ObjectDictionary& od, const std::function<std::uint16_t(std::uint16_t)>& at);
  bool present() const { return function_.present(); }

  // Takes 0x60B8 (with the drive's outputs, once a cycle).
  void takeFunction();
  // One substep of the motor: the home switch and the encoder count before and after it.
  // `switchCounts` is where the home switch changes; `countsPerTurn` the encoder resolution.
  void sense(bool switchBefore, bool switchAfter, double switchCounts, std::int64_t countsBefore,
             std::int64_t countsAfter, std::uint32_t countsPerTurn);
  // Writes 0x60B9-0x60BD: positions (encoder counts) plus `offset`, divided by `countsPerUnit`.
  void publish(double offset, double countsPerUnit);

  std::uint16_t status() const;

 private:
  struct Probe {
    bool enabled{false};
    bool stored[2]{false, false};    // positive, negative edge
    double position[2]{0.0, 0.0};    // encoder counts
    std::uint16_t previousFunction{0};
  };
  void edge(unsigned probe, bool positive, double counts);

  ObjectRef function_, status_;
  std::array<ObjectRef, 4> positions_;  // 0x60BA-0x60BD
  std::array<Probe, 2> probes_;
  std::uint16_t functionWord_{0};
};

}  // namespace ecsim::slavesim::devices
