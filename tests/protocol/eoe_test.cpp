// EoE wire format (ETG.1000.6 §5.7), checked against what SOEM v1.4 ethercateoe.c writes and
// reads (ecx_EOEsetIp, ecx_EOEgetIp, ecx_EOEsend, ecx_EOEreadfragment) and against
// Wireshark's EtherCAT mailbox dissector (tshark decoded the Set IP request below, embedded in
// an FPWR to 0x1000, as "Init Req" with IP 192.168.9.200, subnet 255.255.255.0).
#include "protocol/eoe.hpp"

#include <gtest/gtest.h>

#include <numeric>
#include <vector>

namespace ecsim {
namespace {

// SOEM v1.4 eoe_test.c: ecx_EOEsetIp for 192.168.9.200/255.255.255.0, gateway 0.0.0.0, port 0,
// mailbox counter 1: frame info 1 = type 2 | last fragment, flags = IP|subnet|gateway, each
// address as a little-endian UINT32 (EOE_ip_uint32_to_byte), 58 bytes after the EoE header
// area (EOE_PARAM_OFFSET + 6 + 4*4 + 32), mailbox length 4 + 58 = 62.
std::vector<std::uint8_t> soemSetIpRequest() {
  std::vector<std::uint8_t> m(kMailboxHeaderSize + 62, 0);
  m[0] = 62;
  m[5] = 0x12;  // EoE, counter 1
  m[6] = 0x02;
  m[7] = 0x01;   // type 2, last fragment
  m[10] = 0x0E;  // flags
  const std::uint8_t ip[] = {0xC8, 0x09, 0xA8, 0xC0};
  const std::uint8_t mask[] = {0x00, 0xFF, 0xFF, 0xFF};
  std::copy(std::begin(ip), std::end(ip), m.begin() + 6 + 4 + 4 + 6);
  std::copy(std::begin(mask), std::end(mask), m.begin() + 6 + 4 + 4 + 10);
  return m;
}

TEST(EoeHeader, DecodesSoemSetIpRequest) {
  auto m = soemSetIpRequest();
  auto mbx = decodeMailbox(m);
  ASSERT_TRUE(mbx.ok());
  EXPECT_EQ(mbx->header.type, MailboxType::kEoe);
  auto h = EoeHeader::decode(mbx->payload);
  ASSERT_TRUE(h.ok());
  EXPECT_EQ(h->frameType(), EoeFrameType::kSetIpRequest);
  EXPECT_TRUE(h->lastFragment);
  EXPECT_EQ(h->port, 0);
  auto p = EoeIpParameters::decode(mbx->payload.subspan(kEoeHeaderSize));
  ASSERT_TRUE(p.ok()) << p.error().message();
  EXPECT_FALSE(p->mac);
  EXPECT_EQ(p->ip, (Ipv4Address{192, 168, 9, 200}));
  EXPECT_EQ(p->subnetMask, (Ipv4Address{255, 255, 255, 0}));
  EXPECT_EQ(p->gateway, (Ipv4Address{0, 0, 0, 0}));
  EXPECT_FALSE(p->dnsServer);
  EXPECT_FALSE(p->dnsName);
}

TEST(EoeHeader, EncodesTheSameBytesSoemSends) {
  EoeIpParameters p;
  p.ip = Ipv4Address{192, 168, 9, 200};
  p.subnetMask = Ipv4Address{255, 255, 255, 0};
  p.gateway = Ipv4Address{0, 0, 0, 0};
  auto body = p.encode();
  ASSERT_TRUE(body.ok());
  EoeHeader h;
  h.type = static_cast<std::uint8_t>(EoeFrameType::kSetIpRequest);
  MailboxHeader mh;
  mh.counter = 1;
  auto m = encodeEoeMessage(h, *body, mh);
  ASSERT_TRUE(m.ok());
  EXPECT_EQ(*m, soemSetIpRequest());
}

TEST(EoeHeader, FragmentFieldsAndResultShareWordTwo) {
  // SOEM ecx_EOEsend, fragment 2 of frame 5 at byte offset 960, port 1, not last.
  const std::uint16_t w2 = 2 | ((960 / 32) << 6) | (5 << 12);
  const std::uint8_t raw[] = {0x10, 0x00, static_cast<std::uint8_t>(w2),
                              static_cast<std::uint8_t>(w2 >> 8)};
  auto h = EoeHeader::decode(raw);
  ASSERT_TRUE(h.ok());
  EXPECT_EQ(h->frameType(), EoeFrameType::kFragment);
  EXPECT_EQ(h->port, 1);
  EXPECT_FALSE(h->lastFragment);
  EXPECT_EQ(h->fragmentNumber, 2);
  EXPECT_EQ(h->offsetUnits, 30);
  EXPECT_EQ(h->frameNumber, 5);
  std::uint8_t out[4]{};
  ASSERT_TRUE(h->encode(out).ok());
  EXPECT_TRUE(std::equal(std::begin(raw), std::end(raw), std::begin(out)));

  // A Set IP response carries the result where a fragment has its numbers.
  EoeHeader r;
  r.type = static_cast<std::uint8_t>(EoeFrameType::kSetIpResponse);
  r.result = static_cast<std::uint16_t>(EoeResult::kNoIpSupport);
  ASSERT_TRUE(r.encode(out).ok());
  EXPECT_EQ(out[0], 0x03);
  EXPECT_EQ(out[1], 0x01);
  EXPECT_EQ(out[2], 0x01);
  EXPECT_EQ(out[3], 0x02);
  EXPECT_EQ(eoeResultText(0x0201), "no IP support");

  EoeHeader bad;
  bad.frameNumber = 16;
  EXPECT_FALSE(bad.encode(out).ok());
  EXPECT_FALSE(EoeHeader::decode(ConstBytes(raw, 3)).ok());
}

TEST(EoeIpParameters, RoundTripsEveryFieldAndRejectsAFlaggedFieldCutShort) {
  EoeIpParameters p;
  p.mac = MacAddress{0x02, 0x00, 0x00, 0x00, 0x00, 0x07};
  p.ip = Ipv4Address{10, 0, 0, 7};
  p.subnetMask = Ipv4Address{255, 0, 0, 0};
  p.gateway = Ipv4Address{10, 0, 0, 1};
  p.dnsServer = Ipv4Address{10, 0, 0, 2};
  p.dnsName = "slave7";
  auto body = p.encode();
  ASSERT_TRUE(body.ok());
  EXPECT_EQ(body->size(), kEoeIpParameterSize);
  EXPECT_EQ((*body)[0], 0x3F);
  auto back = EoeIpParameters::decode(*body);
  ASSERT_TRUE(back.ok()) << back.error().message();
  EXPECT_EQ(*back, p);

  auto cut = EoeIpParameters::decode(ConstBytes(*body).first(12));  // IP flagged, 2 bytes of it
  ASSERT_FALSE(cut.ok());
  EXPECT_NE(cut.error().context.find("byte 10"), std::string::npos) << cut.error().context;

  EoeIpParameters longName;
  longName.dnsName = std::string(33, 'x');
  EXPECT_FALSE(longName.encode().ok());

  EoeIpParameters update;
  update.ip = Ipv4Address{10, 0, 0, 8};
  p.merge(update);
  EXPECT_EQ(p.ip, update.ip);
  EXPECT_EQ(p.dnsName, "slave7");
}

std::vector<std::uint8_t> pattern(std::size_t n) {
  std::vector<std::uint8_t> v(n);
  std::iota(v.begin(), v.end(), std::uint8_t{1});
  return v;
}

TEST(EoeFragments, SplitLikeSoemAndReassemble) {
  // SOEM eoe_test sends a 1024-byte frame; with the EL6601's 520-byte mailbox SOEM's
  // ecx_EOEsend puts 480 bytes (510 rounded down to 32-byte units) in each fragment but the
  // last: 480 + 480 + 64.
  const auto frame = pattern(1024);
  auto fragments = fragmentEoeFrame(frame, 520, 0, 3);
  ASSERT_TRUE(fragments.ok()) << fragments.error().message();
  ASSERT_EQ(fragments->size(), 3u);
  const std::size_t sizes[] = {480, 480, 64};
  const std::uint8_t offsets[] = {1024 / 32, 480 / 32, 960 / 32};
  EoeReassembler r;
  for (std::size_t i = 0; i < 3; ++i) {
    auto m = decodeMailbox((*fragments)[i]);
    ASSERT_TRUE(m.ok());
    EXPECT_EQ(m->payload.size(), kEoeHeaderSize + sizes[i]);
    auto h = EoeHeader::decode(m->payload);
    ASSERT_TRUE(h.ok());
    EXPECT_EQ(h->fragmentNumber, i);
    EXPECT_EQ(h->offsetUnits, offsets[i]);
    EXPECT_EQ(h->frameNumber, 3);
    EXPECT_EQ(h->lastFragment, i == 2);
    auto got = r.add(*h, m->payload.subspan(kEoeHeaderSize));
    ASSERT_TRUE(got.ok()) << got.error().message();
    EXPECT_EQ(got->has_value(), i == 2);
    if (i == 2) {
      EXPECT_EQ(**got, frame);
    }
  }
  // The last fragment may fill the mailbox (not only whole units): a 510-byte frame is one.
  auto one = fragmentEoeFrame(pattern(510), 520, 0, 0);
  ASSERT_TRUE(one.ok());
  EXPECT_EQ(one->size(), 1u);
  EXPECT_FALSE(fragmentEoeFrame(pattern(100), 40, 0, 0).ok()) << "30 bytes of room: no unit";
  EXPECT_FALSE(fragmentEoeFrame(pattern(kEoeMaxFrameSize + 1), 520, 0, 0).ok());
}

TEST(EoeFragments, ReassemblyDropsAFrameWithAGapAndStripsTheTimestamp) {
  const auto frame = pattern(200);
  auto fragments = fragmentEoeFrame(frame, 6 + 4 + 64, 0, 1);  // 64 bytes a fragment
  ASSERT_TRUE(fragments.ok());
  ASSERT_EQ(fragments->size(), 4u);
  EoeReassembler r;
  auto first = decodeMailbox((*fragments)[0]);
  ASSERT_TRUE(r.add(*EoeHeader::decode(first->payload), first->payload.subspan(4)).ok());
  auto third = decodeMailbox((*fragments)[2]);  // fragment 1 lost
  auto gap = r.add(*EoeHeader::decode(third->payload), third->payload.subspan(4));
  ASSERT_FALSE(gap.ok());
  EXPECT_NE(gap.error().context.find("fragment 2 where 1 was due"), std::string::npos)
      << gap.error().context;
  EXPECT_FALSE(r.inProgress());

  // One fragment with a 4-byte timestamp appended: the frame is the data without it.
  EoeHeader h;
  h.offsetUnits = 1;
  h.timeAppended = true;
  std::vector<std::uint8_t> data = pattern(36);
  auto done = r.add(h, data);
  ASSERT_TRUE(done.ok()) << done.error().message();
  ASSERT_TRUE(done->has_value());
  EXPECT_EQ((*done)->size(), 32u);

  // More data than fragment 0 announced.
  h.timeAppended = false;
  auto over = r.add(h, pattern(33));
  EXPECT_FALSE(over.ok());
}

}  // namespace
}  // namespace ecsim
