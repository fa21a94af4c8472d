// libFuzzer target for the capture reader (link/pcap.hpp, PcapReader over libpcap, as
// `ecsim replay` and the capture tests use it): arbitrary bytes as a pcap or pcapng file,
// every frame read to the end or to the first error.
//
// PcapReader takes a path, so the bytes go into an anonymous in-memory file (memfd) opened
// by its /proc/self/fd name: no file on disk, one descriptor for the whole run.
#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "link/pcap.hpp"

namespace {

int memoryFile() {
  static const int fd = memfd_create("fuzz-pcap", 0);
  if (fd < 0) __builtin_trap();
  return fd;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const int fd = memoryFile();
  if (ftruncate(fd, 0) != 0 || pwrite(fd, data, size, 0) != static_cast<ssize_t>(size)) {
    __builtin_trap();
  }
  auto reader = ecsim::PcapReader::open("/proc/self/fd/" + std::to_string(fd));
  if (!reader.ok()) return 0;
  (void)reader->linkType();
  for (;;) {
    auto frame = reader->next();
    if (!frame.ok() || !*frame) break;
    for (std::uint8_t byte : (*frame)->data) (void)byte;
  }
  return 0;
}
