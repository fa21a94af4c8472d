// The files a simulated slave keeps for FoE (ETG.1000.6 §5.7): in memory, per slave, shared by
// the FoE server (which reads and writes them) and the device's power-cycle hook (which
// installs a firmware image written in BOOT).
//
// Firmware (ecsim's convention, docs/devices.md "Firmware update over FoE"): a file written
// completely while the slave was in BOOT is the firmware image it boots next. At the next power
// cycle (Slave::powerOn -> Device::coldStart) the image is installed: when it carries the ASCII
// marker "ECSIM-SW-VERSION=" followed by a version text (up to a NUL, CR, LF or the end, at
// most kMaxVersionLength characters), the device reports that text as its software version
// (CiA 301 object 0x100A) from then on; an image without the marker changes nothing.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/bytes.hpp"

namespace ecsim::slavesim::foe {

inline constexpr std::string_view kSoftwareVersionMarker = "ECSIM-SW-VERSION=";
inline constexpr std::size_t kMaxVersionLength = 64;

// The version text an image carries after kSoftwareVersionMarker, if any.
std::optional<std::string> softwareVersionIn(ConstBytes image);

class FoeFiles {
 public:
  const std::vector<std::uint8_t>* find(const std::string& name) const;
  void store(const std::string& name, std::vector<std::uint8_t> data, bool writtenInBoot);
  const std::map<std::string, std::vector<std::uint8_t>>& all() const { return files_; }
  std::size_t totalBytes() const;

  // The name of the last file completely written in BOOT, waiting for the next power cycle.
  const std::optional<std::string>& pendingFirmware() const { return pending_; }
  // Called at a power cycle: the pending image becomes the running firmware.
  void installPending();
  // The software version the running firmware reports (set by installPending from an image
  // with the marker; empty: the version the device was built with).
  const std::optional<std::string>& installedVersion() const { return installedVersion_; }

 private:
  std::map<std::string, std::vector<std::uint8_t>> files_;
  std::optional<std::string> pending_;
  std::optional<std::string> installedVersion_;
};

}  // namespace ecsim::slavesim::foe
