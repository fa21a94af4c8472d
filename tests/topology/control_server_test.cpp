// The control socket's limits (issue #21, item 6): every line of a burst answered in order, a
// per-line length limit that discards only that line, a connection limit, an idle timeout on
// the caller's time, and a client connect bounded by its timeout when the server is full.
#include "topology/control_server.hpp"

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <future>
#include <string>
#include <thread>
#include <vector>

#include "link/fd.hpp"

namespace ecsim::topology {
namespace {

class ControlServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("ecsim-ctl-test-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    path_ = dir_ / "ctl.sock";
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  sockaddr_un address() const {
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::strncpy(addr.sun_path, path_.c_str(), sizeof(addr.sun_path) - 1);
    return addr;
  }
  UniqueFd connectClient() const {
    UniqueFd fd(::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0));
    const sockaddr_un addr = address();
    EXPECT_EQ(::connect(fd.get(), reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)), 0)
        << std::strerror(errno);
    return fd;
  }
  static void sendText(int fd, const std::string& text) {
    std::size_t done = 0;
    while (done < text.size()) {
      const ssize_t n = ::send(fd, text.data() + done, text.size() - done, MSG_NOSIGNAL);
      ASSERT_GT(n, 0) << std::strerror(errno);
      done += static_cast<std::size_t>(n);
    }
  }
  // Reads what the server has sent so far (the server answers within poll()).
  static std::string received(int fd) {
    std::string out;
    char buf[4096];
    while (true) {
      const ssize_t n = ::recv(fd, buf, sizeof(buf), MSG_DONTWAIT);
      if (n <= 0) break;
      out.append(buf, static_cast<std::size_t>(n));
    }
    return out;
  }
  static bool closedByServer(int fd) {
    char c;
    return ::recv(fd, &c, 1, MSG_DONTWAIT) == 0;
  }
  static std::vector<std::string> lines(const std::string& text) {
    std::vector<std::string> out;
    std::size_t start = 0;
    for (std::size_t nl; (nl = text.find('\n', start)) != std::string::npos; start = nl + 1) {
      out.push_back(text.substr(start, nl - start));
    }
    return out;
  }

  std::filesystem::path dir_;
  std::filesystem::path path_;
};

const ControlServer::Handler kEcho = [](std::string_view line) {
  return "ok " + std::string(line);
};

TEST_F(ControlServerTest, EveryLineOfABurstIsAnsweredInOrder) {
  auto server = ControlServer::open(path_);
  ASSERT_TRUE(server.ok()) << server.error().message();
  UniqueFd client = connectClient();
  std::string burst;
  for (int i = 0; i < 1000; ++i) burst += "loss rate=0." + std::to_string(i) + "\n";
  std::thread writer([&] { sendText(client.get(), burst); });
  std::string replies;
  for (int round = 0; round < 10000 && lines(replies).size() < 1000; ++round) {
    server->poll(kEcho, 0);
    replies += received(client.get());
  }
  writer.join();
  const auto got = lines(replies);
  ASSERT_EQ(got.size(), 1000u) << (got.empty() ? std::string() : got.back());
  for (int i = 0; i < 1000; ++i) {
    EXPECT_EQ(got[i], "ok loss rate=0." + std::to_string(i));
  }
}

TEST_F(ControlServerTest, ALineOverTheLimitIsRefusedAndTheConnectionGoesOn) {
  auto server = ControlServer::open(path_);
  ASSERT_TRUE(server.ok()) << server.error().message();
  UniqueFd client = connectClient();
  // The long line arrives in pieces, across several polls, before its newline.
  sendText(client.get(), "first\n" + std::string(3000, 'x'));
  server->poll(kEcho, 0);
  sendText(client.get(), std::string(3000, 'y'));
  server->poll(kEcho, 0);
  sendText(client.get(), std::string(3000, 'z') + "\nlast\n");
  server->poll(kEcho, 0);
  const auto got = lines(received(client.get()));
  ASSERT_EQ(got.size(), 3u);
  EXPECT_EQ(got[0], "ok first");
  EXPECT_EQ(got[1], "error line longer than 4096 bytes");
  EXPECT_EQ(got[2], "ok last");
  EXPECT_FALSE(closedByServer(client.get()));
}

TEST_F(ControlServerTest, ClientsBeyondTheLimitAreRefused) {
  auto server = ControlServer::open(path_);
  ASSERT_TRUE(server.ok()) << server.error().message();
  std::vector<UniqueFd> clients;
  for (std::size_t i = 0; i < kControlMaxClients; ++i) {
    clients.push_back(connectClient());
    server->poll(kEcho, 0);
  }
  UniqueFd extra = connectClient();
  server->poll(kEcho, 0);
  EXPECT_EQ(received(extra.get()),
            "error too many clients (" + std::to_string(kControlMaxClients) + ")\n");
  EXPECT_TRUE(closedByServer(extra.get()));
  // The clients within the limit are still served.
  sendText(clients.front().get(), "link-up cable=drives\n");
  server->poll(kEcho, 0);
  EXPECT_EQ(received(clients.front().get()), "ok link-up cable=drives\n");
}

// `ecsim ctl` against a server whose listen queue is full (its descriptor table full, or not
// polling): the connect gives up after the timeout with a clear error instead of blocking.
TEST_F(ControlServerTest, ConnectGivesUpAfterItsTimeoutWhenTheServerIsFull) {
  std::filesystem::create_directories(dir_);
  UniqueFd listener(::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0));
  const sockaddr_un addr = address();
  ASSERT_EQ(::bind(listener.get(), reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)), 0);
  ASSERT_EQ(::listen(listener.get(), 0), 0);
  std::vector<UniqueFd> queued;  // never accepted
  for (int i = 0; i < 64; ++i) {
    UniqueFd fd(::socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0));
    if (::connect(fd.get(), reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)) != 0) break;
    queued.push_back(std::move(fd));
  }
  auto reply = std::async(std::launch::async, [&] {
    return sendControlLine(path_, "link-up cable=master", std::chrono::milliseconds(200));
  });
  // A bound against the defect (a connect blocked for ever): closing the listener wakes it.
  if (reply.wait_for(std::chrono::seconds(10)) != std::future_status::ready) listener.reset();
  auto r = reply.get();
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kTimeout) << r.error().message();
  EXPECT_EQ(r.error().context,
            path_.string() + ": the server accepted no connection within 200 ms (busy or full)");
}

TEST_F(ControlServerTest, AClientThatSendsNothingIsClosedAfterTheIdleTimeout) {
  ControlLimits limits;
  limits.idleTimeout = 5 * kNsPerSecond;
  auto server = ControlServer::open(path_, limits);
  ASSERT_TRUE(server.ok()) << server.error().message();
  UniqueFd quiet = connectClient();
  UniqueFd busy = connectClient();
  server->poll(kEcho, 0);
  sendText(busy.get(), "link-up cable=master\n");
  server->poll(kEcho, 4 * kNsPerSecond);
  server->poll(kEcho, 5 * kNsPerSecond);  // the quiet one: 5 s, not more
  EXPECT_EQ(received(quiet.get()), "");
  EXPECT_FALSE(closedByServer(quiet.get()));
  server->poll(kEcho, 5 * kNsPerSecond + 1);
  EXPECT_EQ(received(quiet.get()), "error nothing received for 5 s: closed\n");
  EXPECT_TRUE(closedByServer(quiet.get()));
  EXPECT_EQ(received(busy.get()), "ok link-up cable=master\n");
  EXPECT_FALSE(closedByServer(busy.get()));
  EXPECT_EQ(server->clients(), 1u);
}

// `ecsim ctl` without --socket or --iface (issue #16 item 7): the only socket of the folder
// `ecsim serve` puts them in; none or several is an error that names them.
TEST_F(ControlServerTest, ClientFindsTheOnlySocketAndRefusesToGuessBetweenSeveral) {
  std::filesystem::create_directories(dir_);
  auto none = findControlSocket(dir_);
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.error().context.find("no control socket in " + dir_.string()), std::string::npos);
  auto first = ControlServer::open(dir_ / "ecs0.sock");
  ASSERT_TRUE(first.ok()) << first.error().message();
  std::ofstream(dir_ / "notes.txt") << "not a socket";
  std::ofstream(dir_ / "stale.sock") << "a file, not a socket";
  auto one = findControlSocket(dir_);
  ASSERT_TRUE(one.ok()) << one.error().message();
  EXPECT_EQ(*one, dir_ / "ecs0.sock");
  auto second = ControlServer::open(dir_ / "ecs1.sock");
  ASSERT_TRUE(second.ok()) << second.error().message();
  auto two = findControlSocket(dir_);
  ASSERT_FALSE(two.ok());
  EXPECT_NE(two.error().context.find("(ecs0.sock, ecs1.sock): choose one with --iface IF"),
            std::string::npos)
      << two.error().context;
  EXPECT_EQ(defaultControlSocket("ecs0"), std::filesystem::path("/run/ecsim/ecs0.sock"));
}

}  // namespace
}  // namespace ecsim::topology
