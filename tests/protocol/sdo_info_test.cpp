// SDO information service. The layouts checked here are the ones SOEM parses
// (../shared/notes/soem-interop.md §3.5): name length = mailbox length - 12 (object
// description) or - 16 (entry description with value info 0x07), OD list indexes counted as
// (mailbox length - 8) / 2 in the first fragment and (mailbox length - 6) / 2 in later ones.
#include "protocol/sdo_info.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <string>
#include <vector>

namespace ecsim {
namespace {

bool mentions(const Error& e, const std::string& text) {
  return e.context.find(text) != std::string::npos;
}

std::vector<std::uint16_t> someIndexes(std::size_t n) {
  std::vector<std::uint16_t> v;
  for (std::size_t i = 0; i < n; ++i) v.push_back(static_cast<std::uint16_t>(0x1000 + 3 * i));
  return v;
}

// Reads an OD list the way SOEM's ecx_readODlist does, fragment by fragment.
std::vector<std::uint16_t> readLikeSoem(const std::vector<std::vector<std::uint8_t>>& mailboxes,
                                        std::uint16_t* listType) {
  std::vector<std::uint16_t> out;
  bool first = true;
  for (const auto& mbx : mailboxes) {
    const std::size_t mbxLen = readLe16(mbx, 0);
    std::size_t at = kSdoInfoDataOffset;
    std::size_t count = (mbxLen - 6) / 2;
    if (first) {
      *listType = readLe16(mbx, at);
      at += 2;
      count = (mbxLen - 8) / 2;
      first = false;
    }
    for (std::size_t i = 0; i < count; ++i) out.push_back(readLe16(mbx, at + 2 * i));
  }
  return out;
}

TEST(SdoInfoHeader, OpcodeIncompleteBitAndFragmentsLeft) {
  std::array<std::uint8_t, 4> raw{0x82, 0x00, 0x03, 0x00};
  auto h = SdoInfoHeader::decode(raw);
  ASSERT_TRUE(h.ok());
  EXPECT_EQ(h->opcode, SdoInfoOpcode::kGetOdListResponse);
  EXPECT_TRUE(h->incomplete);
  EXPECT_EQ(h->fragmentsLeft, 3);
  std::array<std::uint8_t, 4> out{};
  ASSERT_TRUE(h->encode(out).ok());
  EXPECT_EQ(out, raw);
  EXPECT_EQ(toString(SdoInfoOpcode::kError), "SDO information error");
  EXPECT_EQ((SdoInfoHeader{static_cast<SdoInfoOpcode>(0x80), false, 0}.encode(out).error().code),
            ErrorCode::kInvalidArgument);
}

TEST(SdoInfoRequests, BytesOfTheThreeRequests) {
  // Get OD list, all objects (SOEM: list type 0x0001), counter 1.
  std::array<std::uint8_t, 32> out{};
  const MailboxHeader mh{0, 0, 0, 0, MailboxType::kCoe, 1};
  auto n = encodeSdoInfoRequestMailbox(out, OdListRequest{1}, mh);
  ASSERT_TRUE(n.ok()) << n.error().message();
  EXPECT_TRUE(std::equal(out.begin(), out.begin() + 14,
                         std::array<std::uint8_t, 14>{0x08, 0x00, 0x00, 0x00, 0x00, 0x13, 0x00,
                                                      0x80, 0x01, 0x00, 0x00, 0x00, 0x01, 0x00}
                             .begin()));
  EXPECT_EQ(*n, 14u);
  // Get entry description 0x1018:02 with value info 0x07 (as SOEM asks).
  n = encodeSdoInfoRequestMailbox(out, EntryDescriptionRequest{0x1018, 2, 0x07}, mh);
  ASSERT_TRUE(n.ok());
  EXPECT_EQ(readLe16(out, 0), 10);
  EXPECT_EQ(out[8], 0x05);
  EXPECT_EQ(readLe16(out, 12), 0x1018);
  EXPECT_EQ(out[14], 2);
  EXPECT_EQ(out[15], 0x07);
  // And the slave side decodes each of them back.
  for (const SdoInfoRequest& req : std::vector<SdoInfoRequest>{
           OdListRequest{0}, ObjectDescriptionRequest{0x1C12}, EntryDescriptionRequest{1, 2, 3}}) {
    ASSERT_TRUE(encodeSdoInfoRequestMailbox(out, req).ok());
    auto msg = decodeSdoInfoMailbox(out);
    ASSERT_TRUE(msg.ok()) << msg.error().message();
    auto back = decodeSdoInfoRequest(*msg);
    ASSERT_TRUE(back.ok()) << back.error().message();
    EXPECT_EQ(*back, req);
  }
}

TEST(SdoInfoRequests, ResponseOpcodeIsNotARequest) {
  std::array<std::uint8_t, 32> out{};
  ASSERT_TRUE(encodeSdoInfoResponseMailbox(out, SdoInfoError{0x06020000}).ok());
  auto msg = decodeSdoInfoMailbox(out);
  ASSERT_TRUE(msg.ok());
  EXPECT_EQ(decodeSdoInfoRequest(*msg).error().code, ErrorCode::kUnsupported);
}

TEST(SdoInfoObjectDescription, LayoutMatchesSoemNameLength) {
  ObjectDescription d{0x1018, 0x0023, 4, static_cast<std::uint8_t>(ObjectCode::kRecord),
                      "Identity"};
  std::array<std::uint8_t, 64> out{};
  auto n = encodeSdoInfoResponseMailbox(out, d);
  ASSERT_TRUE(n.ok());
  const std::size_t mbxLen = readLe16(out, 0);
  EXPECT_EQ(mbxLen - 12, d.name.size());
  EXPECT_EQ(out[8], 0x04);
  EXPECT_EQ(readLe16(out, 12), 0x1018);
  EXPECT_EQ(readLe16(out, 14), 0x0023);
  EXPECT_EQ(out[16], 4);
  EXPECT_EQ(out[17], 9);
  EXPECT_EQ(std::string(out.begin() + 18, out.begin() + 18 + 8), "Identity");
  auto msg = decodeSdoInfoMailbox(out);
  ASSERT_TRUE(msg.ok());
  auto back = decodeSdoInfoResponse(*msg);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(std::get<ObjectDescription>(*back), d);
}

TEST(SdoInfoEntryDescription, PlainEntryMatchesSoemNameLength) {
  EntryDescription e;
  e.index = 0x6000;
  e.subindex = 1;
  e.valueInfo = 0x07;
  e.dataType = 0x0003;  // INTEGER16
  e.bitLength = 16;
  e.objectAccess = kAccessReadPreOp | kAccessReadSafeOp | kAccessReadOp | kAccessTxPdoMappable;
  e.name = "Value";
  std::array<std::uint8_t, 64> out{};
  ASSERT_TRUE(encodeSdoInfoResponseMailbox(out, e).ok());
  EXPECT_EQ(readLe16(out, 0) - 16u, e.name.size());
  EXPECT_EQ(readLe16(out, 16), 0x0003);
  EXPECT_EQ(readLe16(out, 18), 16);
  EXPECT_EQ(readLe16(out, 20), 0x0087);
  EXPECT_EQ(std::string(out.begin() + 22, out.begin() + 27), "Value");
}

TEST(SdoInfoEntryDescription, OptionalFieldsFollowValueInfo) {
  EntryDescription e;
  e.index = 0x8000;
  e.subindex = 0x11;
  e.valueInfo = kValueInfoUnitType | kValueInfoDefault | kValueInfoMinimum | kValueInfoMaximum;
  e.dataType = 0x0006;  // UNSIGNED16
  e.bitLength = 12;     // 2-byte values
  e.objectAccess = 0x003F;
  e.unitType = 0x00FD;
  e.defaultValue = {0x10, 0x00};
  e.minimumValue = {0x00, 0x00};
  e.maximumValue = {0xFF, 0x0F};
  e.name = "Limit";
  std::vector<std::uint8_t> data(e.encodedSize());
  ASSERT_TRUE(e.encode(data).ok());
  EXPECT_EQ(data.size(), 10u + 2 + 3 * 2 + 5);
  EXPECT_EQ(readLe16(data, 10), 0x00FD);
  EXPECT_EQ(data[12], 0x10);
  EXPECT_EQ(data[16], 0xFF);
  EXPECT_EQ(data[17], 0x0F);
  auto back = EntryDescription::decode(data);
  ASSERT_TRUE(back.ok()) << back.error().message();
  EXPECT_EQ(*back, e);
  // Cut inside the maximum value: truncated, naming where the maximum starts.
  auto cut = EntryDescription::decode(std::span(data).first(17));
  ASSERT_FALSE(cut.ok());
  EXPECT_EQ(cut.error().code, ErrorCode::kTruncated);
  EXPECT_TRUE(mentions(cut.error(), "byte 16")) << cut.error().context;
  EXPECT_TRUE(mentions(cut.error(), "maximum")) << cut.error().context;
}

TEST(SdoInfoEntryDescription, EncodeChecksValueSizesAndRoom) {
  EntryDescription e;
  e.valueInfo = kValueInfoDefault;
  e.bitLength = 32;
  e.defaultValue = {1, 2};
  std::array<std::uint8_t, 64> out{};
  EXPECT_EQ(e.encode(out).error().code, ErrorCode::kInvalidArgument);
  e.defaultValue = {1, 2, 3, 4};
  e.name = std::string(60, 'x');
  EXPECT_EQ(e.encode(out).error().code, ErrorCode::kTooLarge);
  EXPECT_EQ(EntryDescription::decode(std::span(out).first(9)).error().code, ErrorCode::kTruncated);
}

TEST(SdoInfoError, RoundTripsAbortCode) {
  std::array<std::uint8_t, 16> out{};
  auto n = encodeSdoInfoResponseMailbox(out, SdoInfoError{0x06020000});
  ASSERT_TRUE(n.ok());
  EXPECT_EQ(*n, 16u);
  EXPECT_EQ(out[8], 0x07);
  EXPECT_EQ(readLe32(out, 12), 0x06020000u);
  auto msg = decodeSdoInfoMailbox(out);
  ASSERT_TRUE(msg.ok());
  auto back = decodeSdoInfoResponse(*msg);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(std::get<SdoInfoError>(*back).abortCode, 0x06020000u);
}

TEST(SdoInfoFragments, OdListSplitsForSoemAndReassembles) {
  const OdList list{1, someIndexes(200)};
  std::vector<std::uint8_t> data(list.encodedSize());
  ASSERT_TRUE(list.encode(data).ok());
  constexpr std::size_t kMailbox = 128;
  auto frag = SdoInfoFragmenter::create(SdoInfoOpcode::kGetOdListResponse, data, kMailbox);
  ASSERT_TRUE(frag.ok()) << frag.error().message();
  EXPECT_EQ(frag->fragmentCapacity(), 116u);
  EXPECT_EQ(frag->fragmentCount(), 4u);  // 402 bytes = 116 * 3 + 54

  std::vector<std::vector<std::uint8_t>> mailboxes;
  SdoInfoReassembler joiner;
  for (std::size_t i = 0; i < frag->fragmentCount(); ++i) {
    std::vector<std::uint8_t> sm(kMailbox, 0);
    auto n = frag->encodeFragment(i, sm, MailboxHeader{0, 0, 0, 0, MailboxType::kCoe, 1});
    ASSERT_TRUE(n.ok()) << n.error().message();
    auto msg = decodeSdoInfoMailbox(sm);
    ASSERT_TRUE(msg.ok());
    EXPECT_EQ(msg->header.fragmentsLeft, frag->fragmentCount() - 1 - i);
    EXPECT_EQ(msg->header.incomplete, i + 1 < frag->fragmentCount());
    EXPECT_FALSE(joiner.complete());
    ASSERT_TRUE(joiner.add(*msg).ok());
    mailboxes.push_back(sm);
  }
  EXPECT_EQ(readLe16(mailboxes[0], 0), 122);
  std::uint16_t listType = 0;
  EXPECT_EQ(readLikeSoem(mailboxes, &listType), list.indexes);
  EXPECT_EQ(listType, 1);

  ASSERT_TRUE(joiner.complete());
  auto back = decodeSdoInfoResponse(joiner.opcode(), joiner.data());
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(std::get<OdList>(*back), list);
}

TEST(SdoInfoFragments, SingleFragmentAndEmptyList) {
  const OdList empty{1, {}};
  std::vector<std::uint8_t> data(empty.encodedSize());
  ASSERT_TRUE(empty.encode(data).ok());
  auto frag = SdoInfoFragmenter::create(SdoInfoOpcode::kGetOdListResponse, data, 128);
  ASSERT_TRUE(frag.ok());
  EXPECT_EQ(frag->fragmentCount(), 1u);
  std::vector<std::uint8_t> sm(128);
  ASSERT_TRUE(frag->encodeFragment(0, sm).ok());
  auto msg = decodeSdoInfoMailbox(sm);
  ASSERT_TRUE(msg.ok());
  EXPECT_EQ(msg->header.fragmentsLeft, 0);
  EXPECT_FALSE(msg->header.incomplete);
  auto back = decodeSdoInfoResponse(*msg);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(std::get<OdList>(*back), empty);
  EXPECT_EQ(frag->encodeFragment(1, sm).error().code, ErrorCode::kInvalidArgument);
}

TEST(SdoInfoFragments, CapacityIsEvenAndMailboxMustHoldSomeData) {
  std::vector<std::uint8_t> data(10);
  auto odd = SdoInfoFragmenter::create(SdoInfoOpcode::kGetOdListResponse, data, 129);
  ASSERT_TRUE(odd.ok());
  EXPECT_EQ(odd->fragmentCapacity(), 116u);
  auto tiny = SdoInfoFragmenter::create(SdoInfoOpcode::kGetOdListResponse, data, 14);
  ASSERT_TRUE(tiny.ok());
  EXPECT_EQ(tiny->fragmentCount(), 5u);
  EXPECT_EQ(SdoInfoFragmenter::create(SdoInfoOpcode::kGetOdListResponse, data, 13).error().code,
            ErrorCode::kInvalidArgument);
}

TEST(SdoInfoFragments, ReassemblerRejectsGapsOpcodeChangesAndExtraFragments) {
  std::vector<std::uint8_t> data(300, 0x11);
  auto frag = SdoInfoFragmenter::create(SdoInfoOpcode::kGetOdListResponse, data, 64);
  ASSERT_TRUE(frag.ok());
  ASSERT_GE(frag->fragmentCount(), 3u);
  std::vector<std::vector<std::uint8_t>> sms(frag->fragmentCount(), std::vector<std::uint8_t>(64));
  std::vector<SdoInfoMessage> msgs;
  for (std::size_t i = 0; i < sms.size(); ++i) {
    ASSERT_TRUE(frag->encodeFragment(i, sms[i]).ok());
    msgs.push_back(*decodeSdoInfoMailbox(sms[i]));
  }
  SdoInfoReassembler joiner;
  ASSERT_TRUE(joiner.add(msgs[0]).ok());
  auto gap = joiner.add(msgs[2]);
  ASSERT_FALSE(gap.ok());
  EXPECT_EQ(gap.error().code, ErrorCode::kMalformed);
  EXPECT_FALSE(joiner.started());

  ASSERT_TRUE(joiner.add(msgs[0]).ok());
  SdoInfoMessage other = msgs[1];
  other.header.opcode = SdoInfoOpcode::kGetObjectDescriptionResponse;
  EXPECT_FALSE(joiner.add(other).ok());

  joiner.reset();
  for (const auto& m : msgs) ASSERT_TRUE(joiner.add(m).ok());
  EXPECT_TRUE(joiner.complete());
  EXPECT_EQ(joiner.data().size(), 300u);
  EXPECT_FALSE(joiner.add(msgs.back()).ok());
}

TEST(SdoInfoFragments, ErrorEndsAFragmentedResponse) {
  std::vector<std::uint8_t> data(300, 0x22);
  auto frag = SdoInfoFragmenter::create(SdoInfoOpcode::kGetOdListResponse, data, 64);
  ASSERT_TRUE(frag.ok());
  std::vector<std::uint8_t> sm(64);
  ASSERT_TRUE(frag->encodeFragment(0, sm).ok());
  SdoInfoReassembler joiner;
  ASSERT_TRUE(joiner.add(*decodeSdoInfoMailbox(sm)).ok());
  ASSERT_TRUE(encodeSdoInfoResponseMailbox(sm, SdoInfoError{0x08000000}).ok());
  ASSERT_TRUE(joiner.add(*decodeSdoInfoMailbox(sm)).ok());
  EXPECT_TRUE(joiner.complete());
  EXPECT_EQ(joiner.opcode(), SdoInfoOpcode::kError);
  auto back = decodeSdoInfoResponse(joiner.opcode(), joiner.data());
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(std::get<SdoInfoError>(*back).abortCode, 0x08000000u);
}

TEST(SdoInfoErrors, MalformedMailboxesAndData) {
  std::vector<std::uint8_t> sm(32, 0);
  ASSERT_TRUE(encodeSdoInfoRequestMailbox(sm, OdListRequest{1}).ok());
  // Fragment still pending: single-fragment decode refuses.
  sm[10] = 1;
  auto msg = decodeSdoInfoMailbox(sm);
  ASSERT_TRUE(msg.ok());
  EXPECT_EQ(decodeSdoInfoResponse(*msg).error().code, ErrorCode::kInvalidArgument);
  // Wrong CoE service.
  sm[7] = 0x20;
  auto wrong = decodeSdoInfoMailbox(sm);
  ASSERT_FALSE(wrong.ok());
  EXPECT_TRUE(mentions(wrong.error(), "byte 7"));
  // Mailbox too short for the SDO-info header: CoE header + 3 bytes.
  sm[7] = 0x80;
  sm[0] = 5;
  auto shortHeader = decodeSdoInfoMailbox(sm);
  ASSERT_FALSE(shortHeader.ok());
  EXPECT_EQ(shortHeader.error().code, ErrorCode::kTruncated);
  EXPECT_TRUE(mentions(shortHeader.error(), "byte 11")) << shortHeader.error().context;
  // An OD list with half an index.
  std::array<std::uint8_t, 5> odd{0x01, 0x00, 0x00, 0x10, 0x08};
  auto list = OdList::decode(odd);
  ASSERT_FALSE(list.ok());
  EXPECT_EQ(list.error().code, ErrorCode::kMalformed);
  EXPECT_TRUE(mentions(list.error(), "byte 4"));
  // Encoding into a buffer that cannot hold the headers.
  std::array<std::uint8_t, 11> tiny{};
  EXPECT_EQ(encodeSdoInfoRequestMailbox(tiny, OdListRequest{1}).error().code, ErrorCode::kTooLarge);
}

}  // namespace
}  // namespace ecsim
