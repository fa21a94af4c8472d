// Internals shared by the files that implement the Esc class (esc*.cpp); not part of the API.
#pragma once

#include <array>
#include <cstdint>

#include "protocol/esc_blocks.hpp"
#include "protocol/registers.hpp"
#include "protocol/time.hpp"

namespace ecsim::slavesim::esc_detail {

inline constexpr std::uint16_t kRamStart = reg::kRegisterSpaceEnd;

// DC system time is a 64-bit counter that wraps; offsets come from the master unchecked.
inline SimTime wrapAdd(SimTime a, std::uint64_t b) {
  return static_cast<SimTime>(static_cast<std::uint64_t>(a) + b);
}

inline bool overlaps(std::uint32_t begin, std::uint32_t end, std::uint16_t regBegin,
                     std::uint16_t width) {
  return begin < static_cast<std::uint32_t>(regBegin + width) && regBegin < end;
}

inline bool isMailbox(const SmControl& control) {
  return control.isMailbox();
}
inline bool isEcatWrite(const SmControl& control) {
  return control.isEcatWrite();
}

}  // namespace ecsim::slavesim::esc_detail
