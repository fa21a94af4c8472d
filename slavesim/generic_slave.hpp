// A generic slave of our own: an ET1100 with an SII that carries identity, strings and the
// General category but no mailbox and no process data (like a bus coupler). Used by
// `ecsim serve --slaves N` and by tests that need many plain slaves.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "slavesim/slave.hpp"

namespace ecsim::slavesim {

inline constexpr std::uint32_t kEcsimVendorId = 0x00000E5C;  // placeholder id for our devices
inline constexpr std::uint32_t kGenericProductCode = 0x00010001;

std::unique_ptr<Slave> makeGenericSlave(const std::string& name, std::uint32_t serial,
                                        const EscType& esc = kEt1100);

}  // namespace ecsim::slavesim
