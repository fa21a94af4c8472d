#include "link/signal_flag.hpp"

#include <gtest/gtest.h>
#include <pthread.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <chrono>
#include <csignal>
#include <thread>

#include "link/fd.hpp"

namespace ecsim {
namespace {

using namespace std::chrono_literals;

std::atomic<int> gPreviousHandlerCalls{0};
void previousHandler(int) {
  gPreviousHandlerCalls.fetch_add(1);
}

TEST(SignalFlag, CatchesSigintAndSigterm) {
  {
    SignalFlag flag;
    EXPECT_FALSE(flag.raised());
    ASSERT_EQ(::raise(SIGTERM), 0);
    EXPECT_TRUE(flag.raised());
    EXPECT_EQ(flag.signal(), SIGTERM);
    flag.clear();
    EXPECT_FALSE(flag.raised());
  }
  SignalFlag flag;
  ASSERT_EQ(::raise(SIGINT), 0);
  EXPECT_EQ(flag.signal(), SIGINT);
}

TEST(SignalFlag, RestoresThePreviousHandler) {
  struct sigaction mine {};
  mine.sa_handler = previousHandler;
  sigemptyset(&mine.sa_mask);
  struct sigaction original {};
  ASSERT_EQ(::sigaction(SIGUSR1, &mine, &original), 0);
  gPreviousHandlerCalls = 0;
  {
    SignalFlag flag({SIGUSR1});
    ASSERT_EQ(::raise(SIGUSR1), 0);
    EXPECT_EQ(flag.signal(), SIGUSR1);
    EXPECT_EQ(gPreviousHandlerCalls.load(), 0);
  }
  ASSERT_EQ(::raise(SIGUSR1), 0);
  EXPECT_EQ(gPreviousHandlerCalls.load(), 1);
  ASSERT_EQ(::sigaction(SIGUSR1, &original, nullptr), 0);
}

// Without SA_RESTART a signal ends a blocking wait at once, so a receive loop notices it.
TEST(SignalFlag, InterruptsABlockingWait) {
  std::array<int, 2> fds{};
  ASSERT_EQ(::pipe(fds.data()), 0);
  UniqueFd readEnd(fds[0]);
  UniqueFd writeEnd(fds[1]);
  SignalFlag flag({SIGUSR2});
  const pthread_t waiter = ::pthread_self();
  std::thread signaller([waiter] {
    std::this_thread::sleep_for(100ms);
    ::pthread_kill(waiter, SIGUSR2);
  });
  const auto start = std::chrono::steady_clock::now();
  auto readable = waitReadable(readEnd.get(), 20s);
  const auto elapsed = std::chrono::steady_clock::now() - start;
  signaller.join();
  ASSERT_TRUE(readable.ok());
  EXPECT_FALSE(*readable);
  EXPECT_TRUE(flag.raised());
  EXPECT_LT(elapsed, 10s);
}

}  // namespace
}  // namespace ecsim
