// Internals shared by the files that implement the Esc class (esc*.cpp); not part of the API.
#pragma once

#include <array>
#include <cstdint>

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

inline bool isMailbox(std::uint8_t control) {
  return (control & reg::sm::kControlModeMask) == reg::sm::kControlModeMailbox;
}
inline bool isEcatWrite(std::uint8_t control) {
  return (control & reg::sm::kControlDirectionMask) == reg::sm::kControlDirectionWrite;
}

}  // namespace ecsim::slavesim::esc_detail
