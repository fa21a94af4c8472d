// SDO body and mailbox codecs: command bytes (CiA 301 §7.2.4.3 bit layouts; the values SOEM
// sends and accepts, ../shared/notes/soem-interop.md §3.5), round trips and error reporting.
// Golden bytes from a real capture are in coe_test.cpp.
#include "protocol/sdo.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <numeric>
#include <set>
#include <string>
#include <vector>

namespace ecsim {
namespace {

std::vector<std::uint8_t> iota(std::size_t n, std::uint8_t first = 1) {
  std::vector<std::uint8_t> v(n);
  std::iota(v.begin(), v.end(), first);
  return v;
}

template <typename T>
std::vector<std::uint8_t> encodeBody(const T& message) {
  std::vector<std::uint8_t> out(2048, 0xEE);
  auto n = message.encode(out);
  EXPECT_TRUE(n.ok()) << n.error().message();
  out.resize(n.ok() ? *n : 0);
  return out;
}

bool mentions(const Error& e, const std::string& text) {
  return e.context.find(text) != std::string::npos;
}

// --- command bytes --------------------------------------------------------------------------

TEST(SdoCommand, ExpeditedUploadResponsesUseSoemSizeCodes) {
  // SOEM reads 1/2/3/4-byte expedited responses as 0x4F / 0x4B / 0x47 / 0x43.
  const std::array<std::uint8_t, 4> expected{0x4F, 0x4B, 0x47, 0x43};
  const auto data = iota(4);
  for (std::size_t size = 1; size <= 4; ++size) {
    SdoInitiateUploadResponse r{0x1C00, 0, false, true, true, 0, std::span(data).first(size)};
    auto body = encodeBody(r);
    ASSERT_EQ(body.size(), 8u);
    EXPECT_EQ(body[0], expected[size - 1]) << size;
    EXPECT_EQ(body[4], 1);
    EXPECT_EQ(body[4 + size - 1], size);  // data, then zero padding
    for (std::size_t i = 4 + size; i < 8; ++i) EXPECT_EQ(body[i], 0);
    auto back = decodeSdoResponse(body);
    ASSERT_TRUE(back.ok());
    EXPECT_EQ(std::get<SdoInitiateUploadResponse>(*back).data.size(), size);
  }
}

TEST(SdoCommand, RequestCommandBytes) {
  EXPECT_EQ(encodeBody(SdoInitiateUploadRequest{0x1C12, 1, false})[0], 0x40);
  EXPECT_EQ(encodeBody(SdoInitiateUploadRequest{0x1C12, 1, true})[0], 0x50);  // complete access
  EXPECT_EQ(encodeBody(SdoUploadSegmentRequest{false})[0], 0x60);
  EXPECT_EQ(encodeBody(SdoUploadSegmentRequest{true})[0], 0x70);
  EXPECT_EQ(encodeBody(SdoInitiateDownloadResponse{0x1C12, 0, false})[0], 0x60);
  EXPECT_EQ(encodeBody(SdoDownloadSegmentResponse{false})[0], 0x20);
  EXPECT_EQ(encodeBody(SdoDownloadSegmentResponse{true})[0], 0x30);
  EXPECT_EQ(encodeBody(SdoAbort{0x6000, 1, 0x06020000})[0], 0x80);
}

TEST(SdoCommand, NormalDownloadWithCompleteAccess) {
  const auto data = iota(6);
  SdoInitiateDownloadRequest r{0x1C12, 0, true, false, true, 6, data};
  auto body = encodeBody(r);
  ASSERT_EQ(body.size(), 14u);
  EXPECT_EQ(body[0], 0x31);  // ccs 1, complete access, size indicated
  EXPECT_EQ(readLe16(body, 1), 0x1C12);
  EXPECT_EQ(readLe32(body, 4), 6u);
  EXPECT_TRUE(std::equal(data.begin(), data.end(), body.begin() + 8));
  auto back = decodeSdoRequest(body);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(std::get<SdoInitiateDownloadRequest>(*back), r);
}

TEST(SdoCommand, ExpeditedWithoutSizeIndicatorCarriesFourBytes) {
  const auto data = iota(4);
  SdoInitiateDownloadRequest r{0x2000, 3, false, true, false, 0, data};
  auto body = encodeBody(r);
  EXPECT_EQ(body[0], 0x22);
  auto back = decodeSdoRequest(body);
  ASSERT_TRUE(back.ok());
  const auto& got = std::get<SdoInitiateDownloadRequest>(*back);
  EXPECT_FALSE(got.sizeIndicated);
  EXPECT_EQ(got.data.size(), 4u);
}

// --- segments -------------------------------------------------------------------------------

TEST(SdoSegment, ShortSegmentIsPaddedAndCountsUnusedBytes) {
  const auto data = iota(3);
  SdoUploadSegmentResponse s{true, true, data};
  auto body = encodeBody(s);
  ASSERT_EQ(body.size(), 8u);
  EXPECT_EQ(body[0], 0x19);  // scs 0, toggle, 4 unused << 1, last
  EXPECT_EQ((std::vector<std::uint8_t>(body.begin() + 1, body.end())),
            (std::vector<std::uint8_t>{1, 2, 3, 0, 0, 0, 0}));
  auto back = decodeSdoResponse(body);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(std::get<SdoUploadSegmentResponse>(*back), s);
}

TEST(SdoSegment, EmptyLastSegmentRoundTrips) {
  SdoDownloadSegmentRequest s{false, true, {}};
  auto body = encodeBody(s);
  ASSERT_EQ(body.size(), 8u);
  EXPECT_EQ(body[0], 0x0F);  // 7 unused, last
  auto back = decodeSdoRequest(body);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(std::get<SdoDownloadSegmentRequest>(*back), s);
}

TEST(SdoSegment, SevenAndLongerSegmentsCarryNoUnusedCount) {
  for (std::size_t size : {7u, 8u, 119u, 1400u}) {
    const auto data = iota(size);
    SdoDownloadSegmentRequest s{size % 2 == 0, false, data};
    auto body = encodeBody(s);
    ASSERT_EQ(body.size(), 1 + size);
    EXPECT_EQ(body[0] & 0x0E, 0) << size;
    auto back = decodeSdoRequest(body);
    ASSERT_TRUE(back.ok()) << back.error().message();
    EXPECT_EQ(std::get<SdoDownloadSegmentRequest>(*back), s) << size;
  }
}

TEST(SdoSegment, SegmentTooLongForBufferIsRefusedWithoutWriting) {
  const auto data = iota(120);
  std::vector<std::uint8_t> out(120, 0xEE);  // needs 121
  auto n = SdoUploadSegmentResponse{false, false, data}.encode(out);
  ASSERT_FALSE(n.ok());
  EXPECT_EQ(n.error().code, ErrorCode::kTooLarge);
  EXPECT_TRUE(std::all_of(out.begin(), out.end(), [](std::uint8_t b) { return b == 0xEE; }));
}

TEST(SdoSegment, CapacityHelpersMatchTheMailbox) {
  constexpr std::size_t kMailbox = 128;
  EXPECT_EQ(sdoSegmentDataCapacity(kMailbox), 119u);
  EXPECT_EQ(sdoNormalDataCapacity(kMailbox), 112u);
  EXPECT_EQ(sdoSegmentDataCapacity(8), 0u);
  std::vector<std::uint8_t> sm(kMailbox);
  const auto fits = iota(119);
  const auto tooMany = iota(120);
  EXPECT_TRUE(encodeSdoResponseMailbox(sm, SdoUploadSegmentResponse{false, true, fits}).ok());
  EXPECT_EQ(
      encodeSdoResponseMailbox(sm, SdoUploadSegmentResponse{false, true, tooMany}).error().code,
      ErrorCode::kTooLarge);
  const auto normal = iota(112);
  EXPECT_TRUE(encodeSdoResponseMailbox(
                  sm, SdoInitiateUploadResponse{0x1008, 0, false, false, true, 500, normal})
                  .ok());
  const auto normalTooMany = iota(113);
  EXPECT_FALSE(encodeSdoResponseMailbox(
                   sm, SdoInitiateUploadResponse{0x1008, 0, false, false, true, 500, normalTooMany})
                   .ok());
}

TEST(SdoSegment, DecodeRejectsUnusedCountOnLongSegment) {
  std::vector<std::uint8_t> body(10, 0);
  body[0] = 0x04;  // 2 unused bytes claimed in a 9-byte segment
  auto r = decodeSdoRequest(body);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kMalformed);
  EXPECT_TRUE(mentions(r.error(), "byte 0")) << r.error().context;
}

// --- normal transfers -------------------------------------------------------------------------

TEST(SdoNormal, UploadResponseOfAString) {
  const std::string name = "EL3004 4K. Ana. Eingang";
  const std::vector<std::uint8_t> data(name.begin(), name.end());
  SdoInitiateUploadResponse r{
      0x1008, 0, false, false, true, static_cast<std::uint32_t>(data.size()), data};
  std::vector<std::uint8_t> sm(128, 0);
  auto n = encodeSdoResponseMailbox(sm, r, MailboxHeader{0, 0, 0, 0, MailboxType::kCoe, 5});
  ASSERT_TRUE(n.ok());
  EXPECT_EQ(readLe16(sm, 0), 10 + data.size());  // SOEM: mbx length = 10 + data bytes
  EXPECT_EQ(sm[8], 0x41);
  auto back = decodeSdoResponseMailbox(sm);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(std::get<SdoInitiateUploadResponse>(back->sdo), r);
}

TEST(SdoNormal, FirstPartOfASegmentedTransfer) {
  const auto data = iota(20);
  SdoInitiateDownloadRequest r{0x8000, 1, false, false, true, 5000, data};
  const auto body = encodeBody(r);
  auto back = decodeSdoRequest(body);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(std::get<SdoInitiateDownloadRequest>(*back).completeSize, 5000u);
  EXPECT_EQ(std::get<SdoInitiateDownloadRequest>(*back).data.size(), 20u);
}

TEST(SdoNormal, CompleteSizeSmallerThanDataIsRefused) {
  const auto data = iota(10);
  SdoInitiateDownloadRequest r{0x8000, 1, false, false, true, 9, data};
  std::vector<std::uint8_t> out(64);
  EXPECT_EQ(r.encode(out).error().code, ErrorCode::kInvalidArgument);
  // Same fault on the wire: name the complete-size field (mailbox byte 12).
  r.completeSize = 10;
  std::vector<std::uint8_t> sm(64, 0);
  ASSERT_TRUE(encodeSdoRequestMailbox(sm, r).ok());
  writeLe32(sm, 12, 9);
  auto bad = decodeSdoRequestMailbox(sm);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().code, ErrorCode::kMalformed);
  EXPECT_TRUE(mentions(bad.error(), "byte 12")) << bad.error().context;
}

// --- errors ---------------------------------------------------------------------------------

TEST(SdoErrors, ExpeditedSizeOutOfRange) {
  const auto five = iota(5);
  std::vector<std::uint8_t> out(16);
  EXPECT_EQ(
      (SdoInitiateDownloadRequest{0x6000, 0, false, true, true, 0, {}}.encode(out)).error().code,
      ErrorCode::kInvalidArgument);
  EXPECT_EQ(
      (SdoInitiateDownloadRequest{0x6000, 0, false, true, true, 0, five}.encode(out)).error().code,
      ErrorCode::kInvalidArgument);
  const auto two = iota(2);
  EXPECT_EQ(
      (SdoInitiateUploadResponse{0x6000, 0, false, true, false, 0, two}.encode(out)).error().code,
      ErrorCode::kInvalidArgument);
}

TEST(SdoErrors, BadSizeIndicatorNamesTheCommandByte) {
  // 0x2D: initiate download, normal (e = 0), size indicated, but "3 unused bytes" set.
  std::vector<std::uint8_t> sm{0x0a, 0x00, 0x00, 0x00, 0x00, 0x13, 0x00, 0x20,
                               0x2D, 0x00, 0x60, 0x00, 0x00, 0x00, 0x00, 0x00};
  auto r = decodeSdoRequestMailbox(sm);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kMalformed);
  EXPECT_TRUE(mentions(r.error(), "byte 8")) << r.error().context;
  EXPECT_TRUE(mentions(r.error(), "0x2D")) << r.error().context;
  // Same bits with expedited but no size indicator (0x2E) are wrong too.
  sm[8] = 0x2E;
  EXPECT_EQ(decodeSdoRequestMailbox(sm).error().code, ErrorCode::kMalformed);
}

TEST(SdoErrors, TruncatedBodyAndMailbox) {
  std::vector<std::uint8_t> body{0x40, 0x00, 0x10, 0x00, 0x00, 0x00, 0x00};
  auto r = decodeSdoRequest(body);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kTruncated);
  EXPECT_TRUE(mentions(r.error(), "byte 7")) << r.error().context;
  // Mailbox length 8: CoE header + 6 SDO bytes; the fault is at mailbox byte 14.
  std::vector<std::uint8_t> sm{0x08, 0x00, 0x00, 0x00, 0x00, 0x13, 0x00, 0x20,
                               0x40, 0x00, 0x10, 0x00, 0x00, 0x00, 0x00, 0x00};
  auto m = decodeSdoRequestMailbox(sm);
  ASSERT_FALSE(m.ok());
  EXPECT_EQ(m.error().code, ErrorCode::kTruncated);
  EXPECT_TRUE(mentions(m.error(), "byte 14")) << m.error().context;
  // Mailbox length larger than the buffer.
  sm[0] = 0x20;
  EXPECT_EQ(decodeSdoRequestMailbox(sm).error().code, ErrorCode::kTruncated);
}

TEST(SdoErrors, BlockTransfersAndInvalidSpecifiers) {
  std::vector<std::uint8_t> body(8, 0);
  body[0] = 0xC0;  // cs 6: block download
  EXPECT_EQ(decodeSdoRequest(body).error().code, ErrorCode::kUnsupported);
  body[0] = 0xA0;  // cs 5: block upload
  EXPECT_EQ(decodeSdoResponse(body).error().code, ErrorCode::kUnsupported);
  body[0] = 0xE0;  // cs 7
  EXPECT_EQ(decodeSdoRequest(body).error().code, ErrorCode::kMalformed);
  EXPECT_EQ(decodeSdoResponse(body).error().code, ErrorCode::kMalformed);
}

TEST(SdoErrors, WrongCoeServiceForDirection) {
  std::vector<std::uint8_t> sm(64, 0);
  ASSERT_TRUE(encodeSdoRequestMailbox(sm, SdoInitiateUploadRequest{0x1000, 0, false}).ok());
  auto asResponse = decodeSdoResponseMailbox(sm);
  ASSERT_FALSE(asResponse.ok());
  EXPECT_TRUE(mentions(asResponse.error(), "byte 7"));
  EXPECT_TRUE(mentions(asResponse.error(), "SDO request"));
}

TEST(SdoErrors, EncodeIntoTooSmallBuffers) {
  std::array<std::uint8_t, 7> body{};
  EXPECT_EQ(SdoAbort{}.encode(body).error().code, ErrorCode::kTooLarge);
  EXPECT_EQ(SdoInitiateUploadRequest{}.encode(body).error().code, ErrorCode::kTooLarge);
  std::array<std::uint8_t, 15> sm{};
  EXPECT_EQ(encodeSdoRequestMailbox(sm, SdoUploadSegmentRequest{}).error().code,
            ErrorCode::kTooLarge);
  std::array<std::uint8_t, 4> tiny{};
  EXPECT_EQ(encodeSdoResponseMailbox(tiny, SdoAbort{}).error().code, ErrorCode::kTooLarge);
}

// --- round trips over mailboxes -----------------------------------------------------------------

TEST(SdoMailbox, EveryRequestAndResponseRoundTrips) {
  const auto data = iota(11);
  const std::vector<SdoRequest> requests{
      SdoInitiateDownloadRequest{0x1C12, 0, true, false, true, 11, data},
      SdoDownloadSegmentRequest{true, true, std::span(data).first(5)},
      SdoInitiateUploadRequest{0x1A00, 3, false},
      SdoUploadSegmentRequest{true},
      SdoAbort{0x1A00, 3, 0x05040000},
  };
  const std::vector<SdoResponse> responses{
      SdoInitiateUploadResponse{0x1018, 1, false, true, true, 4, std::span(data).first(4)},
      SdoUploadSegmentResponse{false, false, data},
      SdoInitiateDownloadResponse{0x1C12, 0, true},
      SdoDownloadSegmentResponse{true},
      SdoAbort{0x1018, 5, 0x06090011},
  };
  const MailboxHeader mh{0, 0x1002, 0, 0, MailboxType::kCoe, 6};
  for (const auto& req : requests) {
    std::vector<std::uint8_t> sm(128, 0);
    ASSERT_TRUE(encodeSdoRequestMailbox(sm, req, mh).ok());
    auto back = decodeSdoRequestMailbox(sm);
    ASSERT_TRUE(back.ok()) << back.error().message();
    EXPECT_EQ(back->sdo, req) << "request alternative " << req.index();
    EXPECT_EQ(back->mailbox.address, 0x1002);
    EXPECT_EQ(back->mailbox.counter, 6);
  }
  for (const auto& resp : responses) {
    std::vector<std::uint8_t> sm(128, 0);
    ASSERT_TRUE(encodeSdoResponseMailbox(sm, resp, mh).ok());
    auto back = decodeSdoResponseMailbox(sm);
    ASSERT_TRUE(back.ok()) << back.error().message();
    EXPECT_EQ(back->sdo, resp) << "response alternative " << resp.index();
  }
}

// A slave's Abort SDO Transfer is a CoE SDO *request* (service 2): ETG.1000.6 table of CoE
// services, and SOES esc_coe.c SDO_abort() builds it with COE_SDOREQUEST. SOEM (v1.4
// ethercatcoe.c, v2 ec_coe.c, ecx_SDOwrite/ecx_SDOread) takes a service-3 answer whose index
// matches as the normal answer, so only a service-2 abort reaches its ECT_SDO_ABORT branch.
TEST(SdoMailbox, SlaveAbortIsAnSdoRequestOnTheWire) {
  std::vector<std::uint8_t> sm(16, 0xEE);
  auto n = encodeSdoResponseMailbox(sm, SdoAbort{0x1C00, 0, 0x06010004});
  ASSERT_TRUE(n.ok());
  EXPECT_EQ(*n, 16u);
  EXPECT_EQ(sm, (std::vector<std::uint8_t>{
                    0x0a, 0x00,              // mailbox length 10
                    0x00, 0x00,              // address
                    0x00,                    // channel, priority
                    0x03,                    // type 3 CoE, counter 0
                    0x00, 0x20,              // CoE number 0, service 2 in bits 12-15
                    0x80,                    // command specifier 4: abort
                    0x00, 0x1c, 0x00,        // index 0x1C00, subindex 0
                    0x04, 0x00, 0x01, 0x06}  // abort code 0x06010004, little-endian
                ));
}

TEST(SdoMailbox, AbortIsAcceptedUnderEitherService) {
  // Service 2 (the standard, SOES) and service 3 (seen from slaves in the field) both decode
  // as the slave's abort.
  for (int service : {2, 3}) {
    const std::vector<std::uint8_t> sm{0x0a, 0x00, 0x00, 0x00, 0x00, 0x03,
                                       0x00, static_cast<std::uint8_t>(service << 4),
                                       0x80, 0x18, 0x10, 0x01, 0x02, 0x00, 0x01, 0x06};
    auto back = decodeSdoResponseMailbox(sm);
    ASSERT_TRUE(back.ok()) << "service " << service << ": " << back.error().message();
    const SdoResponse expected = SdoAbort{0x1018, 1, 0x06010002};
    EXPECT_EQ(back->sdo, expected) << service;
  }
  // Service 2 carries nothing else a slave may answer with.
  std::vector<std::uint8_t> sm(64, 0);
  ASSERT_TRUE(encodeSdoRequestMailbox(sm, SdoInitiateDownloadRequest{
                                              0x1000, 0, false, true, false, 4,
                                              std::vector<std::uint8_t>{1, 2, 3, 4}})
                  .ok());
  auto notAbort = decodeSdoResponseMailbox(sm);
  ASSERT_FALSE(notAbort.ok());
  EXPECT_TRUE(mentions(notAbort.error(), "byte 7")) << notAbort.error().context;
  // A short service-2 abort names its missing bytes.
  std::vector<std::uint8_t> shortAbort{0x05, 0x00, 0x00, 0x00, 0x00, 0x03, 0x00, 0x20, 0x80,
                                       0x18, 0x10};
  auto truncated = decodeSdoResponseMailbox(shortAbort);
  ASSERT_FALSE(truncated.ok());
  EXPECT_EQ(truncated.error().code, ErrorCode::kTruncated);
}

// --- abort codes ----------------------------------------------------------------------------

TEST(SdoAbortCodes, EveryStandardCodeHasADistinctText) {
  const std::uint32_t codes[] = {
      0x05030000, 0x05040000, 0x05040001, 0x05040005, 0x06010000, 0x06010001, 0x06010002,
      0x06010003, 0x06010004, 0x06010005, 0x06010006, 0x06020000, 0x06040041, 0x06040042,
      0x06040043, 0x06040047, 0x06060000, 0x06070010, 0x06070012, 0x06070013, 0x06090011,
      0x06090030, 0x06090031, 0x06090032, 0x06090033, 0x06090036, 0x08000000, 0x08000020,
      0x08000021, 0x08000022, 0x08000023};
  std::set<std::string_view> texts;
  for (auto code : codes) {
    EXPECT_TRUE(isKnownSdoAbortCode(code)) << std::hex << code;
    EXPECT_TRUE(texts.insert(sdoAbortText(code)).second) << std::hex << code;
  }
  EXPECT_NE(sdoAbortText(SdoAbortCode::kObjectDoesNotExist).find("does not exist"),
            std::string_view::npos);
  EXPECT_NE(sdoAbortText(0x06090011).find("subindex"), std::string_view::npos);
  EXPECT_EQ(sdoAbortText(0x12345678), "unknown SDO abort code");
  EXPECT_FALSE(isKnownSdoAbortCode(0));
  EXPECT_FALSE(isKnownSdoAbortCode(0x05040002));  // CANopen block-mode only, not ETG.1000.6
}

}  // namespace
}  // namespace ecsim
