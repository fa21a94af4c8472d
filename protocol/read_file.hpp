// Reading a whole input file safely: the one way every reader loads a file the user named
// (topology, scenario, master config, ESI, ENI, CSV signals, SII/EEPROM images). The path must
// name a regular file (a symbolic link to one is fine) of at most `maxBytes`; it is opened
// with O_NONBLOCK, so a FIFO, a device or a socket is refused at once instead of blocking the
// caller (the serve loop is single-threaded) or reading forever (/dev/zero). Errors name the
// path and say why. Off the cyclic path.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

#include "protocol/result.hpp"

namespace ecsim {

// Size bounds of the files we read. The largest real ESI file known to us is about 2 MB.
inline constexpr std::size_t kMaxXmlFileBytes = std::size_t{64} << 20;     // 64 MiB
inline constexpr std::size_t kMaxTextFileBytes = std::size_t{16} << 20;    // CSV signals
inline constexpr std::size_t kMaxEepromFileBytes = std::size_t{1} << 20;   // SII images

// The whole content of the regular file at `path`; kNotFound when it does not exist,
// kInvalidArgument when it is not a regular file, kTooLarge over `maxBytes`, kIo otherwise.
Result<std::string> readRegularFile(const std::filesystem::path& path, std::size_t maxBytes);

}  // namespace ecsim
