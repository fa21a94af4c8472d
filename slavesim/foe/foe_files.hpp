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
#include <memory>
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
class FoeFile;
// The same for a stored file, read in place (no copy of the image at a power cycle).
std::optional<std::string> softwareVersionIn(const FoeFile& image);

// One file's bytes, kept in chunks of kChunkBytes: appending a packet never moves what is
// already stored. (A std::vector that doubles copied the whole file when it grew, inside the
// mailbox turn of one DATA packet: at 2 MiB it allocated 4 MiB, faulted it in and copied 2 MiB,
// 7 ms measured on a loaded 2-core machine, and the master, waiting 3 x 2 ms for the mailbox
// status frame, gave the write up. A device writes its flash behind the mailbox; answering a
// packet never waits for it.)
class FoeFile {
 public:
  static constexpr std::size_t kChunkBytes = 64 * 1024;

  void append(ConstBytes bytes);
  std::size_t size() const { return size_; }
  // Copies the bytes from `offset` on into `out` (as many as fit, up to the end of the file)
  // and returns how many it copied.
  std::size_t copyOut(std::size_t offset, Bytes out) const;
  // Where `text` occurs last in the file, if it does (also across chunk boundaries).
  std::optional<std::size_t> rfind(std::string_view text) const;
  // The whole file in one piece (a copy: for a power cycle and for tests, not per packet).
  std::vector<std::uint8_t> bytes() const;

 private:
  std::vector<std::vector<std::uint8_t>> chunks_;
  std::size_t size_{0};
};

class FoeFiles {
 public:
  const FoeFile* find(const std::string& name) const;
  // The file, shared: a read in progress keeps the bytes it started with, even if the file is
  // written again meanwhile, without copying them.
  std::shared_ptr<const FoeFile> share(const std::string& name) const;
  void store(const std::string& name, FoeFile data, bool writtenInBoot);
  std::size_t totalBytes() const;

  // The name of the last file completely written in BOOT, waiting for the next power cycle.
  const std::optional<std::string>& pendingFirmware() const { return pending_; }
  // Called at a power cycle: the pending image becomes the running firmware.
  void installPending();
  // The software version the running firmware reports (set by installPending from an image
  // with the marker; empty: the version the device was built with).
  const std::optional<std::string>& installedVersion() const { return installedVersion_; }

 private:
  std::map<std::string, std::shared_ptr<const FoeFile>> files_;
  std::optional<std::string> pending_;
  std::optional<std::string> installedVersion_;
};

}  // namespace ecsim::slavesim::foe
