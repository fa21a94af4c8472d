// The MII management interface (0x0510-0x0517, ESC datasheet section II; section I "MII
// management interface") with one IEEE 802.3 clause 22 PHY per MII port (issue #15 item 8):
// a diagnostic tool reading link state over MDIO sees what the topology says.
#include <gtest/gtest.h>

#include <optional>

#include "protocol/mii.hpp"
#include "protocol/registers.hpp"
#include "support/test_network.hpp"

namespace ecsim::testing {
namespace {

// One MDIO frame: 64 bits at 2.5 MHz (IEEE 802.3 22.2.2.13).
constexpr SimTime kMdioFrame = 25'600;

class Mii : public ::testing::Test {
 protected:
  void SetUp() override {
    buildLine(seg_, 2);
    for (std::uint16_t i = 0; i < 2; ++i) {
      one(seg_, Command::kApwr, phys(static_cast<std::uint16_t>(-i), 0x0010),
          le16(static_cast<std::uint16_t>(0x1001 + i)), now_);
    }
  }
  DatagramResult send(std::uint16_t station, Command c, std::uint16_t ado,
                      std::vector<std::uint8_t> data) {
    auto r = one(seg_, c, phys(station, ado), std::move(data), now_);
    now_ += kNsPerUs;
    return r;
  }
  std::uint16_t control(std::uint16_t station) {
    return readLe16(send(station, Command::kFprd, reg::kMiiControlStatus.address, {0, 0}).data, 0);
  }
  // Starts a command with PHY and register address in the same write, as masters do.
  void command(std::uint16_t station, std::uint16_t cmd, std::uint8_t phy, std::uint8_t index,
               std::optional<std::uint16_t> data = {}) {
    std::vector<std::uint8_t> bytes{static_cast<std::uint8_t>(cmd),
                                    static_cast<std::uint8_t>(cmd >> 8), phy, index};
    if (data) {
      bytes.push_back(static_cast<std::uint8_t>(*data));
      bytes.push_back(static_cast<std::uint8_t>(*data >> 8));
    }
    send(station, Command::kFpwr, reg::kMiiControlStatus.address, bytes);
  }
  // A complete read as a tool does it: command, wait out busy, read the data.
  std::uint16_t phyRead(std::uint16_t station, std::uint8_t phy, std::uint8_t index) {
    command(station, reg::mii::kCommandRead, phy, index);
    now_ += kMdioFrame;
    EXPECT_EQ(control(station) & reg::mii::kBusy, 0);
    return readLe16(send(station, Command::kFprd, reg::kPhyData.address, {0, 0}).data, 0);
  }

  topology::Segment seg_;
  SimTime now_{kNsPerMs};
};

TEST_F(Mii, LinkStatusFollowsTheTopology) {
  // Slave 0: port 0 to the master, port 1 to slave 1, ports 2 and 3 without cable.
  for (std::uint8_t port = 0; port < 4; ++port) {
    const std::uint16_t status = phyRead(0x1001, port, reg::phy::kStatus);
    const bool cabled = port < 2;
    EXPECT_EQ((status & reg::phy::kStatusLinkUp) != 0, cabled) << "port " << int(port);
    EXPECT_EQ((status & reg::phy::kStatusAutoNegComplete) != 0, cabled) << "port " << int(port);
    EXPECT_EQ(phyRead(0x1001, port, reg::phy::kLinkPartner) != 0, cabled) << "port " << int(port);
  }
  // A cut cable (fault injection, or unplugged): both ends see the link go down.
  seg_.setLinkUp(1, 0, false);
  EXPECT_EQ(phyRead(0x1001, 1, reg::phy::kStatus) & reg::phy::kStatusLinkUp, 0);
  seg_.setLinkUp(1, 0, true);
  EXPECT_NE(phyRead(0x1001, 1, reg::phy::kStatus) & reg::phy::kStatusLinkUp, 0);
}

TEST_F(Mii, ReadIsBusyForOneMdioFrameWithTheCommandHeld) {
  const SimTime first = now_;
  command(0x1001, reg::mii::kCommandRead, 0, reg::phy::kId1);
  EXPECT_EQ(control(0x1001) & (reg::mii::kBusy | reg::mii::kCommandMask),
            reg::mii::kBusy | reg::mii::kCommandRead);
  now_ = first + 10 * kNsPerUs;
  command(0x1001, reg::mii::kCommandRead, 0, reg::phy::kId2);  // ignored while busy
  now_ = first + kMdioFrame + kNsPerUs;  // the first is done; a restarted one would not be
  EXPECT_EQ(control(0x1001) & (reg::mii::kBusy | reg::mii::kCommandMask | reg::mii::kErrorBits),
            0);
  EXPECT_EQ(readLe16(send(0x1001, Command::kFprd, reg::kPhyData.address, {0, 0}).data, 0), 0x2000)
      << "PHY ID 1 (DP83848), not ID 2: the second command was ignored";
  EXPECT_EQ(phyRead(0x1001, 0, reg::phy::kId2), 0x5C90);
}

TEST_F(Mii, NoPhyAtAnAddressIsAReadError) {
  EXPECT_EQ(phyRead(0x1001, 7, reg::phy::kStatus), 0xFFFF) << "MDIO pulled up";
  EXPECT_NE(control(0x1001) & reg::mii::kReadError, 0);
  command(0x1001, reg::mii::kCommandNop, 0, 0);  // a NOP clears the error bits
  EXPECT_EQ(control(0x1001) & reg::mii::kErrorBits, 0);
}

TEST_F(Mii, WriteNeedsWriteEnableAndChangesThePhy) {
  command(0x1001, reg::mii::kCommandWrite, 1, reg::phy::kAdvertisement, 0x0181);
  EXPECT_NE(control(0x1001) & reg::mii::kCommandError, 0) << "write without write enable";
  now_ += kMdioFrame;
  EXPECT_EQ(phyRead(0x1001, 1, reg::phy::kAdvertisement), 0x01E1) << "unchanged";
  command(0x1001, reg::mii::kCommandWrite | reg::mii::kWriteEnable, 1, reg::phy::kAdvertisement,
          0x0181);
  now_ += kMdioFrame;
  EXPECT_EQ(control(0x1001) & (reg::mii::kBusy | reg::mii::kErrorBits), 0);
  EXPECT_EQ(phyRead(0x1001, 1, reg::phy::kAdvertisement), 0x0181);
  // Auto-negotiation off (control register): the link stays, "complete" goes.
  command(0x1001, reg::mii::kCommandWrite | reg::mii::kWriteEnable, 1, reg::phy::kControl,
          reg::phy::kControlSpeed100 | reg::phy::kControlFullDuplex);
  now_ += kMdioFrame;
  const std::uint16_t status = phyRead(0x1001, 1, reg::phy::kStatus);
  EXPECT_NE(status & reg::phy::kStatusLinkUp, 0);
  EXPECT_EQ(status & reg::phy::kStatusAutoNegComplete, 0);
}

TEST_F(Mii, PdiAccessLocksTheEcatSideOut) {
  seg_.slave(0).esc().pdiWrite(reg::kMiiPdiAccessState, reg::mii::kPdiHasAccess);
  command(0x1001, reg::mii::kCommandRead, 0, reg::phy::kStatus);
  EXPECT_EQ(control(0x1001) & reg::mii::kBusy, 0) << "no command started";
  EXPECT_EQ(readLe16(send(0x1001, Command::kFprd, reg::kPhyAddress.address, {0, 0}).data, 0), 0)
      << "PHY and register address not written";
}

}  // namespace
}  // namespace ecsim::testing
