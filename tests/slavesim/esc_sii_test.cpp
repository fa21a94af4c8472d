// The SII EEPROM interface's timing and size (issue #15 item 7): a command keeps the interface
// busy for the time the device's EEPROM takes, with the busy bit and the command bits held
// (ESC datasheet section II 0x0502; real EK1100 in ../shared/pcap/replay-dc.pcapng frames
// 104-110: 0x8140 while busy, 0x0040 after); the data registers are valid once busy clears; a
// command written while busy is ignored; addresses beyond the EEPROM wrap around as on an I2C
// EEPROM (section I §11.3.3.2).
#include <gtest/gtest.h>

#include "protocol/registers.hpp"
#include "support/test_network.hpp"

namespace ecsim::testing {
namespace {

constexpr std::uint16_t kStation = 0x1001;

class SiiTiming : public ::testing::Test {
 protected:
  void build(const slavesim::EscType& type) {
    seg_.addSlave(std::make_unique<slavesim::Slave>("s", type, makeSii(0x0000ABCD, 0x100),
                                                    slavesim::SlaveProfile{}));
    seg_.wireLine();
    send(Command::kApwr, reg::kConfiguredStationAddress.address, le16(kStation));
  }
  DatagramResult send(Command c, std::uint16_t ado, std::vector<std::uint8_t> data) {
    auto r = one(seg_, c, phys(c == Command::kApwr ? 0 : kStation, ado), std::move(data), now_);
    now_ += 10 * kNsPerUs;
    return r;
  }
  void command(std::uint16_t cmd, std::uint32_t word, std::vector<std::uint8_t> extra = {}) {
    std::vector<std::uint8_t> bytes(6, 0);
    writeLe16(bytes, 0, cmd);
    writeLe32(bytes, 2, word);
    bytes.insert(bytes.end(), extra.begin(), extra.end());
    commandAt_ = now_;
    send(Command::kFpwr, reg::kSiiControlStatus.address, bytes);
  }
  std::uint16_t status() {
    return readLe16(send(Command::kFprd, reg::kSiiControlStatus.address, {0, 0}).data, 0);
  }
  std::uint32_t data32() {
    return readLe32(send(Command::kFprd, reg::kSiiData.address, {0, 0, 0, 0}).data, 0);
  }
  // Lets simulated time pass up to `offset` after the last command.
  void at(SimTime offset) { now_ = std::max(now_, commandAt_ + offset); }

  topology::Segment seg_;
  SimTime now_{kNsPerMs};
  SimTime commandAt_{0};
};

TEST_F(SiiTiming, ReadIsBusyForTheDeviceTimeWithTheCommandBitsHeld) {
  build(slavesim::kEt1100);
  const SimTime busy = slavesim::kEt1100.siiBusyNs;
  command(reg::sii::kCommandRead, 0x08);  // vendor id
  // replay-dc.pcapng frame 106: 0x8140 (busy, read command, 8-byte reads) from a real EK1100.
  EXPECT_EQ(status(), reg::sii::kBusy | reg::sii::kCommandRead | reg::sii::kReadSize8Bytes);
  EXPECT_EQ(data32(), 0u) << "the data registers are not valid before busy clears";
  at(busy - 20 * kNsPerUs);
  EXPECT_NE(status() & reg::sii::kBusy, 0) << "still busy just before the device time";
  at(busy);
  EXPECT_EQ(status(), reg::sii::kReadSize8Bytes) << "frame 110: 0x0040, command bits cleared";
  EXPECT_EQ(data32(), 0x0000ABCDu);
}

TEST_F(SiiTiming, BusyTimeIsAParameterOfTheEscType) {
  // ET1200 terminals of replay-dc.pcapng take longer than the EK1100 (esc_type.hpp).
  build(slavesim::kEt1200);
  ASSERT_GT(slavesim::kEt1200.siiBusyNs, slavesim::kEt1100.siiBusyNs);
  command(reg::sii::kCommandRead, 0x08);
  at(slavesim::kEt1100.siiBusyNs);
  EXPECT_NE(status() & reg::sii::kBusy, 0);
  at(slavesim::kEt1200.siiBusyNs);
  EXPECT_EQ(status() & reg::sii::kBusy, 0);
}

TEST_F(SiiTiming, CommandWrittenWhileBusyIsIgnored) {
  build(slavesim::kEt1100);
  command(reg::sii::kCommandRead, 0x08);
  const SimTime first = commandAt_;
  at(100 * kNsPerUs);
  command(reg::sii::kCommandRead, 0x0A);  // product code: not taken, the interface is busy
  now_ = first + slavesim::kEt1100.siiBusyNs + 10 * kNsPerUs;  // the first command's time is over
  EXPECT_EQ(status() & reg::sii::kBusy, 0) << "the second command did not restart busy";
  EXPECT_EQ(data32(), 0x0000ABCDu) << "the first command's data";
  EXPECT_EQ(readLe32(send(Command::kFprd, reg::kSiiAddress.address, {0, 0, 0, 0}).data, 0), 8u)
      << "the address written while busy was ignored too";
}

TEST_F(SiiTiming, WriteTakesEffectAfterBusy) {
  build(slavesim::kEt1100);
  command(reg::sii::kCommandWrite | reg::sii::kWriteEnable, 0x40, {0x34, 0x12});
  EXPECT_NE(status() & reg::sii::kBusy, 0);
  at(slavesim::kEt1100.siiBusyNs);
  EXPECT_EQ(status() & (reg::sii::kBusy | reg::sii::kErrorMask), 0);
  EXPECT_EQ(seg_.slave(0).esc().sii()[0x80], 0x34);
  EXPECT_EQ(seg_.slave(0).esc().sii()[0x81], 0x12);
}

TEST_F(SiiTiming, AddressesBeyondTheEepromWrapAround) {
  build(slavesim::kEt1100);
  const auto words = static_cast<std::uint32_t>(seg_.slave(0).esc().sii().size() / 2);
  command(reg::sii::kCommandRead, words + 0x08);  // one EEPROM size past the vendor id
  at(slavesim::kEt1100.siiBusyNs);
  EXPECT_EQ(status() & reg::sii::kErrorMask, 0);
  EXPECT_EQ(data32(), 0x0000ABCDu) << "address modulo the EEPROM size";
  command(reg::sii::kCommandRead, words - 1);  // the last word, then words 0-2 (8-byte read)
  at(slavesim::kEt1100.siiBusyNs);
  status();
  auto d = send(Command::kFprd, reg::kSiiData.address, std::vector<std::uint8_t>(8, 0)).data;
  EXPECT_EQ(readLe16(d, 2), 0x0104) << "word 0 (PDI control of the EL2004 config area) follows";
  command(reg::sii::kCommandWrite | reg::sii::kWriteEnable, 2 * words + 0x41, {0x78, 0x56});
  at(slavesim::kEt1100.siiBusyNs);
  EXPECT_EQ(status() & reg::sii::kErrorMask, 0);
  EXPECT_EQ(seg_.slave(0).esc().sii()[0x82], 0x78) << "written at word 0x41";
}

}  // namespace
}  // namespace ecsim::testing
