// CoE header, emergency, and golden SDO exchanges from a real capture:
// ../shared/pcap/replay-ek1914-el3004-mailbox.pcapng (EtherCrab master, EK1914 + EL3004, SM0
// at 0x1000 and SM1 at 0x1080, 128 bytes each). The arrays below are the first 16 bytes of the
// 128-byte datagram data (mailbox header + CoE + SDO) of the frames named, read with
// `tshark -r FILE -Y frame.number==N -x`. Frame 966 is kept whole.
#include "protocol/coe.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <vector>

#include "protocol/frame.hpp"
#include "protocol/sdo.hpp"

namespace ecsim {
namespace {

using Bytes16 = std::array<std::uint8_t, 16>;

// Frame 957: FPWR 0x1001:0x1000, SDO initiate upload request 0x100A:00, counter 1.
constexpr Bytes16 kUpload100AReq{0x0a, 0x00, 0x00, 0x00, 0x00, 0x13, 0x00, 0x20,
                                 0x40, 0x0a, 0x10, 0x00, 0x00, 0x00, 0x00, 0x00};
// Frame 971: FPWR, SDO expedited download request 0xF008:00 = 01 00 00 00, counter 2.
constexpr Bytes16 kDownloadF008Req{0x0a, 0x00, 0x00, 0x00, 0x00, 0x23, 0x00, 0x20,
                                   0x23, 0x08, 0xf0, 0x00, 0x01, 0x00, 0x00, 0x00};
// Frame 980: FPRD 0x1001:0x1080, SDO initiate download response 0xF008:00. The slave leaves
// the request's data in the 4 reserved bytes.
constexpr Bytes16 kDownloadF008Resp{0x0a, 0x00, 0x00, 0x00, 0x00, 0x23, 0x00, 0x30,
                                    0x60, 0x08, 0xf0, 0x00, 0x01, 0x00, 0x00, 0x00};
// Frame 985: FPWR, SDO initiate upload request 0xF008:00, counter 3.
constexpr Bytes16 kUploadF008Req{0x0a, 0x00, 0x00, 0x00, 0x00, 0x33, 0x00, 0x20,
                                 0x40, 0x08, 0xf0, 0x00, 0x00, 0x00, 0x00, 0x00};
// Frame 994: FPRD, SDO expedited upload response 0xF008:00, 4 bytes 01 00 00 00 (cmd 0x43).
constexpr Bytes16 kUploadF008Resp{0x0a, 0x00, 0x00, 0x00, 0x00, 0x33, 0x00, 0x30,
                                  0x43, 0x08, 0xf0, 0x00, 0x01, 0x00, 0x00, 0x00};

// Frame 966, whole (156 bytes, as returned by the ring): FPRD 0x1001:0x1080, 128 bytes, WKC 1.
// Mailbox: SDO expedited upload response 0x100A:00, cmd 0x4B (2 bytes), data "08"; after the
// 16 mailbox bytes the SM1 buffer holds stale memory.
const std::vector<std::uint8_t> kFrame966 = {
    0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0x12, 0x10, 0x10, 0x10, 0x10, 0x10, 0x88, 0xa4, 0x8c, 0x10,
    0x04, 0xe2, 0x01, 0x10, 0x80, 0x10, 0x80, 0x00, 0x00, 0x00, 0x0a, 0x00, 0x00, 0x00, 0x00, 0x13,
    0x00, 0x30, 0x4b, 0x0a, 0x10, 0x00, 0x30, 0x38, 0x00, 0x00, 0xae, 0xfd, 0xef, 0x75, 0x34, 0x91,
    0x01, 0x7b, 0xe5, 0xf4, 0xc6, 0xae, 0xd4, 0x85, 0xea, 0x99, 0xe9, 0x61, 0xe2, 0x9f, 0xda, 0x93,
    0xab, 0x0c, 0x87, 0xd7, 0x1b, 0x67, 0xf5, 0x83, 0xf0, 0x6f, 0xfc, 0x46, 0xde, 0xb5, 0x55, 0xac,
    0xa6, 0xe2, 0xd9, 0xe4, 0x2d, 0x62, 0xc3, 0x1e, 0x9f, 0x6b, 0xea, 0xff, 0x79, 0xea, 0x68, 0x13,
    0x03, 0xf5, 0xee, 0xbe, 0xe7, 0x57, 0xda, 0xe4, 0xdc, 0xb7, 0xde, 0x5a, 0x3f, 0x3e, 0x73, 0xc6,
    0x02, 0xc7, 0x8a, 0x0c, 0xe9, 0xea, 0x19, 0x3a, 0x41, 0x93, 0x20, 0xa7, 0xab, 0x2f, 0xf5, 0xd6,
    0xa9, 0xe8, 0xc4, 0x6b, 0x63, 0xff, 0x7e, 0x7a, 0x7b, 0xeb, 0x71, 0xdd, 0xff, 0xc2, 0x6d, 0x4f,
    0xfc, 0xf9, 0xd2, 0xef, 0xbc, 0xb7, 0xd7, 0x45, 0xef, 0x0a, 0x01, 0x00,
};

constexpr std::size_t kSmSize = 128;

std::vector<std::uint8_t> smBuffer(const Bytes16& mailbox) {
  std::vector<std::uint8_t> sm(kSmSize, 0);
  std::copy(mailbox.begin(), mailbox.end(), sm.begin());
  return sm;
}

// --- CoE header -----------------------------------------------------------------------------

TEST(CoeHeader, RawValuesOfServices) {
  EXPECT_EQ((CoeHeader{0, CoeService::kSdoRequest}.raw()), 0x2000);
  EXPECT_EQ((CoeHeader{0, CoeService::kSdoInformation}.raw()), 0x8000);
  EXPECT_EQ((CoeHeader{0x1FF, CoeService::kTxPdo}.raw()), 0x41FF);
  auto h = CoeHeader::fromRaw(0x3E05);  // reserved bits 9-11 set: ignored
  EXPECT_EQ(h.service, CoeService::kSdoResponse);
  EXPECT_EQ(h.number, 0x005);
  EXPECT_EQ(toString(CoeService::kEmergency), "Emergency");
  EXPECT_EQ(toString(static_cast<CoeService>(0)), "unknown");
}

TEST(CoeHeader, EncodeChecksRangeAndRoom) {
  std::array<std::uint8_t, 2> out{};
  ASSERT_TRUE((CoeHeader{0, CoeService::kSdoResponse}.encode(out).ok()));
  EXPECT_EQ(out, (std::array<std::uint8_t, 2>{0x00, 0x30}));
  EXPECT_EQ((CoeHeader{0x200, CoeService::kRxPdo}.encode(out).error().code),
            ErrorCode::kInvalidArgument);
  std::array<std::uint8_t, 1> small{};
  EXPECT_EQ(CoeHeader{}.encode(small).error().code, ErrorCode::kTooLarge);
  EXPECT_EQ(CoeHeader::decode(small).error().code, ErrorCode::kTruncated);
}

TEST(CoeMailbox, RejectsOtherMailboxTypesAndMissingCoeHeader) {
  auto sm = smBuffer(kUpload100AReq);
  sm[5] = 0x12;  // EoE
  auto eoe = decodeCoeMailbox(sm);
  ASSERT_FALSE(eoe.ok());
  EXPECT_EQ(eoe.error().code, ErrorCode::kMalformed);
  EXPECT_NE(eoe.error().context.find("byte 5"), std::string::npos);
  sm[5] = 0x13;
  sm[0] = 1;  // mailbox length 1: no room for the CoE header
  EXPECT_EQ(decodeCoeMailbox(sm).error().code, ErrorCode::kTruncated);
}

// --- emergency ------------------------------------------------------------------------------

TEST(Emergency, LayoutAndRoundTrip) {
  // ETG.1000.6 emergency layout: u16 error code, u8 error register, 5 manufacturer bytes.
  // 0x8210 "PDO not processed due to length error" (CiA 301), error register 0x11.
  Emergency e{0x8210, 0x11, {1, 2, 3, 4, 5}};
  std::array<std::uint8_t, 32> out{};
  auto n = encodeEmergencyMailbox(out, e, MailboxHeader{0, 0x1001, 0, 0, MailboxType::kCoe, 4});
  ASSERT_TRUE(n.ok()) << n.error().message();
  EXPECT_EQ(*n, 16u);
  const std::array<std::uint8_t, 16> expected{0x0a, 0x00, 0x01, 0x10, 0x00, 0x43, 0x00, 0x10,
                                              0x10, 0x82, 0x11, 0x01, 0x02, 0x03, 0x04, 0x05};
  EXPECT_TRUE(std::equal(expected.begin(), expected.end(), out.begin()));
  auto back = decodeEmergencyMailbox(out);
  ASSERT_TRUE(back.ok()) << back.error().message();
  EXPECT_EQ(*back, e);
}

TEST(Emergency, ErrorsOnShortInputAndWrongService) {
  std::array<std::uint8_t, 7> body{};
  EXPECT_EQ(Emergency::decode(body).error().code, ErrorCode::kTruncated);
  std::array<std::uint8_t, 15> small{};
  EXPECT_EQ(encodeEmergencyMailbox(small, Emergency{}).error().code, ErrorCode::kTooLarge);
  auto notEmergency = decodeEmergencyMailbox(smBuffer(kUpload100AReq));
  ASSERT_FALSE(notEmergency.ok());
  EXPECT_NE(notEmergency.error().context.find("byte 7"), std::string::npos);
}

// --- golden SDO exchanges -----------------------------------------------------------------------

TEST(CoeGolden, Frame957UploadRequestDecodesAndReencodes) {
  const auto sm = smBuffer(kUpload100AReq);
  auto m = decodeSdoRequestMailbox(sm);
  ASSERT_TRUE(m.ok()) << m.error().message();
  EXPECT_EQ(m->mailbox.counter, 1);
  EXPECT_EQ(m->coe.service, CoeService::kSdoRequest);
  const auto* req = std::get_if<SdoInitiateUploadRequest>(&m->sdo);
  ASSERT_NE(req, nullptr);
  EXPECT_EQ(*req, (SdoInitiateUploadRequest{0x100A, 0, false}));

  std::vector<std::uint8_t> out(kSmSize, 0);
  auto n = encodeSdoRequestMailbox(out, *req, MailboxHeader{0, 0, 0, 0, MailboxType::kCoe, 1});
  ASSERT_TRUE(n.ok()) << n.error().message();
  EXPECT_EQ(*n, 16u);
  EXPECT_EQ(out, smBuffer(kUpload100AReq));  // the whole 128-byte datagram of frame 957
}

TEST(CoeGolden, Frame966WholeFrameCarriesExpeditedUploadResponse) {
  auto frame = ConstEtherCatFrame::parse(kFrame966);
  ASSERT_TRUE(frame.ok()) << frame.error().message();
  ASSERT_EQ(frame->datagramCount(), 1u);
  auto d = *frame->begin();
  EXPECT_EQ(d.command(), Command::kFprd);
  EXPECT_EQ(d.ado(), 0x1080);
  EXPECT_EQ(d.wkc(), 1);
  auto m = decodeSdoResponseMailbox(d.data());
  ASSERT_TRUE(m.ok()) << m.error().message();
  const auto* resp = std::get_if<SdoInitiateUploadResponse>(&m->sdo);
  ASSERT_NE(resp, nullptr);
  EXPECT_EQ(resp->index, 0x100A);
  EXPECT_EQ(resp->subindex, 0);
  EXPECT_TRUE(resp->expedited);
  EXPECT_TRUE(resp->sizeIndicated);
  EXPECT_EQ(std::string(resp->data.begin(), resp->data.end()), "08");

  std::vector<std::uint8_t> out(kSmSize, 0);
  auto n = encodeSdoResponseMailbox(out, *resp, m->mailbox);
  ASSERT_TRUE(n.ok());
  EXPECT_TRUE(std::equal(out.begin(), out.begin() + 16, d.data().begin()));
}

TEST(CoeGolden, Frame971ExpeditedDownloadRequest) {
  const std::array<std::uint8_t, 4> value{0x01, 0x00, 0x00, 0x00};
  SdoInitiateDownloadRequest req{0xF008, 0, false, true, true, 0, value};
  std::vector<std::uint8_t> out(kSmSize, 0);
  auto n = encodeSdoRequestMailbox(out, req, MailboxHeader{0, 0, 0, 0, MailboxType::kCoe, 2});
  ASSERT_TRUE(n.ok()) << n.error().message();
  EXPECT_EQ(out, smBuffer(kDownloadF008Req));
  auto back = decodeSdoRequestMailbox(out);
  ASSERT_TRUE(back.ok());
  const auto* got = std::get_if<SdoInitiateDownloadRequest>(&back->sdo);
  ASSERT_NE(got, nullptr);
  req.completeSize = 4;  // decode reports the expedited size
  EXPECT_EQ(*got, req);
}

TEST(CoeGolden, Frame980DownloadResponseIgnoresReservedBytes) {
  const auto sm = smBuffer(kDownloadF008Resp);
  auto m = decodeSdoResponseMailbox(sm);
  ASSERT_TRUE(m.ok()) << m.error().message();
  const auto* resp = std::get_if<SdoInitiateDownloadResponse>(&m->sdo);
  ASSERT_NE(resp, nullptr);
  EXPECT_EQ(*resp, (SdoInitiateDownloadResponse{0xF008, 0, false}));
  // We write zeros in the reserved bytes, the real slave echoed the request data there.
  std::vector<std::uint8_t> out(kSmSize, 0);
  ASSERT_TRUE(encodeSdoResponseMailbox(out, *resp, m->mailbox).ok());
  EXPECT_TRUE(std::equal(out.begin(), out.begin() + 12, kDownloadF008Resp.begin()));
  EXPECT_EQ(out[12], 0x00);
  EXPECT_EQ(kDownloadF008Resp[12], 0x01);
}

TEST(CoeGolden, Frames985And994UploadOfF008) {
  const auto reqSm = smBuffer(kUploadF008Req);
  auto reqMsg = decodeSdoRequestMailbox(reqSm);
  ASSERT_TRUE(reqMsg.ok());
  EXPECT_EQ(std::get<SdoInitiateUploadRequest>(reqMsg->sdo).index, 0xF008);
  EXPECT_EQ(reqMsg->mailbox.counter, 3);

  const auto sm = smBuffer(kUploadF008Resp);  // the decoded data views this buffer
  auto respMsg = decodeSdoResponseMailbox(sm);
  ASSERT_TRUE(respMsg.ok());
  const auto& resp = std::get<SdoInitiateUploadResponse>(respMsg->sdo);
  ASSERT_EQ(resp.data.size(), 4u);
  EXPECT_EQ(readLe32(resp.data, 0), 1u);
  EXPECT_EQ(respMsg->mailbox.counter, 3);  // the slave answers with the request's counter

  std::vector<std::uint8_t> out(kSmSize, 0);
  ASSERT_TRUE(encodeSdoResponseMailbox(out, resp, respMsg->mailbox).ok());
  EXPECT_EQ(out, sm);
}

}  // namespace
}  // namespace ecsim
