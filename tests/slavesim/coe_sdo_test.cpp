// SDO upload and download through a real Segment, as SOEM performs them (notes/soem-interop.md
// §3.5): expedited sizes (0x4F/0x4B/0x47/0x43), normal and segmented transfers, complete
// access, every abort code the server gives, mailbox errors, the mailbox counter retry rule
// (ETG.1000.4 §5.6) and emergencies.
#include <gtest/gtest.h>

#include "tests/slavesim/coe_test_support.hpp"

namespace ecsim::testing {
namespace {

using slavesim::coe::CoeServerOptions;

TEST(CoeSdo, ExpeditedUploadAnswersWithTheObjectsOwnSize) {
  CoeTestSlave t;
  // Command bytes of the initiate upload response (scs 2, expedited, size indicated, n unused
  // bytes in bits 2-3): SOEM reads u8 objects into 1-byte buffers and needs exactly these.
  struct Case {
    std::uint16_t index;
    std::uint8_t sub;
    std::uint8_t command;
    std::vector<std::uint8_t> data;
  };
  const Case cases[] = {
      {0x1C00, 0, 0x4F, {4}},
      {0x1C00, 3, 0x4F, {3}},
      {0x1C12, 1, 0x4B, {0x00, 0x16}},
      {0x2007, 0, 0x47, {0xFE, 0xFF, 0xFF}},
      {0x1018, 2, 0x43, {0x42, 0, 0, 0}},
      {0x1009, 0, 0x47, {'1', '.', '0'}},
  };
  for (const Case& c : cases) {
    Upload u = t.master->upload(c.index, c.sub);
    EXPECT_EQ(u.abort, 0u) << std::hex << c.index;
    EXPECT_EQ(u.command, c.command) << std::hex << c.index << ":" << int(c.sub);
    EXPECT_EQ(u.data, c.data) << std::hex << c.index;
  }
}

TEST(CoeSdo, StringLongerThanFourBytesIsANormalUpload) {
  CoeTestSlave t;
  Upload u = t.master->upload(0x1008, 0);
  ASSERT_EQ(u.abort, 0u);
  EXPECT_EQ(u.command, 0x41) << "normal transfer, size indicated";
  EXPECT_EQ(u.segments, 0);
  EXPECT_EQ(std::string(u.data.begin(), u.data.end()), kTestDeviceName);
  // Mailbox length = 10 + data (notes/soem-interop.md §3.5).
  EXPECT_EQ(readLe16(t.master->lastReply(), 0), 10 + std::string(kTestDeviceName).size());
  EXPECT_EQ(readLe32(t.master->lastReply(), 12), std::string(kTestDeviceName).size());
}

TEST(CoeSdo, LargeObjectIsUploadedInSegments) {
  CoeTestSlave t;  // 128-byte mailbox: 112 bytes in the initiate response, 119 per segment
  Upload u = t.master->upload(0x2006, 0);
  ASSERT_EQ(u.abort, 0u);
  EXPECT_EQ(u.command, 0x41);
  ASSERT_EQ(u.data.size(), 300u);
  for (std::size_t i = 0; i < 300; ++i) ASSERT_EQ(u.data[i], static_cast<std::uint8_t>(i)) << i;
  EXPECT_EQ(u.segments, 2) << "300 = 112 + 119 + 69";
}

TEST(CoeSdo, ExpeditedDownloadRoundTripAndDeviceSeesTheValue) {
  CoeTestSlave t;
  EXPECT_EQ(t.master->download(0x2001, 0, {0x34, 0x12}), 0u);
  EXPECT_EQ(t.master->uploadValue<std::uint16_t>(0x2001, 0), 0x1234);
  EXPECT_EQ(t.od->get<std::uint16_t>(0x2001, 0).value(), 0x1234);
  ASSERT_TRUE(t.od->set<std::int32_t>(0x2002, 0, -7).ok());
  EXPECT_EQ(t.master->uploadValue<std::int32_t>(0x2002, 0), -7) << "device writes, SDO reads";
}

TEST(CoeSdo, NormalAndSegmentedDownloadRoundTrip) {
  CoeTestSlave t;
  std::vector<std::uint8_t> blob(300);
  for (std::size_t i = 0; i < blob.size(); ++i) blob[i] = static_cast<std::uint8_t>(0xFF - i);
  EXPECT_EQ(t.master->download(0x2006, 0, blob), 0u) << "segmented (300 > 112)";
  EXPECT_EQ(t.master->upload(0x2006, 0).data, blob);
  EXPECT_EQ(t.master->download(0x2001, 0, {0x78, 0x56}, false, true), 0u) << "normal, 2 bytes";
  EXPECT_EQ(t.od->get<std::uint16_t>(0x2001, 0).value(), 0x5678);
  // A string-like object accepts a shorter download; the rest reads as zero.
  EXPECT_EQ(t.master->download(0x2006, 0, {1, 2, 3, 4, 5, 6}), 0u);
  auto back = t.master->upload(0x2006, 0).data;
  ASSERT_EQ(back.size(), 300u);
  EXPECT_EQ(back[5], 6);
  EXPECT_EQ(back[6], 0);
}

TEST(CoeSdo, AbortCodes) {
  CoeTestSlave t;
  EXPECT_EQ(t.master->upload(0x5555, 0).abort, 0x06020000u) << "object does not exist";
  EXPECT_EQ(t.master->upload(0x1018, 9).abort, 0x06090011u) << "subindex does not exist";
  EXPECT_EQ(t.master->download(0x2003, 0, bytesOf(1, 4)), 0x06010002u) << "read-only";
  EXPECT_EQ(t.master->upload(0x2004, 0).abort, 0x06010001u) << "write-only";
  EXPECT_EQ(t.master->download(0x2001, 0, {1}), 0x06070013u) << "length too low";
  EXPECT_EQ(t.master->download(0x2001, 0, {1, 2, 3}), 0x06070012u) << "length too high";
  EXPECT_EQ(t.master->download(0x2000, 0, {201}), 0x06090031u) << "value too high";
  EXPECT_EQ(t.master->download(0x2000, 0, {9}), 0x06090032u) << "value too low";
  EXPECT_EQ(t.master->download(0x2002, 0, bytesOf(static_cast<std::uint32_t>(-1001), 4)),
            0x06090032u);
  EXPECT_EQ(t.master->download(0x2002, 0, bytesOf(1001, 4)), 0x06090031u);
  EXPECT_EQ(t.master->download(0x2008, 3, {2}), 0x06090030u) << "BOOL takes only bit 0";
  EXPECT_EQ(t.od->get<std::uint8_t>(0x2000, 0).value(), 50) << "refused writes change nothing";
  // CA write whose data does not end on an entry boundary: 0x06070010.
  EXPECT_EQ(t.master->download(0x2008, 0, {3, 0, 1, 2}, true), 0x06070010u);
  // PDO objects: an entry written while sub 0 != 0, an object that is not mappable, an
  // assignment naming a PDO of the wrong direction.
  EXPECT_EQ(t.master->download(0x1600, 1, bytesOf(0x70000101, 4)), 0x06010003u);
  EXPECT_EQ(t.master->download(0x1600, 0, {0}), 0u);
  EXPECT_EQ(t.master->download(0x1600, 1, bytesOf(0x20010010, 4)), 0x06040041u)
      << "0x2001 is not RX mappable";
  EXPECT_EQ(t.master->download(0x1600, 1, bytesOf(0x70000120, 4)), 0x06040041u)
      << "32 bits of a BOOL";
  EXPECT_EQ(t.master->download(0x1C12, 0, {0}), 0u);
  EXPECT_EQ(t.master->download(0x1C12, 1, bytesOf(0x1A00, 2)), 0x06090030u);
  EXPECT_EQ(t.master->download(0x1C12, 0, {3}), 0x06090031u) << "more than the 2 entries";
}

// The server's aborts are CoE SDO requests, service 2 (ETG.1000.6 table of CoE services;
// SOES esc_coe.c SDO_abort() sends COE_SDOREQUEST): in answer to an initiate upload, an
// initiate download and a segment alike. Mailbox type 3, command 0x80.
TEST(CoeSdo, EveryAbortTravelsAsCoeServiceTwo) {
  CoeTestSlave t;
  auto expectAbortOnWire = [&](std::uint32_t code, const char* what) {
    const auto& m = t.master->lastReply();
    ASSERT_GE(m.size(), 16u) << what;
    EXPECT_EQ(m[5] & 0x0F, 3) << what << ": mailbox type CoE";
    EXPECT_EQ(readLe16(m, 6), 0x2000) << what << ": CoE service 2, number 0";
    EXPECT_EQ(m[8], 0x80) << what;
    EXPECT_EQ(readLe32(m, 12), code) << what;
  };
  EXPECT_EQ(t.master->upload(0x6FFF, 0).abort, 0x06020000u);
  expectAbortOnWire(0x06020000, "initiate upload of a missing object");
  EXPECT_EQ(t.master->download(0x1018, 1, bytesOf(1, 4)), 0x06010002u);
  expectAbortOnWire(0x06010002, "expedited download to a read-only entry");
  std::vector<std::uint8_t> blob(200, 0xAB);
  auto r = t.master->sdoTransact(
      SdoInitiateDownloadRequest{0x2003, 0, false, false, true, 200, ConstBytes(blob).first(112)});
  ASSERT_TRUE(r && std::holds_alternative<SdoAbort>(*r));
  expectAbortOnWire(std::get<SdoAbort>(*r).abortCode, "normal download refused");
  r = t.master->sdoTransact(SdoUploadSegmentRequest{false});  // no upload under way
  ASSERT_TRUE(r && std::holds_alternative<SdoAbort>(*r));
  expectAbortOnWire(0x05040001, "segment without a transfer");
}

TEST(CoeSdo, NotInThisStateAndPdoChangesOutsidePreOp) {
  CoeTestSlave t;
  EXPECT_EQ(t.master->download(0x2005, 0, bytesOf(7, 4)), 0u) << "PREOP: allowed";
  ASSERT_EQ(t.toSafeOp(), 0x0004);
  EXPECT_EQ(t.master->download(0x2005, 0, bytesOf(8, 4)), 0x08000022u);
  EXPECT_EQ(t.master->download(0x1C12, 0, {0}), 0x08000022u) << "assignment in SAFEOP";
  EXPECT_EQ(t.master->download(0x1600, 0, {0}), 0x08000022u) << "mapping in SAFEOP";
  EXPECT_EQ(t.master->upload(0x2005, 0).data, bytesOf(7, 4)) << "reading is fine";
  EXPECT_EQ(t.master->download(0x2001, 0, {1, 0}), 0u) << "a plain rw object is writable";
}

TEST(CoeSdo, WrongToggleAbortsSegmentedTransfers) {
  CoeTestSlave t;
  auto r = t.master->sdoTransact(SdoInitiateUploadRequest{0x2006, 0, false});
  ASSERT_TRUE(r && std::holds_alternative<SdoInitiateUploadResponse>(*r));
  r = t.master->sdoTransact(SdoUploadSegmentRequest{true});  // first toggle must be 0
  ASSERT_TRUE(r && std::holds_alternative<SdoAbort>(*r));
  EXPECT_EQ(std::get<SdoAbort>(*r).abortCode, 0x05030000u);
  EXPECT_EQ(std::get<SdoAbort>(*r).index, 0x2006);

  std::vector<std::uint8_t> blob(200, 0xAB);
  SdoInitiateDownloadRequest init{0x2006, 0, false, false, true, 200, ConstBytes(blob).first(112)};
  r = t.master->sdoTransact(init);
  ASSERT_TRUE(r && std::holds_alternative<SdoInitiateDownloadResponse>(*r));
  r = t.master->sdoTransact(
      SdoDownloadSegmentRequest{false, false, ConstBytes(blob).subspan(112, 50)});
  ASSERT_TRUE(r && std::holds_alternative<SdoDownloadSegmentResponse>(*r));
  r = t.master->sdoTransact(
      SdoDownloadSegmentRequest{false, true, ConstBytes(blob).subspan(162, 38)});
  ASSERT_TRUE(r && std::holds_alternative<SdoAbort>(*r));
  EXPECT_EQ(std::get<SdoAbort>(*r).abortCode, 0x05030000u);
  EXPECT_NE(t.od->bytes(0x2006, 0)[0], 0xAB) << "the aborted download wrote nothing";
}

TEST(CoeSdo, CompleteAccessOfAssignmentMappingAndRecord) {
  CoeTestSlave t;
  // 0x1C12 (2 entries): sub 0 padded to 16 bits, then the u16 entries.
  Upload u = t.master->upload(0x1C12, 0, true);
  ASSERT_EQ(u.abort, 0u);
  EXPECT_EQ(u.data, (std::vector<std::uint8_t>{1, 0, 0x00, 0x16, 0x00, 0x00}));
  EXPECT_EQ(u.command & 0x10, 0x10) << "complete-access bit echoed";
  u = t.master->upload(0x1600, 0, true);
  ASSERT_EQ(u.abort, 0u);
  ASSERT_EQ(u.data.size(), 2u + 4 * 4);
  EXPECT_EQ(u.data[0], 4);
  EXPECT_EQ(readLe32(u.data, 2), 0x70000101u);
  EXPECT_EQ(readLe32(u.data, 14), 0x70000310u);
  // Record with a BOOL: 16 + 8 + 16 + 1 bits -> 6 bytes, the flag in bit 0 of byte 5.
  ASSERT_TRUE(t.od->set<std::uint8_t>(0x2008, 1, 0x11).ok());
  ASSERT_TRUE(t.od->set<std::uint16_t>(0x2008, 2, 0x3322).ok());
  ASSERT_TRUE(t.od->set<bool>(0x2008, 3, true).ok());
  u = t.master->upload(0x2008, 0, true);
  EXPECT_EQ(u.data, (std::vector<std::uint8_t>{3, 0, 0x11, 0x22, 0x33, 0x01}));
  u = t.master->upload(0x2008, 1, true);
  EXPECT_EQ(u.data, (std::vector<std::uint8_t>{0x11, 0x22, 0x33, 0x01})) << "from sub 1";

  // CA download of the assignment in PREOP: {2, 0, 0x1600, 0x1601}.
  EXPECT_EQ(t.master->download(0x1C12, 0, {2, 0, 0x00, 0x16, 0x01, 0x16}, true), 0u);
  EXPECT_EQ(t.master->uploadValue<std::uint8_t>(0x1C12, 0), 2);
  EXPECT_EQ(t.master->uploadValue<std::uint16_t>(0x1C12, 2), 0x1601);
  // A refused CA download leaves the object as it was (0x1A01 cannot go to SM2).
  EXPECT_EQ(t.master->download(0x1C12, 0, {2, 0, 0x00, 0x16, 0x01, 0x1A}, true), 0x06090030u);
  EXPECT_EQ(t.master->uploadValue<std::uint16_t>(0x1C12, 2), 0x1601);
  EXPECT_EQ(t.master->upload(0x1C12, 2, true).abort, 0x06090011u) << "CA starts at sub 0 or 1";
}

TEST(CoeSdo, CompleteAccessRefusedWhenTheDeviceHasNone) {
  CoeServerOptions options;
  options.completeAccess = false;
  CoeTestSlave t(128, options);
  EXPECT_EQ(t.master->upload(0x1C12, 0, true).abort, 0x06010004u);
  EXPECT_EQ(t.master->download(0x1C12, 0, {0, 0, 0, 0, 0, 0}, true), 0x06010004u);
  EXPECT_EQ(t.master->upload(0x1C12, 0).abort, 0u) << "single access still works";
}

std::vector<std::uint8_t> mailboxOfType(std::uint8_t type, std::uint16_t length,
                                        std::uint8_t counter) {
  std::vector<std::uint8_t> m(16, 0);
  writeLe16(m, 0, length);
  m[5] = static_cast<std::uint8_t>(type | (counter << 4));
  return m;
}

TEST(CoeSdo, MailboxErrors) {
  CoeTestSlave t;
  struct Case {
    std::vector<std::uint8_t> request;
    std::uint16_t detail;
    const char* why;
  };
  std::vector<std::uint8_t> shortSdo = mailboxOfType(3, 4, 5);
  writeLe16(shortSdo, 6, 0x2000);  // CoE service 2, SDO request
  std::vector<std::uint8_t> unknownService = mailboxOfType(3, 10, 3);
  writeLe16(unknownService, 6, 0x5000);  // CoE service 5 (RxPDO) is not served
  const Case cases[] = {
      {mailboxOfType(4, 10, 1), 0x0002, "FoE: unsupported protocol"},
      {mailboxOfType(3, 200, 2), 0x0008, "length past the 128-byte SM0: invalid size"},
      {unknownService, 0x0004, "service not supported"},
      {mailboxOfType(3, 1, 4), 0x0006, "no room for the CoE header: size too short"},
      {shortSdo, 0x0006, "SDO shorter than 8 bytes: size too short"},
  };
  for (const Case& c : cases) {
    auto reply = t.master->transact(c.request);
    ASSERT_TRUE(reply) << c.why;
    auto decoded = decodeMailbox(*reply);
    ASSERT_TRUE(decoded.ok()) << c.why;
    EXPECT_EQ(decoded->header.type, MailboxType::kError) << c.why;
    auto error = MailboxErrorReply::decode(decoded->payload);
    ASSERT_TRUE(error.ok()) << c.why;
    EXPECT_EQ(error->detail, c.detail) << c.why;
  }
}

TEST(CoeSdo, RepeatedCounterIsAnsweredAgainNotExecutedAgain) {
  CoeTestSlave t;
  std::vector<std::uint8_t> write(128, 0);
  MailboxHeader h;
  h.counter = 5;
  const std::vector<std::uint8_t> value{0x11, 0x11};
  auto n = encodeSdoRequestMailbox(
      write, SdoInitiateDownloadRequest{0x2001, 0, false, true, true, 2, value}, h);
  ASSERT_TRUE(n.ok());
  auto first = t.master->transact(write);
  ASSERT_TRUE(first);
  EXPECT_EQ(t.od->get<std::uint16_t>(0x2001, 0).value(), 0x1111);
  ASSERT_TRUE(t.od->set<std::uint16_t>(0x2001, 0, 0x2222).ok());  // the device changes it
  auto again = t.master->transact(write);  // the master retries: same counter, same request
  ASSERT_TRUE(again);
  EXPECT_EQ(*again, *first) << "the same response, byte for byte";
  EXPECT_EQ(t.od->get<std::uint16_t>(0x2001, 0).value(), 0x2222) << "not executed again";
  EXPECT_EQ(t.server->counters().repeatedRequests, 1u);
  write[5] = static_cast<std::uint8_t>((write[5] & 0x8F) | (6 << 4));  // next counter
  ASSERT_TRUE(t.master->transact(write));
  EXPECT_EQ(t.od->get<std::uint16_t>(0x2001, 0).value(), 0x1111) << "a new counter executes";
}

TEST(CoeSdo, EmergencyWaitsForAFreeSm1) {
  CoeTestSlave t;
  // A response is pending in SM1 (not read yet); the emergency queues behind it.
  t.master->send(t.master->sdoRequest(SdoInitiateUploadRequest{0x1000, 0, false}));
  t.server->pushEmergency(Emergency{0x8611, 0x80, {1, 2, 3, 4, 5}});
  EXPECT_EQ(t.server->queuedMessages(), 1u);
  auto response = t.master->receive();
  ASSERT_TRUE(response);
  EXPECT_FALSE(MailboxMaster::isEmergency(*response));
  auto emergency = t.master->receive();
  ASSERT_TRUE(emergency) << "sent once SM1 was read";
  auto decoded = decodeEmergencyMailbox(*emergency);
  ASSERT_TRUE(decoded.ok());
  EXPECT_EQ(decoded->errorCode, 0x8611);
  EXPECT_EQ(decoded->errorRegister, 0x80);
  EXPECT_EQ(t.server->counters().emergenciesSent, 1u);
  // transact() skips emergencies as SOEM does and still gets the SDO response.
  t.server->pushEmergency(Emergency{0x1000, 0x01, {}});
  EXPECT_EQ(t.master->uploadValue<std::uint32_t>(0x1000, 0), 0x00001389u);
  EXPECT_EQ(t.master->emergencies.size(), 1u);
}

TEST(CoeSdo, NoAnswerWhileTheMailboxIsOff) {
  CoeTestSlave t(128, {}, false);  // INIT, SMs not configured
  EXPECT_EQ(t.master->send(t.master->sdoRequest(SdoInitiateUploadRequest{0x1000, 0, false})), 1)
      << "the write goes to plain RAM";
  EXPECT_FALSE(t.master->receive());
  EXPECT_EQ(t.server->counters().requests, 0u);
}

}  // namespace
}  // namespace ecsim::testing
