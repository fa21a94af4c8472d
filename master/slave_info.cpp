#include "master/slave_info.hpp"

#include <cstdio>

namespace ecsim::master {

std::string SlaveInfo::label() const {
  char buf[32];
  std::snprintf(buf, sizeof buf, "slave %zu (0x%04X", position, station);
  std::string s = buf;
  if (!displayName().empty()) s += " '" + displayName() + "'";
  return s + ")";
}

std::string describeAlStatus(std::uint16_t alStatus) {
  auto state = alStateFromRaw(alStatus);
  std::string s;
  if (state) {
    s = std::string(toString(*state));
  } else {
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%04X", alStatus & kAlStateMask);
    s = buf;
  }
  if ((alStatus & kAlErrorFlag) != 0) s += "+ERROR";
  return s;
}

std::string describeAlStatusCode(std::uint16_t code) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%04X", code);
  return std::string(buf) + " (" + std::string(alStatusCodeText(code)) + ")";
}

std::optional<std::uint16_t> explicitDeviceId(std::uint16_t alStatus, std::uint16_t alStatusCode) {
  const std::uint16_t shown = alStatus & (reg::al::kDeviceIdentification | kAlErrorFlag);
  if (shown != reg::al::kDeviceIdentification) return std::nullopt;
  return alStatusCode;
}

std::string describeIdentity(const SiiIdentity& identity) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "vendor 0x%08X product 0x%08X revision 0x%08X", identity.vendorId,
                identity.productCode, identity.revision);
  return buf;
}

}  // namespace ecsim::master
