#include "link/memory_link.hpp"

#include <gtest/gtest.h>
#include <poll.h>

#include <array>
#include <chrono>
#include <thread>
#include <vector>

#include "protocol/ethernet.hpp"

namespace ecsim {
namespace {

using namespace std::chrono_literals;

std::vector<std::uint8_t> numberedFrame(std::uint32_t number, std::size_t size = 60) {
  std::vector<std::uint8_t> frame(size, 0);
  writeBe16(frame, 12, kEtherTypeEtherCat);
  writeLe32(frame, 16, number);
  return frame;
}

bool readable(int fd) {
  pollfd pfd{fd, POLLIN, 0};
  return ::poll(&pfd, 1, 0) == 1 && (pfd.revents & POLLIN) != 0;
}

TEST(MemoryLink, DeliversInOrderInBothDirections) {
  auto [a, b] = MemoryLink::makePair(8);
  for (std::uint32_t i = 0; i < 5; ++i) ASSERT_TRUE(a.send(numberedFrame(i)).ok());
  ASSERT_TRUE(b.send(numberedFrame(100)).ok());
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  for (std::uint32_t i = 0; i < 5; ++i) {
    auto n = b.receive(buf, 0ns);
    ASSERT_TRUE(n.ok()) << n.error().message();
    ASSERT_EQ(*n, 60u);
    EXPECT_EQ(readLe32(buf, 16), i);
  }
  auto n = a.receive(buf, 0ns);
  ASSERT_TRUE(n.ok());
  ASSERT_EQ(*n, 60u);
  EXPECT_EQ(readLe32(buf, 16), 100u);
  // Nothing is left in either direction, and a frame never comes back to its sender.
  EXPECT_EQ(*a.receive(buf, 0ns), 0u);
  EXPECT_EQ(*b.receive(buf, 0ns), 0u);
}

TEST(MemoryLink, KeepsFrameBytesAtEveryLength) {
  auto [a, b] = MemoryLink::makePair(2);
  for (std::size_t size : {std::size_t{1}, std::size_t{14}, std::size_t{60}, kMaxFrameSize}) {
    std::vector<std::uint8_t> frame(size);
    for (std::size_t i = 0; i < size; ++i) frame[i] = static_cast<std::uint8_t>(i * 7 + size);
    ASSERT_TRUE(a.send(frame).ok());
    std::vector<std::uint8_t> buf(kMaxFrameSize, 0xEE);
    auto n = b.receive(buf, 0ns);
    ASSERT_TRUE(n.ok());
    ASSERT_EQ(*n, size);
    EXPECT_EQ(std::vector<std::uint8_t>(buf.begin(), buf.begin() + static_cast<long>(size)), frame);
  }
}

TEST(MemoryLink, RefusesFramesWhenTheQueueIsFull) {
  auto [a, b] = MemoryLink::makePair(2);
  EXPECT_EQ(b.capacity(), 2u);
  ASSERT_TRUE(a.send(numberedFrame(1)).ok());
  ASSERT_TRUE(a.send(numberedFrame(2)).ok());
  EXPECT_EQ(b.pending(), 2u);
  auto full = a.send(numberedFrame(3));
  ASSERT_FALSE(full.ok());
  EXPECT_EQ(full.error().code, ErrorCode::kTooLarge);
  EXPECT_NE(full.error().context.find("full"), std::string::npos) << full.error().context;

  std::array<std::uint8_t, kMaxFrameSize> buf{};
  ASSERT_EQ(*b.receive(buf, 0ns), 60u);
  EXPECT_EQ(readLe32(buf, 16), 1u);
  ASSERT_TRUE(a.send(numberedFrame(4)).ok());  // room again; the refused frame is gone
  ASSERT_EQ(*b.receive(buf, 0ns), 60u);
  EXPECT_EQ(readLe32(buf, 16), 2u);
  ASSERT_EQ(*b.receive(buf, 0ns), 60u);
  EXPECT_EQ(readLe32(buf, 16), 4u);
}

TEST(MemoryLink, RefusesOversizeAndEmptyFrames) {
  auto [a, b] = MemoryLink::makePair(4);
  std::vector<std::uint8_t> big(kMaxFrameSize + 1, 0);
  auto tooBig = a.send(big);
  ASSERT_FALSE(tooBig.ok());
  EXPECT_EQ(tooBig.error().code, ErrorCode::kTooLarge);
  auto empty = a.send(ConstBytes{});
  ASSERT_FALSE(empty.ok());
  EXPECT_EQ(empty.error().code, ErrorCode::kInvalidArgument);
  EXPECT_EQ(b.pending(), 0u);
}

TEST(MemoryLink, SmallReceiveBufferDropsTheFrameWithAnError) {
  auto [a, b] = MemoryLink::makePair(4);
  ASSERT_TRUE(a.send(numberedFrame(1, 100)).ok());
  ASSERT_TRUE(a.send(numberedFrame(2, 60)).ok());
  std::array<std::uint8_t, 80> small{};
  auto n = b.receive(small, 0ns);
  ASSERT_FALSE(n.ok());
  EXPECT_EQ(n.error().code, ErrorCode::kTooLarge);
  auto next = b.receive(small, 0ns);
  ASSERT_TRUE(next.ok());
  ASSERT_EQ(*next, 60u);
  EXPECT_EQ(readLe32(small, 16), 2u);
}

TEST(MemoryLink, ReceiveWaitsForTheTimeoutWhenNothingArrives) {
  auto [a, b] = MemoryLink::makePair(4);
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  const auto start = std::chrono::steady_clock::now();
  auto n = b.receive(buf, 30ms);
  const auto elapsed = std::chrono::steady_clock::now() - start;
  ASSERT_TRUE(n.ok());
  EXPECT_EQ(*n, 0u);
  EXPECT_GE(elapsed, 30ms);
  EXPECT_LT(elapsed, 2s);

  const auto zeroStart = std::chrono::steady_clock::now();
  EXPECT_EQ(*b.receive(buf, 0ns), 0u);
  EXPECT_LT(std::chrono::steady_clock::now() - zeroStart, 20ms);
}

TEST(MemoryLink, BlockedReceiverWakesWhenAFrameIsSent) {
  auto [a, b] = MemoryLink::makePair(4);
  std::thread sender([&a] {
    std::this_thread::sleep_for(20ms);
    EXPECT_TRUE(a.send(numberedFrame(7)).ok());
  });
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  const auto start = std::chrono::steady_clock::now();
  auto n = b.receive(buf, 10s);
  const auto elapsed = std::chrono::steady_clock::now() - start;
  sender.join();
  ASSERT_TRUE(n.ok());
  ASSERT_EQ(*n, 60u);
  EXPECT_EQ(readLe32(buf, 16), 7u);
  EXPECT_LT(elapsed, 5s);
}

TEST(MemoryLink, PollFdIsReadableExactlyWhileFramesWait) {
  auto [a, b] = MemoryLink::makePair(4);
  ASSERT_GE(b.pollFd(), 0);
  ASSERT_NE(a.pollFd(), b.pollFd());
  EXPECT_FALSE(readable(b.pollFd()));
  ASSERT_TRUE(a.send(numberedFrame(1)).ok());
  ASSERT_TRUE(a.send(numberedFrame(2)).ok());
  EXPECT_TRUE(readable(b.pollFd()));
  EXPECT_FALSE(readable(a.pollFd()));
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  ASSERT_EQ(*b.receive(buf, 0ns), 60u);
  EXPECT_TRUE(readable(b.pollFd()));  // one frame still waiting
  ASSERT_EQ(*b.receive(buf, 0ns), 60u);
  EXPECT_FALSE(readable(b.pollFd()));
}

TEST(MemoryLink, OneSenderAndOneReceiverThreadKeepOrder) {
  constexpr std::uint32_t kFrames = 20'000;
  auto [a, b] = MemoryLink::makePair(16);
  std::thread sender([&a] {
    for (std::uint32_t i = 0; i < kFrames;) {
      auto status = a.send(numberedFrame(i, 60 + i % 100));
      if (status.ok()) {
        ++i;
      } else {
        ASSERT_EQ(status.error().code, ErrorCode::kTooLarge);
        std::this_thread::yield();
      }
    }
  });
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  std::uint32_t expected = 0;
  while (expected < kFrames) {
    auto n = b.receive(buf, 5s);
    ASSERT_TRUE(n.ok());
    ASSERT_GT(*n, 0u) << "timed out waiting for frame " << expected;
    ASSERT_EQ(*n, 60 + expected % 100);
    ASSERT_EQ(readLe32(buf, 16), expected);
    ++expected;
  }
  sender.join();
  EXPECT_EQ(b.pending(), 0u);
}

TEST(MemoryLink, DescribesEachEnd) {
  auto [a, b] = MemoryLink::makePair();
  EXPECT_EQ(a.describe(), "memory link end A");
  EXPECT_EQ(b.describe(), "memory link end B");
  EXPECT_EQ(a.capacity(), MemoryLink::kDefaultCapacity);
}

}  // namespace
}  // namespace ecsim
