// FoE header encoding (ETG.1000.6 §5.7): the layout SOEM's ec_FOEt gives it (u8 opcode,
// u8 reserved, u32 password / packet number / error code, then name or data), the opcode
// values 1..6 and the error codes 0x8000..0x800B of SOES esc.h (FOE_OP_*, FOE_ERR_*).
#include "protocol/foe.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace ecsim {
namespace {

TEST(Foe, WriteRequestAsSoemBuildsIt) {
  // ecx_FOEwrite(slave, "fw.bin", password 0x12345678): mailbox length 6 + 6, type FoE.
  auto m = encodeFoeMailbox(FoeOpcode::kWrite, 0x12345678, std::string_view("fw.bin"));
  const std::vector<std::uint8_t> expected{0x0C, 0x00, 0x00, 0x00, 0x00, 0x04,  // mailbox header
                                           0x02, 0x00, 0x78, 0x56, 0x34, 0x12,  // WRQ, password
                                           'f',  'w',  '.',  'b',  'i',  'n'};
  EXPECT_EQ(m, expected);
  auto mbx = decodeMailbox(m);
  ASSERT_TRUE(mbx.ok());
  EXPECT_EQ(mbx->header.type, MailboxType::kFoe);
  auto p = decodeFoe(mbx->payload);
  ASSERT_TRUE(p.ok()) << p.error().message();
  EXPECT_EQ(p->opcode, FoeOpcode::kWrite);
  EXPECT_EQ(p->value, 0x12345678u);
  EXPECT_EQ(p->text(), "fw.bin");
}

TEST(Foe, OpcodeAndErrorValuesAreTheSpecifiedOnes) {
  EXPECT_EQ(static_cast<int>(FoeOpcode::kRead), 1);
  EXPECT_EQ(static_cast<int>(FoeOpcode::kWrite), 2);
  EXPECT_EQ(static_cast<int>(FoeOpcode::kData), 3);
  EXPECT_EQ(static_cast<int>(FoeOpcode::kAck), 4);
  EXPECT_EQ(static_cast<int>(FoeOpcode::kError), 5);
  EXPECT_EQ(static_cast<int>(FoeOpcode::kBusy), 6);
  EXPECT_EQ(static_cast<std::uint32_t>(FoeErrorCode::kNotFound), 0x8001u);
  EXPECT_EQ(static_cast<std::uint32_t>(FoeErrorCode::kPacketNumberWrong), 0x8005u);
  EXPECT_EQ(static_cast<std::uint32_t>(FoeErrorCode::kNoRights), 0x800Au);
  EXPECT_EQ(static_cast<std::uint32_t>(FoeErrorCode::kProgramError), 0x800Bu);
  EXPECT_EQ(describeFoeError(0x8001), "0x8001 (not found)");
  EXPECT_EQ(describeFoeError(0x8009), "0x8009 (not bootstrap)");
  EXPECT_EQ(describeFoeError(0x1234), "0x1234 (unknown FoE error)");
  EXPECT_EQ(toString(FoeOpcode::kBusy), "BUSY");
  EXPECT_EQ(toString(static_cast<FoeOpcode>(9)), "unknown");
}

TEST(Foe, DataAckErrorAndBusyRoundTrip) {
  const std::vector<std::uint8_t> bytes{1, 2, 3};
  auto data = encodeFoeMailbox(FoeOpcode::kData, 7, bytes);
  auto p = decodeFoe(decodeMailbox(data)->payload);
  ASSERT_TRUE(p.ok());
  EXPECT_EQ(p->opcode, FoeOpcode::kData);
  EXPECT_EQ(p->value, 7u);
  EXPECT_EQ(std::vector<std::uint8_t>(p->data.begin(), p->data.end()), bytes);

  auto ack = encodeFoeMailbox(FoeOpcode::kAck, 0);
  EXPECT_EQ(ack.size(), kFoeDataOffset);
  EXPECT_EQ(decodeFoe(decodeMailbox(ack)->payload)->opcode, FoeOpcode::kAck);

  auto err = encodeFoeMailbox(FoeOpcode::kError, 0x8001, std::string_view("no such file"));
  auto e = decodeFoe(decodeMailbox(err)->payload);
  EXPECT_EQ(e->value, 0x8001u);
  EXPECT_EQ(e->text(), "no such file");

  auto busy = encodeFoeMailbox(FoeOpcode::kBusy, foeBusyValue(3, 10));
  auto b = decodeFoe(decodeMailbox(busy)->payload);
  EXPECT_EQ(b->busyDone(), 3);
  EXPECT_EQ(b->busyEntire(), 10);
}

TEST(Foe, ShortPayloadIsAnErrorAndPacketSizeFollowsTheMailbox) {
  const std::vector<std::uint8_t> five{3, 0, 1, 0, 0};
  auto p = decodeFoe(five);
  ASSERT_FALSE(p.ok());
  EXPECT_EQ(p.error().code, ErrorCode::kTruncated);
  EXPECT_NE(p.error().context.find("5 bytes"), std::string::npos);
  // SOEM: maxdata = mbx_l - 12 (a 128-byte mailbox carries 116 bytes of file per packet).
  EXPECT_EQ(foeDataPerPacket(128), 116u);
  EXPECT_EQ(foeDataPerPacket(12), 0u);
  EXPECT_EQ(foeDataPerPacket(0), 0u);
}

}  // namespace
}  // namespace ecsim
