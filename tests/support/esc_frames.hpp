// Test helpers for the ESC's frame-error behaviour: a frame sent through a Segment with a
// corruption on one cable (SM channel bytes: smChannelBytes in test_network.hpp).
#pragma once

#include <gtest/gtest.h>

#include "support/test_network.hpp"

namespace ecsim::testing {

// Corrupts the first frame that enters slave `victim` at port 0.
struct CorruptAtEntry : topology::WireFaults {
  std::size_t victim{0};
  bool armed{true};
  bool corrupts(std::size_t s, unsigned port, SimTime) override {
    const bool hit = armed && s == victim && port == 0;
    if (hit) armed = false;
    return hit;
  }
  SimTime extraDelay(std::size_t, unsigned, SimTime) override { return 0; }
};

// Sends one frame that is corrupted on the cable into slave `victim`, then runs the slaves'
// firmware; returns whether the master got the frame back.
inline bool sendCorrupted(topology::Segment& seg, std::size_t victim,
                          const std::vector<DatagramSpec>& specs) {
  CorruptAtEntry faults;
  faults.victim = victim;
  seg.setWireFaults(&faults);
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  FrameBuilder b(
      buf, EthernetHeader{kBroadcastMac, {1, 1, 1, 1, 1, 1}, std::nullopt, kEtherTypeEtherCat});
  std::uint8_t idx = 0;
  for (const auto& s : specs) EXPECT_TRUE(b.add(s.command, idx++, s.address, s.data).ok());
  auto len = b.finish();
  EXPECT_TRUE(len.ok());
  const bool delivered = seg.processFrame(std::span(buf.data(), *len), 0).delivered;
  seg.setWireFaults(nullptr);
  seg.pollSlaves(0);
  return delivered;
}

}  // namespace ecsim::testing
