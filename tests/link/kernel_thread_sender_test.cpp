#include "link/kernel_thread_sender.hpp"

#include <gtest/gtest.h>
#include <sched.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <thread>
#include <vector>

#include "protocol/unique_fd.hpp"
#include "test_support.hpp"

namespace ecsim {
namespace {

using namespace std::chrono_literals;

// A CPU other than the one this thread runs on, or -1 on a single CPU.
int otherCpu() {
  const long cpus = ::sysconf(_SC_NPROCESSORS_ONLN);
  if (cpus < 2) return -1;
  return (::sched_getcpu() + 1) % static_cast<int>(cpus);
}

class KernelThreadSenderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    int pair[2];
    ASSERT_EQ(::socketpair(AF_UNIX, SOCK_DGRAM, 0, pair), 0);
    ours_.reset(pair[0]);
    theirs_.reset(pair[1]);
    cpu_ = otherCpu();
    ECSIM_REQUIRE_OR_SKIP(cpu_ >= 0, "one CPU: no other CPU for the sending thread");
  }

  // The sender on ours_; a skip (a failure under CI=true) when the kernel has no io_uring.
  std::optional<KernelThreadSender> open(unsigned idleMs = 1000) {
    auto s = KernelThreadSender::open(ours_.get(), cpu_, "test socket", idleMs);
    if (!s.ok() && s.error().code == ErrorCode::kUnsupported) return std::nullopt;
    EXPECT_TRUE(s.ok()) << s.error().message();
    if (!s.ok()) return std::nullopt;
    return std::move(s).value();
  }

  std::vector<std::uint8_t> receive() {
    std::vector<std::uint8_t> buf(4096);
    const ssize_t n = ::recv(theirs_.get(), buf.data(), buf.size(), MSG_DONTWAIT);
    buf.resize(n < 0 ? 0 : static_cast<std::size_t>(n));
    return buf;
  }

  UniqueFd ours_;
  UniqueFd theirs_;
  int cpu_{-1};
};

#define ECSIM_OPEN_SENDER(var, ...)                                                       \
  auto var = open(__VA_ARGS__);                                                           \
  if (HasFailure()) return;                                                               \
  ECSIM_REQUIRE_OR_SKIP(var.has_value(), "the kernel refuses io_uring with SQPOLL here"); \
  do {                                                                                    \
  } while (false)

// Frames leave whole and in the order given, each send done when it returns: the peer has it.
TEST_F(KernelThreadSenderTest, SendsFramesInOrderAndDoneOnReturn) {
  ECSIM_OPEN_SENDER(sender);
  EXPECT_EQ(sender->cpu(), cpu_);
  std::vector<std::uint8_t> frame(60);
  for (unsigned i = 0; i < 1000; ++i) {
    for (std::size_t b = 0; b < frame.size(); ++b) frame[b] = static_cast<std::uint8_t>(i + b);
    frame.resize(60 + i % 7);
    auto sent = sender->send(frame);
    ASSERT_TRUE(sent.ok()) << sent.error().message();
    ASSERT_EQ(*sent, static_cast<long>(frame.size()));
    ASSERT_EQ(receive(), frame) << "frame " << i;
  }
}

// The result is what send(2) gives on the same socket: here EMSGSIZE for a datagram larger
// than the socket can ever send, the same errno as a plain send() of it.
TEST_F(KernelThreadSenderTest, ReturnsTheErrnoOfAFailedSendAsSendWould) {
  ECSIM_OPEN_SENDER(sender);
  int sendBuffer = 4096;
  ASSERT_EQ(::setsockopt(ours_.get(), SOL_SOCKET, SO_SNDBUF, &sendBuffer, sizeof sendBuffer), 0);
  const std::vector<std::uint8_t> huge(1 << 20, 0xAB);
  errno = 0;
  ASSERT_LT(::send(ours_.get(), huge.data(), huge.size(), 0), 0);
  const int plain = errno;
  auto sent = sender->send(huge);
  ASSERT_TRUE(sent.ok()) << sent.error().message();
  EXPECT_EQ(*sent, -static_cast<long>(plain)) << "send(2) failed with errno " << plain;
  // And the sender is still usable afterwards.
  const std::vector<std::uint8_t> small(60, 1);
  sent = sender->send(small);
  ASSERT_TRUE(sent.ok());
  EXPECT_EQ(*sent, 60);
  EXPECT_EQ(receive(), small);
}

// After `idleMs` without a frame the kernel thread sleeps; the next send wakes it (counted) and
// still arrives.
TEST_F(KernelThreadSenderTest, WakesASleepingThread) {
  ECSIM_OPEN_SENDER(sender, 1);
  const std::vector<std::uint8_t> frame(60, 7);
  ASSERT_TRUE(sender->send(frame).ok());
  EXPECT_EQ(receive(), frame);
  const std::uint64_t before = sender->wakeUps();
  std::this_thread::sleep_for(50ms);
  auto sent = sender->send(frame);
  ASSERT_TRUE(sent.ok());
  EXPECT_EQ(*sent, 60);
  EXPECT_EQ(receive(), frame);
  EXPECT_EQ(sender->wakeUps(), before + 1);
}

TEST_F(KernelThreadSenderTest, NamesACpuThatIsNotThere) {
  auto s = KernelThreadSender::open(ours_.get(), CPU_SETSIZE - 1, "test socket");
  ASSERT_FALSE(s.ok());
  if (s.error().code == ErrorCode::kUnsupported) {
    ECSIM_REQUIRE_OR_SKIP(false, "the kernel refuses io_uring with SQPOLL here");
  }
  EXPECT_EQ(s.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(s.error().context.find("CPU " + std::to_string(CPU_SETSIZE - 1)), std::string::npos)
      << s.error().context;
  EXPECT_NE(s.error().context.find("test socket"), std::string::npos);
}

}  // namespace
}  // namespace ecsim
