// Where a slave's FoE files outlive the simulator (issue #20: files written over FoE are kept
// per slave, in memory, and optionally with the slave's state file). With a topology
// stateFile=PATH, a slave with FoE keeps its files in the folder PATH.foe beside the state file:
//
//   PATH.foe/file-NAME   the bytes of the FoE file NAME (percent-encoded: every byte other
//                        than A-Z a-z 0-9 . _ - as %XX, so any FoE name is one folder entry)
//   PATH.foe/firmware    the firmware record, text:
//                          # comment lines
//                          ecsim-foe-firmware 1
//                          pending NAME              written in BOOT, booted at the next power-up
//                          installed-version TEXT    what the running firmware reports (0x100A)
//                        (NAME and TEXT percent-encoded as above; both lines optional)
//
// A file is written to file-NAME.tmp as its DATA packets arrive (one write(2) per packet) and
// renamed over file-NAME with the last one, so a transfer cut short (cable pull, master gone,
// kill) leaves the previous file as it was. Nothing is fsynced: flushing a multi-megabyte image
// inside one mailbox turn would stall the whole simulated network for that long. The files
// outlive a restart of the simulator, not necessarily a crash of the host.
//
// Our own format, read strictly: a symbolic link or a non-folder at PATH.foe is refused, and so
// is an entry in it that is none of the above (leftover file-NAME.tmp entries of an interrupted
// transfer are skipped), a file larger than the limit, and a firmware record line it does not
// know; every error names the path (and line).
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "protocol/bytes.hpp"
#include "protocol/result.hpp"
#include "protocol/unique_fd.hpp"
#include "slavesim/foe/foe_files.hpp"

namespace ecsim::slavesim::foe {

// PATH.foe for the state file PATH.
std::filesystem::path foeFolderFor(const std::filesystem::path& stateFile);

// "app.bin" -> "app.bin", "fw/v2 x" -> "fw%2Fv2%20x", and back (nullopt: not an encoding).
std::string percentEncode(std::string_view text);
std::optional<std::string> percentDecode(std::string_view text);

// What a folder held when opened.
struct FoeFolderContent {
  std::vector<std::pair<std::string, FoeFile>> files;
  std::optional<std::string> pending;
  std::optional<std::string> installedVersion;
};

class FoeFolder {
 public:
  // Opens `path` and reads what it holds into `content`; files over `maxFileBytes` are
  // refused. A missing folder holds nothing: it is made (its parent must exist) when the first
  // file or record is written, so building a network that is never run leaves no trace.
  static Result<FoeFolder> open(const std::filesystem::path& path, FoeFolderContent& content,
                                std::size_t maxFileBytes);

  const std::filesystem::path& path() const { return path_; }

  // One file written at a time: begin (file-NAME.tmp created, emptied), append per packet,
  // finish (renamed into place) or abandon (removed).
  Status begin(const std::string& name);
  Status append(ConstBytes bytes);
  Status finish();
  void abandon();

  // Writes the firmware record (PATH.foe/firmware.tmp renamed over firmware).
  Status saveFirmwareRecord(const std::optional<std::string>& pending,
                            const std::optional<std::string>& installedVersion) const;

 private:
  // true: the folder is there; false: missing; an error for anything else at its path.
  Result<bool> check() const;
  // Makes the folder when missing.
  Status create() const;
  std::filesystem::path path_;
  UniqueFd writing_;
  std::string writingPath_;  // file-NAME.tmp of the file being written
  std::string finalPath_;    // file-NAME
};

}  // namespace ecsim::slavesim::foe
