#include "slavesim/generic_slave.hpp"

#include "protocol/sii.hpp"

namespace ecsim::slavesim {

std::unique_ptr<Slave> makeGenericSlave(const std::string& name, std::uint32_t serial,
                                        const EscType& esc) {
  SiiContents c;
  c.config.pdiControl = 0x0100;  // no PDI, ESC configuration: enhanced link detection off
  c.identity = {kEcsimVendorId, kGenericProductCode, 0x00010000, serial};
  c.sizeField = 1;  // 2 kbit
  c.strings = {name, "ecsim generic"};
  SiiGeneral g;
  g.nameIndex = 1;
  g.groupIndex = 2;
  g.physicalPorts = 0x0011;  // ports 0 and 1: MII
  c.general = g;
  auto image = encodeSii(c);
  // The contents above always fit in 2 kbit; an error here is a programming error.
  std::vector<std::uint8_t> bytes =
      image.ok() ? std::move(image).value() : std::vector<std::uint8_t>(256, 0xFF);
  return std::make_unique<Slave>(name, esc, std::move(bytes), SlaveProfile{});
}

}  // namespace ecsim::slavesim
