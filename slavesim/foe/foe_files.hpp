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
// With a folder (keptIn, foe_folder.hpp: the slave's stateFile) the files, the pending image and
// the installed version also outlive the simulator.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/bytes.hpp"
#include "protocol/result.hpp"

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

class FoeFolder;

// The largest file a slave takes (a bigger write is refused with "disk full") or loads.
inline constexpr std::size_t kMaxFoeFileBytes = 16u * 1024 * 1024;

class FoeFiles {
 public:
  FoeFiles();
  ~FoeFiles();
  FoeFiles(const FoeFiles&) = delete;
  FoeFiles& operator=(const FoeFiles&) = delete;

  // Files kept in `folder` (foe_folder.hpp) as well as in memory: what it holds is loaded, and
  // an image pending there is installed (starting the simulator powers the device up).
  static Result<std::shared_ptr<FoeFiles>> keptIn(const std::filesystem::path& folder);
  // The folder, if kept in one.
  const FoeFolder* folder() const { return folder_.get(); }

  const FoeFile* find(const std::string& name) const;
  // The file, shared: a read in progress keeps the bytes it started with, even if the file is
  // written again meanwhile, without copying them.
  std::shared_ptr<const FoeFile> share(const std::string& name) const;
  // A write in progress also goes to the folder, packet by packet, so that storing costs a
  // rename and not the whole file (no-ops without a folder). An error: the host could not
  // write it (the FoE server answers "disk full").
  Status beginWrite(const std::string& name);
  Status appendWrite(ConstBytes bytes);
  void abandonWrite();
  // The file written completely (renamed into place in the folder first).
  Status store(const std::string& name, FoeFile data, bool writtenInBoot);
  std::size_t totalBytes() const;

  // The name of the last file completely written in BOOT, waiting for the next power cycle.
  const std::optional<std::string>& pendingFirmware() const { return pending_; }
  // Called at a power cycle: the pending image becomes the running firmware.
  Status installPending();
  // The software version the running firmware reports (set by installPending from an image
  // with the marker; empty: the version the device was built with).
  const std::optional<std::string>& installedVersion() const { return installedVersion_; }

 private:
  std::map<std::string, std::shared_ptr<const FoeFile>> files_;
  std::optional<std::string> pending_;
  std::optional<std::string> installedVersion_;
  std::unique_ptr<FoeFolder> folder_;
};

}  // namespace ecsim::slavesim::foe
