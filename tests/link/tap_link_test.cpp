#include "link/tap_link.hpp"

#include <gtest/gtest.h>
#include <sched.h>
#include <sys/mount.h>

#include <array>
#include <chrono>
#include <string>
#include <vector>

#include "link/netns.hpp"
#include "link/raw_socket_link.hpp"
#include "test_support.hpp"

namespace ecsim {
namespace {

using namespace std::chrono_literals;
using testing::etherCatFrame;
using testing::otherFrame;

class TapLinkTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ECSIM_REQUIRE_NETWORK_PRIVILEGES();
    auto created = VethNamespace::create();
    ASSERT_TRUE(created.ok()) << created.error().message();
    ns_ = std::make_unique<VethNamespace>(std::move(*created));
    // Unique within our namespace anyway; the suffix keeps it recognisable.
    tapName_ = "ect-" + ns_->masterInterface().substr(4);
  }

  bool existsInside(const std::string& iface) {
    auto out = ns_->run({"ip", "link", "show", iface});
    return out.ok() && out->exitCode == 0;
  }

  std::unique_ptr<VethNamespace> ns_;
  std::string tapName_;
  std::array<std::uint8_t, kMaxFrameSize> buf_{};
};

TEST_F(TapLinkTest, CarriesFramesBothWaysInsideTheNamespace) {
  auto tap = TapLink::open(tapName_, TapOptions{ns_->name(), true});
  ASSERT_TRUE(tap.ok()) << tap.error().message();
  EXPECT_EQ(tap->interfaceName(), tapName_);
  EXPECT_TRUE(existsInside(tapName_));
  auto outside = runCommand({"ip", "link", "show", tapName_});
  ASSERT_TRUE(outside.ok());
  EXPECT_NE(outside->exitCode, 0) << "TAP device leaked into the test's namespace";
  auto state = ns_->run({"ip", "-o", "link", "show", tapName_});
  ASSERT_TRUE(state.ok());
  EXPECT_NE(state->output.find(",UP"), std::string::npos) << state->output;

  // A master on the interface side of the TAP, the caller of TapLink on the other.
  auto master = RawSocketLink::open(tapName_, RawSocketOptions{ns_->name(), true});
  ASSERT_TRUE(master.ok()) << master.error().message();

  ASSERT_TRUE(master->send(etherCatFrame(1)).ok());
  auto n = tap->receive(buf_, 2s);
  ASSERT_TRUE(n.ok()) << n.error().message();
  ASSERT_EQ(*n, 60u);
  EXPECT_EQ(std::vector<std::uint8_t>(buf_.begin(), buf_.begin() + 60), etherCatFrame(1));

  ASSERT_TRUE(tap->send(etherCatFrame(2)).ok());
  n = master->receive(buf_, 2s);
  ASSERT_TRUE(n.ok()) << n.error().message();
  ASSERT_EQ(*n, 60u);
  EXPECT_EQ(std::vector<std::uint8_t>(buf_.begin(), buf_.begin() + 60), etherCatFrame(2));

  // The TapLink never reads back what it wrote.
  n = tap->receive(buf_, 100ms);
  ASSERT_TRUE(n.ok());
  EXPECT_EQ(*n, 0u);
}

TEST_F(TapLinkTest, CountsAndDropsOtherEtherTypes) {
  auto tap = TapLink::open(tapName_, TapOptions{ns_->name(), true});
  ASSERT_TRUE(tap.ok()) << tap.error().message();
  auto master = RawSocketLink::open(tapName_, RawSocketOptions{ns_->name(), true});
  ASSERT_TRUE(master.ok()) << master.error().message();
  const auto droppedBefore = tap->droppedNonEtherCat();
  ASSERT_TRUE(master->send(otherFrame()).ok());
  ASSERT_TRUE(master->send(otherFrame()).ok());
  ASSERT_TRUE(master->send(etherCatFrame(3)).ok());
  auto n = tap->receive(buf_, 2s);
  ASSERT_TRUE(n.ok());
  ASSERT_EQ(*n, 60u);
  EXPECT_EQ(readBe16(buf_, 12), kEtherTypeEtherCat);
  EXPECT_EQ(tap->droppedNonEtherCat() - droppedBefore, 2u);
}

TEST_F(TapLinkTest, DeviceDisappearsWhenTheLinkCloses) {
  {
    auto tap = TapLink::open(tapName_, TapOptions{ns_->name(), true});
    ASSERT_TRUE(tap.ok()) << tap.error().message();
    EXPECT_TRUE(existsInside(tapName_));
    auto big = tap->send(std::vector<std::uint8_t>(kMaxFrameSize + 1));
    ASSERT_FALSE(big.ok());
    EXPECT_EQ(big.error().code, ErrorCode::kTooLarge);
  }
  EXPECT_FALSE(existsInside(tapName_));
}

TEST_F(TapLinkTest, KernelChosenName) {
  auto tap = TapLink::open("", TapOptions{ns_->name(), false});
  ASSERT_TRUE(tap.ok()) << tap.error().message();
  EXPECT_FALSE(tap->interfaceName().empty());
  EXPECT_TRUE(existsInside(tap->interfaceName()));
}

TEST_F(TapLinkTest, NamesCapNetAdminWhenRefused) {
  const std::string netns = ns_->name();
  const std::string name = tapName_;
  const int code = testing::runWithoutCapability(CAP_NET_ADMIN, [&] {
    auto tap = TapLink::open(name, TapOptions{netns, true});
    if (tap.ok()) return 1;
    if (tap.error().code != ErrorCode::kPermission) return 2;
    if (tap.error().context.find("CAP_NET_ADMIN") == std::string::npos) return 3;
    return 0;
  });
  EXPECT_EQ(code, 0) << "1: opened anyway, 2: wrong code, 3: message lacks CAP_NET_ADMIN";
}

TEST_F(TapLinkTest, ReportsAMissingTunDevice) {
  const std::string netns = ns_->name();
  const std::string name = tapName_;
  // In a forked child with a private mount namespace, hide /dev/net under an empty tmpfs.
  const int code = testing::runInChild([&] {
    if (::unshare(CLONE_NEWNS) != 0) return 10;
    if (::mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr) != 0) return 11;
    if (::mount("tmpfs", "/dev/net", "tmpfs", 0, nullptr) != 0) return 12;
    auto tap = TapLink::open(name, TapOptions{netns, true});
    if (tap.ok()) return 1;
    if (tap.error().code != ErrorCode::kNotFound) return 2;
    if (tap.error().context.find("/dev/net/tun") == std::string::npos) return 3;
    return 0;
  });
  ASSERT_NE(code, 10) << "unshare(CLONE_NEWNS) failed";
  ASSERT_NE(code, 11);
  ASSERT_NE(code, 12) << "could not mount a tmpfs over /dev/net";
  EXPECT_EQ(code, 0) << "1: opened anyway, 2: wrong code, 3: message lacks /dev/net/tun";
}

}  // namespace
}  // namespace ecsim
