// The soak run: set-up of the network (station addresses, FMMUs), then `frames` frames from a
// seeded FrameSource with up to `window` valid frames in flight, each answer checked, each
// valid frame given `timeout` to come back.
#pragma once

#include <sys/types.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>

#include "link/raw_socket_link.hpp"
#include "tools/ecsim-soak/frames.hpp"

namespace ecsim::soak {

struct SoakOptions {
  std::uint64_t seed{1};
  std::uint64_t frames{100000};
  unsigned window{8};
  std::chrono::milliseconds timeout{1000};
  unsigned malformedPercent{20};
  unsigned expectedSlaves{0};  // 0: as many as answer the first BRD
  std::uint8_t escType{0x11};  // ESC type register (0x0000) of every slave: 0x11 ET1100
  pid_t serverPid{0};          // 0: not watched
  std::chrono::milliseconds waitReady{0};  // keep probing this long for a first answer
  unsigned errorsShown{10};    // details printed for the first N errors
  std::chrono::seconds progress{0};  // a progress line this often (0: none)
};

struct SoakReport {
  std::uint16_t slaves{0};
  std::uint64_t sent{0};
  std::uint64_t validSent{0};
  std::uint64_t answered{0};
  std::uint64_t timeouts{0};
  std::uint64_t wkcErrors{0};
  std::uint64_t dataErrors{0};
  std::uint64_t lateAnswers{0};     // answers after their timeout
  std::uint64_t foreignFrames{0};   // EtherCAT frames that are none of ours
  std::uint64_t sendErrors{0};      // valid frames the kernel refused
  std::array<std::uint64_t, kMalformations> malformedSent{};  // by kind (index 0 unused)
  std::uint64_t malformedRefused{0};   // refused by the kernel (oversized past the MTU)
  std::uint64_t malformedAnswered{0};  // executed although malformed: an error
  std::uint64_t malformedForwarded{0}; // came back unprocessed (allowed for a wrong type)
  double seconds{0};
  long rssStartKb{-1};
  long rssEndKb{-1};
  bool serverDied{false};
  std::string setupError;  // set-up failed: the run did not start

  std::uint64_t malformedTotal() const;
  bool failed() const;
};

// Resident set size of a process in kB (VmRSS of /proc/PID/status), -1 when unreadable.
long residentKb(pid_t pid);
// False once the process has ended (gone, or a zombie waiting for its parent).
bool processAlive(pid_t pid);

// Runs the soak over `link`; progress and the first errors go to `log`.
SoakReport runSoak(RawSocketLink& link, const SoakOptions& options, std::FILE* log);

void printReport(const SoakReport& report, const SoakOptions& options, std::FILE* out);

}  // namespace ecsim::soak
