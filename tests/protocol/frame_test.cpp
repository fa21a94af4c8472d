#include "protocol/frame.hpp"

#include <gtest/gtest.h>

#include <array>
#include <vector>

namespace ecsim {
namespace {

// First frame SOEM v1.4.0 puts on the wire (../shared/notes/soem-interop.md §2, captured on a
// veth pair): BWR to 0x0103, 1 data byte 0x00, index 0, broadcast MAC, source 01:01:01:...
const std::vector<std::uint8_t> kSoemFirstFrame = {
    0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x88, 0xa4,  // Eth
    0x0d, 0x10,                                                  // EtherCAT: len 13, type 1
    0x08, 0x00, 0x00, 0x00, 0x03, 0x01, 0x01, 0x00, 0x00, 0x00,  // BWR idx0 adp0 ado0x0103
    0x00,                                                        // data
    0x00, 0x00,                                                  // wkc
};

TEST(Frame, ParsesSoemFirstFrame) {
  auto bytes = kSoemFirstFrame;
  bytes.resize(60, 0);
  auto frame = EtherCatFrame::parse(bytes);
  ASSERT_TRUE(frame.ok()) << frame.error().message();
  EXPECT_EQ(frame->etherCatHeader().length, 13);
  EXPECT_EQ(frame->datagramCount(), 1u);
  auto d = *frame->begin();
  EXPECT_EQ(d.command(), Command::kBwr);
  EXPECT_EQ(d.ado(), 0x0103);
  EXPECT_EQ(d.length(), 1);
  EXPECT_FALSE(d.more());
}

TEST(Frame, BuilderReproducesSoemFirstFrameBytes) {
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  EthernetHeader eth{kBroadcastMac, {1, 1, 1, 1, 1, 1}, std::nullopt, kEtherTypeEtherCat};
  FrameBuilder b(buf, eth);
  std::array<std::uint8_t, 1> data{0};
  ASSERT_TRUE(b.add(Command::kBwr, 0, DatagramHeader::physical(0, 0x0103), data).ok());
  auto len = b.finish();
  ASSERT_TRUE(len.ok());
  EXPECT_EQ(*len, 60u);
  std::vector<std::uint8_t> expected = kSoemFirstFrame;
  expected.resize(60, 0);
  EXPECT_EQ(std::vector<std::uint8_t>(buf.begin(), buf.begin() + 60), expected);
}

TEST(Frame, BuilderRefusesDatagramThatDoesNotFit) {
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  FrameBuilder b(buf, EthernetHeader{});
  // 1514 - 14 - 2 - 12 = 1486 data bytes fit exactly.
  ASSERT_TRUE(b.add(Command::kLrw, 1, 0, 1486).ok());
  auto more = b.add(Command::kNop, 1, 0, 0);
  ASSERT_FALSE(more.ok());
  EXPECT_EQ(more.error().code, ErrorCode::kTooLarge);
  EXPECT_EQ(b.datagramCount(), 1u);
  auto len = b.finish();
  ASSERT_TRUE(len.ok());
  EXPECT_EQ(*len, kMaxFrameSize);
}

TEST(Frame, ChainSetsMoreBits) {
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  FrameBuilder b(buf, EthernetHeader{});
  ASSERT_TRUE(b.add(Command::kLrw, 7, 0x10000, 4).ok());
  ASSERT_TRUE(b.add(Command::kFrmw, 7, DatagramHeader::physical(0x1001, 0x0910), 8).ok());
  auto len = b.finish();
  ASSERT_TRUE(len.ok());
  auto frame = EtherCatFrame::parse(std::span(buf.data(), *len));
  ASSERT_TRUE(frame.ok());
  ASSERT_EQ(frame->datagramCount(), 2u);
  auto it = frame->begin();
  EXPECT_TRUE((*it).more());
  EXPECT_EQ((*it).command(), Command::kLrw);
  ++it;
  EXPECT_FALSE((*it).more());
  EXPECT_EQ((*it).command(), Command::kFrmw);
  EXPECT_EQ((*it).adp(), 0x1001);
  ++it;
  EXPECT_TRUE(it == frame->end());
}

TEST(Frame, RejectsDatagramPastEnd) {
  auto bytes = kSoemFirstFrame;
  bytes[16 + 6] = 0x20;  // length 32, frame only has 1 data byte + wkc
  auto frame = EtherCatFrame::parse(bytes);
  ASSERT_FALSE(frame.ok());
  EXPECT_EQ(frame.error().code, ErrorCode::kTruncated);
  EXPECT_NE(frame.error().context.find("byte 22"), std::string::npos) << frame.error().context;
}

TEST(Frame, AcceptsVlanTag) {
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  EthernetHeader eth{kBroadcastMac, {2, 0, 0, 0, 0, 1}, std::uint16_t{0x0005}, kEtherTypeEtherCat};
  FrameBuilder b(buf, eth);
  ASSERT_TRUE(b.add(Command::kBrd, 3, 0, 2).ok());
  auto len = b.finish();
  ASSERT_TRUE(len.ok());
  EXPECT_EQ(buf[12], 0x81);
  EXPECT_EQ(buf[13], 0x00);
  auto frame = EtherCatFrame::parse(std::span(buf.data(), *len));
  ASSERT_TRUE(frame.ok()) << frame.error().message();
  EXPECT_EQ(frame->ethernet().vlanTci, 0x0005);
  EXPECT_EQ((*frame->begin()).command(), Command::kBrd);
}

}  // namespace
}  // namespace ecsim
