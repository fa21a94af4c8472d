// Typed register access of the master's datagrams (master/datagram.hpp): width and offsets come
// from the register map (protocol/registers.hpp, ESC datasheet section II), never from the
// caller.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>

#include "master/datagram.hpp"
#include "protocol/registers.hpp"

namespace ecsim::master {
namespace {

TEST(DatagramRegisters, OneReadOverSeveralRegistersGivesEachItsValue) {
  Datagram d;
  d.fprd(0x1001, reg::kAlStatus, reg::kAlStatusCode);  // 0x0130-0x0135, as SOEM reads it
  EXPECT_EQ(d.command(), Command::kFprd);
  EXPECT_EQ(d.adp(), 0x1001);
  EXPECT_EQ(d.ado(), 0x0130);
  EXPECT_EQ(d.length(), 6);
  EXPECT_EQ(d.expectedWkc(), 1);
  // What an EL1004 answers when it refuses SAFEOP: status 0x0012, code 0x001D.
  const std::array<std::uint8_t, 6> answer{0x12, 0x00, 0x00, 0x00, 0x1D, 0x00};
  std::copy(answer.begin(), answer.end(), d.data().begin());
  EXPECT_EQ(d.get(reg::kAlStatus), 0x0012);
  EXPECT_EQ(d.get(reg::kAlStatusCode), 0x001D);
}

TEST(DatagramRegisters, AWriteHasTheRegistersWidthLittleEndian) {
  Datagram d;
  d.fpwr(0x1002, reg::kSystemTimeOffset, 0x0102030405060708u);
  EXPECT_EQ(d.command(), Command::kFpwr);
  EXPECT_EQ(d.ado(), 0x0920);
  ASSERT_EQ(d.length(), 8);
  const std::array<std::uint8_t, 8> le{0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01};
  EXPECT_TRUE(std::equal(le.begin(), le.end(), d.data().begin()));

  d.write(Command::kBwr, 0, reg::kAlControl, 0x0011, 3);
  EXPECT_EQ(d.command(), Command::kBwr);
  EXPECT_EQ(d.adp(), 0);
  EXPECT_EQ(d.ado(), 0x0120);
  ASSERT_EQ(d.length(), 2);
  EXPECT_EQ(d.data()[0], 0x11);
  EXPECT_EQ(d.data()[1], 0x00);
  EXPECT_EQ(d.expectedWkc(), 3);
}

TEST(DatagramRegisters, AutoIncrementReadOfOneRegister) {
  Datagram d;
  d.read(Command::kAprd, Datagram::autoIncrement(2), reg::kConfiguredStationAddress);
  EXPECT_EQ(d.adp(), 0xFFFE);
  EXPECT_EQ(d.ado(), 0x0010);
  EXPECT_EQ(d.length(), 2);
  d.data()[0] = 0x03;
  d.data()[1] = 0x10;
  EXPECT_EQ(d.get(reg::kConfiguredStationAddress), 0x1003);
}

// A register the datagram did not read is 0, never bytes from outside the datagram.
TEST(DatagramRegisters, ARegisterOutsideTheReadIsZero) {
  Datagram d;
  d.fprd(0x1001, reg::kAlStatus);
  std::fill(d.data().begin(), d.data().end(), std::uint8_t{0xFF});
  EXPECT_EQ(d.get(reg::kAlStatus), 0xFFFF);
  EXPECT_EQ(d.get(reg::kAlStatusCode), 0);  // 0x0134: past the 2 bytes read
  EXPECT_EQ(d.get(reg::kAlControl), 0);     // 0x0120: before them
}

}  // namespace
}  // namespace ecsim::master
