// Shared helpers for the link tests: test frames, the CI rule for missing prerequisites, and
// dropping one capability in a forked child.
#pragma once

#include <gtest/gtest.h>
#include <linux/capability.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "link/netns.hpp"
#include "protocol/frame.hpp"
#include "tests/support/ci_mode.hpp"

namespace ecsim::testing {

// A prerequisite is missing: a failure under CI=true, otherwise a skip with the reason.
#define ECSIM_REQUIRE_OR_SKIP(condition, reason)                            \
  do {                                                                      \
    if (!(condition)) {                                                     \
      if (::ecsim::testing::ciMode()) FAIL() << "CI=true and " << (reason); \
      GTEST_SKIP() << (reason);                                             \
    }                                                                       \
  } while (false)

#define ECSIM_REQUIRE_NETWORK_PRIVILEGES()                                        \
  do {                                                                            \
    const ::ecsim::Status caps_ = ::ecsim::checkNetworkCapabilities();            \
    ECSIM_REQUIRE_OR_SKIP(caps_.ok(), caps_.ok() ? "" : caps_.error().message()); \
  } while (false)

// An EtherCAT frame of 60 bytes: one BRD of 2 bytes at 0x0000 with the given index (the
// datagram SOEM uses to count slaves, ../shared/notes/soem-interop.md §2).
inline std::vector<std::uint8_t> etherCatFrame(std::uint8_t index,
                                               MacAddress destination = kBroadcastMac) {
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  EthernetHeader eth{
      destination, {0x02, 0x01, 0x01, 0x01, 0x01, 0x01}, std::nullopt, kEtherTypeEtherCat};
  FrameBuilder builder(buf, eth);
  EXPECT_TRUE(builder.add(Command::kBrd, index, DatagramHeader::physical(0, 0), 2).ok());
  auto length = builder.finish();
  EXPECT_TRUE(length.ok());
  return std::vector<std::uint8_t>(buf.begin(), buf.begin() + static_cast<long>(*length));
}

// A 60-byte frame of another EtherType (0x88B5, IEEE local experimental).
inline std::vector<std::uint8_t> otherFrame() {
  std::vector<std::uint8_t> frame(60, 0x5A);
  for (std::size_t i = 0; i < 6; ++i) frame[i] = 0xFF;
  writeBe16(frame, 12, 0x88B5);
  return frame;
}

// Runs body in a forked child and returns its exit code (body's return value); -1 when the
// child did not exit normally or `setup` failed (exit codes of 100 and above).
template <typename Body>
int runInChild(Body body) {
  const pid_t pid = ::fork();
  if (pid == 0) ::_exit(body());
  int status = 0;
  if (pid < 0 || ::waitpid(pid, &status, 0) != pid) return -1;
  if (!WIFEXITED(status) || WEXITSTATUS(status) >= 100) return -1;
  return WEXITSTATUS(status);
}

// As runInChild, with `capability` removed from the child's effective set first.
template <typename Body>
int runWithoutCapability(unsigned capability, Body body) {
  return runInChild([&]() -> int {
    __user_cap_header_struct header{_LINUX_CAPABILITY_VERSION_3, 0};
    std::array<__user_cap_data_struct, 2> data{};
    if (::syscall(SYS_capget, &header, data.data()) != 0) return 100;
    data[capability / 32].effective &= ~(1u << (capability % 32));
    if (::syscall(SYS_capset, &header, data.data()) != 0) return 101;
    return body();
  });
}

}  // namespace ecsim::testing
