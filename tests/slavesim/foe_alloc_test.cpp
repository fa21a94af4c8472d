// A large file over FoE is taken and sent without copying it per packet, proved by the largest
// heap allocation made while its packets are answered: global operator new and delete are
// replaced in this test binary only (support/allocation_counter.hpp; its own executable, as
// tests/master/cycle_alloc_test.cpp).
//
// Why: the simulator answers each DATA packet inside one mailbox turn of the frame path
// (ETG.1000.6 §5.7: a device that needs time for its flash answers BUSY, it does not stall the
// ESC). The file buffer used to be a std::vector that doubled: the packet that took it past
// 2 MiB allocated 4 MiB and copied 2 MiB, 7.3 ms in one firmware run of `ecsim serve --paced`
// (measured on a loaded 2-core machine), and `ecmaster foe write --boot` of 2.2 MB over veth
// lost its SM1 status frame (3 x 2 ms) every time. A read copied the whole file at its request.
#include <gtest/gtest.h>

#include <algorithm>

#include "protocol/foe.hpp"
#include "slavesim/foe/foe_server.hpp"
#include "support/allocation_counter.hpp"
#include "tests/slavesim/coe_test_support.hpp"

namespace ecsim::testing {
namespace {

// The CoE test slave's mailbox (0x1000/0x1080, 128 bytes each): 116 bytes per packet.
constexpr std::uint16_t kMailboxSize = 128;
// Past the 2 MiB at which the doubling vector copied 2 MiB (the failure over veth was at 2.09 MB).
constexpr std::size_t kFileSize = 3 * 1024 * 1024 + 123;
// The most one packet may allocate: a new chunk of the file (FoeFile::kChunkBytes, 64 KiB).
constexpr std::size_t kLargestAllowed = 64 * 1024;

class Counting {
 public:
  Counting() {
    gLargestAllocation = 0;
    gCounting = true;
  }
  ~Counting() { gCounting = false; }
};

struct Reply {
  FoeOpcode opcode{FoeOpcode::kError};
  std::uint32_t value{0};
  std::vector<std::uint8_t> data;
};

template <typename Data>
Reply ask(CoeTestSlave& t, FoeOpcode op, std::uint32_t value, Data data) {
  auto m = encodeFoeMailbox(op, value, data);
  m[5] = static_cast<std::uint8_t>(m[5] | (t.master->nextCounter() << 4));
  auto r = t.master->transact(m);
  EXPECT_TRUE(r.has_value()) << "no answer to " << toString(op);
  if (!r) return {};
  const FoePacket p = decodeFoe(decodeMailbox(*r)->payload).value();
  return {p.opcode, p.value, std::vector<std::uint8_t>(p.data.begin(), p.data.end())};
}

TEST(FoeAlloc, ALargeFileIsWrittenAndReadWithoutCopyingItPerPacket) {
  CoeTestSlave t(kMailboxSize);
  auto files = std::make_shared<slavesim::foe::FoeFiles>();
  t.server->addProtocol(std::make_unique<slavesim::foe::FoeServer>(files));
  std::vector<std::uint8_t> image(kFileSize);
  for (std::size_t i = 0; i < image.size(); ++i) image[i] = static_cast<std::uint8_t>(i * 7 + 3);
  const std::size_t perPacket = foeDataPerPacket(kMailboxSize);

  const std::string name = "firmware.bin";
  const Reply started = ask(t, FoeOpcode::kWrite, 0, std::string_view(name));
  ASSERT_EQ(started.opcode, FoeOpcode::kAck)
      << started.value << " " << std::string(started.data.begin(), started.data.end());
  std::size_t largestWrite = 0;
  {
    Counting counting;
    std::uint32_t packet = 0;
    for (std::size_t at = 0; at <= image.size(); at += perPacket) {
      const std::size_t n = std::min(perPacket, image.size() - at);
      const Reply r = ask(t, FoeOpcode::kData, ++packet, ConstBytes(image).subspan(at, n));
      ASSERT_EQ(r.opcode, FoeOpcode::kAck);
      ASSERT_EQ(r.value, packet);
      if (n < perPacket) break;
    }
    largestWrite = gLargestAllocation;
  }
  ASSERT_NE(files->find(name), nullptr);
  EXPECT_EQ(files->find(name)->size(), image.size());
  EXPECT_LE(largestWrite, kLargestAllowed) << "a DATA packet reallocated the file";

  // Read back: the same bytes, and the read request does not copy the file either.
  std::vector<std::uint8_t> back;
  back.reserve(image.size());
  std::size_t largestRead = 0;
  {
    Counting counting;
    Reply r = ask(t, FoeOpcode::kRead, 0, std::string_view(name));
    while (r.opcode == FoeOpcode::kData) {
      back.insert(back.end(), r.data.begin(), r.data.end());
      if (r.data.size() < perPacket) break;
      r = ask(t, FoeOpcode::kAck, r.value, ConstBytes());
    }
    largestRead = gLargestAllocation;
  }
  EXPECT_TRUE(back == image) << "read " << back.size() << " of " << image.size() << " bytes";
  EXPECT_LE(largestRead, kLargestAllowed) << "the read request copied the file";
}

}  // namespace
}  // namespace ecsim::testing
