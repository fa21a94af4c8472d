#include "protocol/mailbox.hpp"

#include <gtest/gtest.h>

#include <array>
#include <vector>

namespace ecsim {
namespace {

// Mailbox header of the CoE SDO upload request 0x100A:00 in
// ../shared/pcap/replay-ek1914-el3004-mailbox.pcapng, frame 957 (FPWR 0x1001:0x1000, datagram
// data bytes 0-5): length 10, address 0, channel/priority 0, type CoE with counter 1.
constexpr std::array<std::uint8_t, 6> kFrame957Header{0x0a, 0x00, 0x00, 0x00, 0x00, 0x13};

TEST(MailboxHeader, DecodesRealHeader) {
  auto h = MailboxHeader::decode(kFrame957Header);
  ASSERT_TRUE(h.ok()) << h.error().message();
  EXPECT_EQ(h->length, 10);
  EXPECT_EQ(h->address, 0);
  EXPECT_EQ(h->channel, 0);
  EXPECT_EQ(h->priority, 0);
  EXPECT_EQ(h->type, MailboxType::kCoe);
  EXPECT_EQ(h->counter, 1);
}

TEST(MailboxHeader, EncodesRealHeader) {
  MailboxHeader h{10, 0, 0, 0, MailboxType::kCoe, 1};
  std::array<std::uint8_t, 6> out{};
  auto n = h.encode(out);
  ASSERT_TRUE(n.ok()) << n.error().message();
  EXPECT_EQ(*n, 6u);
  EXPECT_EQ(out, kFrame957Header);
}

TEST(MailboxHeader, PacksChannelPriorityTypeAndCounter) {
  MailboxHeader h{0x1234, 0x1001, 5, 2, MailboxType::kFoe, 7};
  std::array<std::uint8_t, 6> out{};
  ASSERT_TRUE(h.encode(out).ok());
  // channel 5 | priority 2 << 6 = 0x85; FoE 4 | counter 7 << 4 = 0x74
  EXPECT_EQ(out, (std::array<std::uint8_t, 6>{0x34, 0x12, 0x01, 0x10, 0x85, 0x74}));
  auto back = MailboxHeader::decode(out);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(*back, h);
}

TEST(MailboxHeader, ReservedTypeBitIsIgnoredAndReservedTypeKept) {
  // type byte 0xE6: reserved bit 7 set, counter 6, type 6 (reserved value)
  std::array<std::uint8_t, 6> raw{0, 0, 0, 0, 0, 0xE6};
  auto h = MailboxHeader::decode(raw);
  ASSERT_TRUE(h.ok());
  EXPECT_EQ(static_cast<unsigned>(h->type), 6u);
  EXPECT_EQ(h->counter, 6);
  EXPECT_FALSE(isKnownMailboxType(6));
  EXPECT_EQ(toString(h->type), "unknown");
  EXPECT_TRUE(isKnownMailboxType(15));
  EXPECT_EQ(toString(MailboxType::kVoe), "VoE");
}

TEST(MailboxHeader, EncodeRefusesFieldsThatDoNotFit) {
  std::array<std::uint8_t, 6> out{};
  EXPECT_EQ((MailboxHeader{0, 0, 64, 0, MailboxType::kCoe, 0}.encode(out).error().code),
            ErrorCode::kInvalidArgument);
  EXPECT_EQ((MailboxHeader{0, 0, 0, 4, MailboxType::kCoe, 0}.encode(out).error().code),
            ErrorCode::kInvalidArgument);
  EXPECT_EQ((MailboxHeader{0, 0, 0, 0, MailboxType::kCoe, 8}.encode(out).error().code),
            ErrorCode::kInvalidArgument);
  EXPECT_EQ((MailboxHeader{0, 0, 0, 0, static_cast<MailboxType>(16), 0}.encode(out).error().code),
            ErrorCode::kInvalidArgument);
  std::array<std::uint8_t, 5> small{};
  EXPECT_EQ(MailboxHeader{}.encode(small).error().code, ErrorCode::kTooLarge);
}

TEST(MailboxHeader, DecodeOfShortInputNamesOffset) {
  auto h = MailboxHeader::decode(std::span(kFrame957Header).first(5));
  ASSERT_FALSE(h.ok());
  EXPECT_EQ(h.error().code, ErrorCode::kTruncated);
  EXPECT_NE(h.error().context.find("byte 5"), std::string::npos) << h.error().context;
}

TEST(Mailbox, DecodeHonoursLengthAndIgnoresTrailingBytes) {
  // A 16-byte SyncManager buffer holding a 4-byte mailbox; the rest is stale memory.
  std::vector<std::uint8_t> sm{0x04, 0x00, 0x00, 0x00, 0x00, 0x03, 1,    2,
                               3,    4,    0xAA, 0xBB, 0xCC, 0xDD, 0xEE, 0xFF};
  auto m = decodeMailbox(sm);
  ASSERT_TRUE(m.ok());
  EXPECT_EQ(m->payload.size(), 4u);
  EXPECT_EQ(m->payload[3], 4);
}

TEST(Mailbox, DecodeRejectsLengthPastBuffer) {
  std::vector<std::uint8_t> sm{0x05, 0x00, 0x00, 0x00, 0x00, 0x03, 1, 2, 3, 4};
  auto m = decodeMailbox(sm);
  ASSERT_FALSE(m.ok());
  EXPECT_EQ(m.error().code, ErrorCode::kTruncated);
  EXPECT_NE(m.error().context.find("byte 0"), std::string::npos);
}

TEST(Mailbox, FinishWritesLengthAndRefusesOverflow) {
  std::array<std::uint8_t, 10> out{};
  auto n = finishMailbox(out, MailboxHeader{0, 0, 0, 0, MailboxType::kEoe, 3}, 4);
  ASSERT_TRUE(n.ok());
  EXPECT_EQ(*n, 10u);
  EXPECT_EQ(out[0], 4);
  EXPECT_EQ(out[5], 0x32);
  EXPECT_EQ(finishMailbox(out, MailboxHeader{}, 5).error().code, ErrorCode::kTooLarge);
  std::vector<std::uint8_t> big(0x10010);
  EXPECT_EQ(finishMailbox(big, MailboxHeader{}, 0x10000).error().code, ErrorCode::kTooLarge);
}

TEST(Mailbox, CounterCyclesOneToSeven) {
  std::vector<std::uint8_t> seen;
  std::uint8_t c = 0;
  for (int i = 0; i < 9; ++i) {
    c = nextMailboxCounter(c);
    seen.push_back(c);
  }
  EXPECT_EQ(seen, (std::vector<std::uint8_t>{1, 2, 3, 4, 5, 6, 7, 1, 2}));
}

TEST(MailboxError, EncodesCompleteMailbox) {
  std::array<std::uint8_t, 16> out{};
  auto n = encodeMailboxError(out, MailboxErrorCode::kUnsupportedProtocol,
                              MailboxHeader{0, 0x1001, 0, 0, MailboxType::kCoe, 2});
  ASSERT_TRUE(n.ok()) << n.error().message();
  EXPECT_EQ(*n, 10u);
  // length 4, address 0x1001, type 0 (error) with counter 2, service 0x0001, detail 0x0002
  const std::array<std::uint8_t, 10> expected{0x04, 0x00, 0x01, 0x10, 0x00,
                                              0x20, 0x01, 0x00, 0x02, 0x00};
  EXPECT_TRUE(std::equal(expected.begin(), expected.end(), out.begin()));
  auto m = decodeMailbox(out);
  ASSERT_TRUE(m.ok());
  EXPECT_EQ(m->header.type, MailboxType::kError);
  auto reply = MailboxErrorReply::decode(m->payload);
  ASSERT_TRUE(reply.ok());
  EXPECT_EQ(reply->detail, 0x0002);
}

TEST(MailboxError, DecodeChecksServiceTypeAndSize) {
  std::array<std::uint8_t, 4> wrongService{0x02, 0x00, 0x01, 0x00};
  EXPECT_EQ(MailboxErrorReply::decode(wrongService).error().code, ErrorCode::kMalformed);
  std::array<std::uint8_t, 3> shortReply{0x01, 0x00, 0x01};
  EXPECT_EQ(MailboxErrorReply::decode(shortReply).error().code, ErrorCode::kTruncated);
  std::array<std::uint8_t, 9> small{};
  EXPECT_EQ(encodeMailboxError(small, MailboxErrorCode::kSyntax).error().code,
            ErrorCode::kTooLarge);
}

TEST(MailboxError, EveryDetailCodeHasItsOwnText) {
  std::vector<std::string_view> texts;
  for (std::uint16_t code = 1; code <= 8; ++code) {
    auto text = mailboxErrorText(code);
    EXPECT_NE(text, "unknown mailbox error") << code;
    for (auto other : texts) EXPECT_NE(text, other);
    texts.push_back(text);
  }
  EXPECT_EQ(mailboxErrorText(0), "unknown mailbox error");
  EXPECT_EQ(mailboxErrorText(9), "unknown mailbox error");
  EXPECT_EQ(mailboxErrorText(MailboxErrorCode::kInvalidSize), mailboxErrorText(8));
}

}  // namespace
}  // namespace ecsim
