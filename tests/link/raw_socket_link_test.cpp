#include "link/raw_socket_link.hpp"

#include <gtest/gtest.h>
#include <poll.h>
#include <sched.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <string>
#include <vector>

#include "link/netns.hpp"
#include "test_support.hpp"

namespace ecsim {
namespace {

using namespace std::chrono_literals;
using testing::etherCatFrame;
using testing::otherFrame;

class RawSocketLinkTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ECSIM_REQUIRE_NETWORK_PRIVILEGES();
    auto created = VethNamespace::create();
    ASSERT_TRUE(created.ok()) << created.error().message();
    ns_ = std::make_unique<VethNamespace>(std::move(*created));
  }

  Result<RawSocketLink> open(const std::string& iface) {
    return RawSocketLink::open(iface, RawSocketOptions{ns_->name(), true});
  }

  std::string promiscuity(const std::string& iface) {
    auto out = ns_->run({"ip", "-d", "-o", "link", "show", iface});
    if (!out.ok()) return "";
    const auto at = out->output.find("promiscuity ");
    return at == std::string::npos ? "" : out->output.substr(at, 13);
  }

  std::unique_ptr<VethNamespace> ns_;
  std::array<std::uint8_t, kMaxFrameSize> buf_{};
};

// The receive tests, each run twice: frames taken from the socket (recvmsg) and from the
// receive ring that busy-polling uses (link/packet_rx_ring.hpp); both must hand over the same
// frames, tags and errors.
class RawSocketReceiveTest : public RawSocketLinkTest,
                             public ::testing::WithParamInterface<bool> {
 protected:
  Result<RawSocketLink> open(const std::string& iface) {
    auto link = RawSocketLink::open(
        iface, RawSocketOptions{.netns = ns_->name(), .promiscuous = true, .busyPoll = GetParam()});
    if (link.ok()) {
      EXPECT_EQ(link->receivesWithoutSystemCalls(), GetParam());
    }
    return link;
  }
};

std::string receiveName(const ::testing::TestParamInfo<bool>& info) {
  return info.param ? "Ring" : "Socket";
}

TEST_P(RawSocketReceiveTest, CarriesEtherCatFramesBetweenTheEnds) {
  auto master = open(ns_->masterInterface());
  ASSERT_TRUE(master.ok()) << master.error().message();
  auto sim = open(ns_->simulatorInterface());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  EXPECT_NE(master->describe().find(ns_->masterInterface()), std::string::npos);
  EXPECT_GT(master->interfaceIndex(), 0);
  EXPECT_NE(master->macAddress(), MacAddress{});

  const auto request = etherCatFrame(3);
  ASSERT_TRUE(master->send(request).ok());
  auto n = sim->receive(buf_, 2s);
  ASSERT_TRUE(n.ok()) << n.error().message();
  ASSERT_EQ(*n, request.size());
  EXPECT_EQ(std::vector<std::uint8_t>(buf_.begin(), buf_.begin() + 60), request);

  // The reply travels back, also to a unicast MAC that is not the interface's own.
  const auto reply = etherCatFrame(4, {0x02, 0x00, 0x00, 0x00, 0x00, 0x99});
  ASSERT_TRUE(sim->send(reply).ok());
  n = master->receive(buf_, 2s);
  ASSERT_TRUE(n.ok()) << n.error().message();
  ASSERT_EQ(*n, reply.size());
  EXPECT_EQ(std::vector<std::uint8_t>(buf_.begin(), buf_.begin() + 60), reply);
}

// An 802.1Q-tagged EtherCAT frame arrives with its tag where it was on the wire: the kernel
// strips the tag before the socket and reports it aside (PACKET_AUXDATA); receive() puts it
// back, so an answer built in place carries it as a real ESC passes it through.
TEST_P(RawSocketReceiveTest, ReceivesAVlanTaggedFrameWithItsTag) {
  auto master = open(ns_->masterInterface());
  ASSERT_TRUE(master.ok()) << master.error().message();
  auto sim = open(ns_->simulatorInterface());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  const auto plain = etherCatFrame(7);
  std::vector<std::uint8_t> tagged(plain.begin(), plain.begin() + 12);
  const std::uint16_t tci = 0x6005;  // priority 3, VLAN 5
  tagged.insert(tagged.end(), {0x81, 0x00, static_cast<std::uint8_t>(tci >> 8),
                               static_cast<std::uint8_t>(tci & 0xFF)});
  tagged.insert(tagged.end(), plain.begin() + 12, plain.end());
  ASSERT_TRUE(master->send(tagged).ok());
  auto n = sim->receive(buf_, 2s);
  ASSERT_TRUE(n.ok()) << n.error().message();
  ASSERT_EQ(*n, tagged.size()) << "the 4-byte tag is missing";
  EXPECT_EQ(std::vector<std::uint8_t>(buf_.begin(), buf_.begin() + static_cast<long>(*n)), tagged);
  // An untagged frame stays untagged.
  ASSERT_TRUE(master->send(plain).ok());
  n = sim->receive(buf_, 2s);
  ASSERT_TRUE(n.ok()) << n.error().message();
  EXPECT_EQ(std::vector<std::uint8_t>(buf_.begin(), buf_.begin() + static_cast<long>(*n)), plain);
}

TEST_P(RawSocketReceiveTest, DoesNotDeliverOtherEtherTypes) {
  auto master = open(ns_->masterInterface());
  auto sim = open(ns_->simulatorInterface());
  ASSERT_TRUE(master.ok() && sim.ok());
  ASSERT_TRUE(master->send(otherFrame()).ok());
  ASSERT_TRUE(master->send(etherCatFrame(5)).ok());
  // The first frame to arrive is the EtherCAT one; the 0x88B5 frame never queued.
  auto n = sim->receive(buf_, 2s);
  ASSERT_TRUE(n.ok());
  ASSERT_EQ(*n, 60u);
  EXPECT_EQ(readBe16(buf_, 12), kEtherTypeEtherCat);
  EXPECT_EQ(buf_[kEthernetHeaderSize + 3], 5);  // datagram index
  n = sim->receive(buf_, 100ms);
  ASSERT_TRUE(n.ok());
  EXPECT_EQ(*n, 0u);
}

TEST_P(RawSocketReceiveTest, DoesNotReceiveItsOwnFrames) {
  auto master = open(ns_->masterInterface());
  auto sim = open(ns_->simulatorInterface());
  ASSERT_TRUE(master.ok() && sim.ok());
  EXPECT_TRUE(master->kernelIgnoresOutgoing());  // Linux >= 4.20
  ASSERT_TRUE(master->send(etherCatFrame(6)).ok());
  auto own = master->receive(buf_, 200ms);
  ASSERT_TRUE(own.ok());
  EXPECT_EQ(*own, 0u);
  auto peer = sim->receive(buf_, 2s);
  ASSERT_TRUE(peer.ok());
  EXPECT_EQ(*peer, 60u);
}

TEST_P(RawSocketReceiveTest, PollFdSignalsAWaitingFrame) {
  auto master = open(ns_->masterInterface());
  auto sim = open(ns_->simulatorInterface());
  ASSERT_TRUE(master.ok() && sim.ok());
  ASSERT_TRUE(master->send(etherCatFrame(7)).ok());
  pollfd pfd{sim->pollFd(), POLLIN, 0};
  ASSERT_EQ(::poll(&pfd, 1, 2000), 1);
  auto n = sim->receive(buf_, 0ns);
  ASSERT_TRUE(n.ok());
  EXPECT_EQ(*n, 60u);
}

TEST_P(RawSocketReceiveTest, TimesOutAndRefusesBadFrames) {
  auto master = open(ns_->masterInterface());
  ASSERT_TRUE(master.ok());
  const auto start = std::chrono::steady_clock::now();
  auto n = master->receive(buf_, 50ms);
  ASSERT_TRUE(n.ok());
  EXPECT_EQ(*n, 0u);
  EXPECT_GE(std::chrono::steady_clock::now() - start, 50ms);

  auto big = master->send(std::vector<std::uint8_t>(kMaxFrameSize + 1));
  ASSERT_FALSE(big.ok());
  EXPECT_EQ(big.error().code, ErrorCode::kTooLarge);
  auto tiny = master->send(std::vector<std::uint8_t>(10));
  ASSERT_FALSE(tiny.ok());
  EXPECT_EQ(tiny.error().code, ErrorCode::kInvalidArgument);
  EXPECT_TRUE(master->send(std::vector<std::uint8_t>(kMaxFrameSize, 0)).ok());
}

// Issue 18: the served path's options. Busy-polling carries frames and still ends an empty
// wait at its timeout; frames sent past the queueing discipline reach the other end.
TEST_F(RawSocketLinkTest, BusyPollAndQdiscBypassCarryFramesAndKeepTheTimeout) {
  auto master = open(ns_->masterInterface());
  auto sim = RawSocketLink::open(ns_->simulatorInterface(),
                                 {.netns = ns_->name(), .qdiscBypass = true, .busyPoll = true});
  ASSERT_TRUE(master.ok() && sim.ok());
  const auto start = std::chrono::steady_clock::now();
  auto n = sim->receive(buf_, 20ms);
  ASSERT_TRUE(n.ok());
  EXPECT_EQ(*n, 0u);
  EXPECT_GE(std::chrono::steady_clock::now() - start, 20ms);

  const auto request = etherCatFrame(3);
  ASSERT_TRUE(master->send(request).ok());
  n = sim->receive(buf_, 2s);
  ASSERT_TRUE(n.ok()) << n.error().message();
  EXPECT_EQ(std::vector<std::uint8_t>(buf_.begin(), buf_.begin() + 60), request);

  const auto reply = etherCatFrame(4);
  ASSERT_TRUE(sim->send(reply).ok());
  n = master->receive(buf_, 2s);
  ASSERT_TRUE(n.ok()) << n.error().message();
  EXPECT_EQ(std::vector<std::uint8_t>(buf_.begin(), buf_.begin() + 60), reply);
  n = sim->receive(buf_, 0ms);
  ASSERT_TRUE(n.ok());
  EXPECT_EQ(*n, 0u) << "its own frame does not come back";
}

// Issue 18: `ecsim serve --busy-poll` sends through a kernel thread on another CPU
// (link/kernel_thread_sender.hpp). The frames reach the other end as with send(2), and an
// interface that is down is reported the same way.
TEST_F(RawSocketLinkTest, SendsThroughAKernelThreadOnAnotherCpu) {
  const long cpus = ::sysconf(_SC_NPROCESSORS_ONLN);
  ECSIM_REQUIRE_OR_SKIP(cpus >= 2, "one CPU: no other CPU for the sending thread");
  const int cpu = (::sched_getcpu() + 1) % static_cast<int>(cpus);
  auto master = open(ns_->masterInterface());
  auto sim = RawSocketLink::open(
      ns_->simulatorInterface(),
      {.netns = ns_->name(), .qdiscBypass = true, .busyPoll = true, .sendCpu = cpu});
  ASSERT_TRUE(master.ok()) << master.error().message();
  if (!sim.ok() && sim.error().code == ErrorCode::kUnsupported) {
    ECSIM_REQUIRE_OR_SKIP(false, sim.error().message());
  }
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  ASSERT_NE(sim->kernelThreadSender(), nullptr);
  EXPECT_EQ(sim->kernelThreadSender()->cpu(), cpu);
  for (std::uint8_t i = 0; i < 50; ++i) {
    const auto reply = etherCatFrame(i);
    ASSERT_TRUE(sim->send(reply).ok());
    auto n = master->receive(buf_, 2s);
    ASSERT_TRUE(n.ok()) << n.error().message();
    ASSERT_EQ(std::vector<std::uint8_t>(buf_.begin(), buf_.begin() + 60), reply);
  }
  auto n = sim->receive(buf_, 0ms);
  ASSERT_TRUE(n.ok());
  EXPECT_EQ(*n, 0u) << "its own frames do not come back";

  ASSERT_TRUE(ns_->run({"ip", "link", "set", "dev", ns_->simulatorInterface(), "down"}).ok());
  const auto sent = sim->send(etherCatFrame(1));
  ASSERT_FALSE(sent.ok());
  EXPECT_NE(sent.error().context.find("is down"), std::string::npos) << sent.error().context;
}

TEST_P(RawSocketReceiveTest, SmallReceiveBufferIsAnError) {
  auto master = open(ns_->masterInterface());
  auto sim = open(ns_->simulatorInterface());
  ASSERT_TRUE(master.ok() && sim.ok());
  ASSERT_TRUE(master->send(etherCatFrame(8)).ok());
  std::array<std::uint8_t, 32> small{};
  auto n = sim->receive(small, 2s);
  ASSERT_FALSE(n.ok());
  EXPECT_EQ(n.error().code, ErrorCode::kTooLarge);
}

TEST_F(RawSocketLinkTest, PromiscuousWhileOpen) {
  const std::string iface = ns_->simulatorInterface();
  EXPECT_EQ(promiscuity(iface), "promiscuity 0");
  {
    auto sim = open(iface);
    ASSERT_TRUE(sim.ok());
    EXPECT_EQ(promiscuity(iface), "promiscuity 1");
  }
  EXPECT_EQ(promiscuity(iface), "promiscuity 0");
}

TEST_F(RawSocketLinkTest, NamesAMissingInterface) {
  auto link = open("nosuchif0");
  ASSERT_FALSE(link.ok());
  EXPECT_EQ(link.error().code, ErrorCode::kNotFound);
  EXPECT_NE(link.error().context.find("nosuchif0"), std::string::npos);
  EXPECT_NE(link.error().context.find(ns_->name()), std::string::npos);

  // The namespace's interfaces are not found outside it.
  auto outside = RawSocketLink::open(ns_->masterInterface());
  ASSERT_FALSE(outside.ok());
  EXPECT_EQ(outside.error().code, ErrorCode::kNotFound);

  auto noNamespace = RawSocketLink::open("lo", RawSocketOptions{"ecsim-no-such-namespace", true});
  ASSERT_FALSE(noNamespace.ok());
  EXPECT_EQ(noNamespace.error().code, ErrorCode::kNotFound);

  auto tooLong = RawSocketLink::open("a-name-of-16-chr");
  ASSERT_FALSE(tooLong.ok());
  EXPECT_EQ(tooLong.error().code, ErrorCode::kInvalidArgument);
}

TEST_F(RawSocketLinkTest, NamesCapNetRawWhenRefused) {
  const std::string netns = ns_->name();
  const std::string iface = ns_->masterInterface();
  const int code = testing::runWithoutCapability(CAP_NET_RAW, [&] {
    auto link = RawSocketLink::open(iface, RawSocketOptions{netns, true});
    if (link.ok()) return 1;
    if (link.error().code != ErrorCode::kPermission) return 2;
    if (link.error().context.find("CAP_NET_RAW") == std::string::npos) return 3;
    return 0;
  });
  EXPECT_EQ(code, 0) << "1: opened anyway, 2: wrong code, 3: message lacks CAP_NET_RAW";
}

INSTANTIATE_TEST_SUITE_P(Both, RawSocketReceiveTest, ::testing::Bool(), receiveName);

}  // namespace
}  // namespace ecsim
