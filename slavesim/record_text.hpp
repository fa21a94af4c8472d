// The small text records ecsim keeps for a device (a drive's state file,
// devices/device_state.hpp; the FoE firmware record, foe/foe_folder.hpp), one reader for both:
//
//   # comment lines and blank lines, anywhere
//   MAGIC VERSION
//   KEY VALUE
//
// (a CR before a line's LF is taken off). Errors name the file and line: "PATH:3: what".
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "protocol/result.hpp"

namespace ecsim::slavesim {

struct RecordFormat {
  std::string_view magic;    // "ecsim-device-state"
  std::string_view version;  // "1"
  std::string_view kind;     // "device state file": how errors name the record
};

inline Error recordError(const std::string& shown, int line, const std::string& what) {
  return makeError(ErrorCode::kParse, shown + ":" + std::to_string(line) + ": " + what);
}

// Checks the MAGIC VERSION line of `text` (`shown` names it in errors), then calls
// take(lineNumber, key, value) -> Status for every KEY VALUE line after it; the first error
// ends the reading. Returns the number of lines read.
template <typename Take>
Result<int> readRecord(const std::string& shown, std::string_view text, const RecordFormat& format,
                       Take take) {
  const std::string kind(format.kind);
  bool header = false;
  int lineNo = 0;
  while (!text.empty()) {
    const std::size_t end = text.find('\n');
    std::string_view line = text.substr(0, end);
    text = end == std::string_view::npos ? std::string_view() : text.substr(end + 1);
    ++lineNo;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.empty() || line.front() == '#') continue;
    const std::size_t space = line.find(' ');
    const std::string_view key = line.substr(0, space);
    const std::string_view value =
        space == std::string_view::npos ? std::string_view() : line.substr(space + 1);
    if (!header) {
      if (key != format.magic) return recordError(shown, lineNo, "not an ecsim " + kind);
      if (value != format.version) {
        return recordError(shown, lineNo,
                           "unsupported " + kind + " version '" + std::string(value) + "'");
      }
      header = true;
      continue;
    }
    ECSIM_TRY(take(lineNo, key, value));
  }
  if (!header) return recordError(shown, lineNo, "empty " + kind);
  return lineNo;
}

}  // namespace ecsim::slavesim
