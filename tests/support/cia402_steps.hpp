// The CiA 402 power state machine driven through a master's process-data variables, as the
// vendor drive tests step it (IEC 61800-7-201 statusword table): the controlword is set, the
// target held at the actual position, and the cycle repeated until the statusword masked with
// `mask` reads `want` (at most 50 cycles).
#pragma once

#include <cstdint>

namespace ecsim::testing {

template <typename Variable, typename Cycle>
bool cia402RunUntil(Variable& controlword, Variable& statusword, Variable& target, Variable& actual,
                    Cycle&& cycle, std::uint16_t cw, std::uint16_t mask, std::uint16_t want) {
  controlword.template set<std::uint16_t>(cw);
  for (int i = 0; i < 50; ++i) {
    target.template set<std::int32_t>(actual.template get<std::int32_t>());
    if (!cycle().ok()) return false;
    if ((statusword.template get<std::uint16_t>() & mask) == want) return true;
  }
  return false;
}

}  // namespace ecsim::testing
