// IPv4/ARP/ICMP helpers for the EoE device stack. The checksum example is RFC 1071 §3's;
// the IPv4 header is the one tshark shows for a Linux ping (192.168.9.1 -> 192.168.9.200).
#include "protocol/ipv4.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace ecsim {
namespace {

TEST(Ipv4, InternetChecksumOfRfc1071Example) {
  // RFC 1071 §3: 00 01 f2 03 f4 f5 f6 f7 sums to 0xddf2, checksum 0x220d.
  const std::uint8_t bytes[] = {0x00, 0x01, 0xf2, 0x03, 0xf4, 0xf5, 0xf6, 0xf7};
  EXPECT_EQ(internetChecksum(bytes), 0x220d);
  const std::uint8_t odd[] = {0x01};
  EXPECT_EQ(internetChecksum(odd), 0xFEFF);
}

TEST(Ipv4, HeaderRoundTripsWithAValidChecksum) {
  Ipv4Header h;
  h.totalLength = 84;
  h.identification = 0x1c46;
  h.flagsFragment = 0x4000;  // don't fragment
  h.source = {192, 168, 9, 1};
  h.destination = {192, 168, 9, 200};
  std::vector<std::uint8_t> b(84, 0);
  ASSERT_TRUE(h.encode(b).ok());
  EXPECT_EQ(internetChecksum(ConstBytes(b).first(20)), 0);
  auto back = Ipv4Header::decode(b);
  ASSERT_TRUE(back.ok()) << back.error().message();
  EXPECT_EQ(back->destination, h.destination);
  EXPECT_FALSE(back->isFragment());
  b[15] ^= 1;  // corrupt the source address
  EXPECT_FALSE(Ipv4Header::decode(b).ok());
}

TEST(Ipv4, ArpRoundTripAndParsing) {
  ArpPacket p;
  p.senderMac = {2, 0, 0, 0, 0, 1};
  p.senderIp = {10, 1, 1, 1};
  p.targetIp = {10, 1, 1, 2};
  std::uint8_t b[kArpSize]{};
  ASSERT_TRUE(p.encode(b).ok());
  auto back = ArpPacket::decode(b);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->targetIp, p.targetIp);
  EXPECT_EQ(back->operation, kArpRequest);

  EXPECT_EQ(parseIpv4("192.168.9.200").valueOr(Ipv4Address{}), (Ipv4Address{192, 168, 9, 200}));
  EXPECT_FALSE(parseIpv4("192.168.9").ok());
  EXPECT_FALSE(parseIpv4("192.168.9.256").ok());
  EXPECT_FALSE(parseIpv4("192.168.9.2x").ok());
  EXPECT_EQ(formatIpv4({10, 0, 0, 1}), "10.0.0.1");
  auto mac = parseMac("02:00:0a:0B:0c:ff");
  ASSERT_TRUE(mac.ok());
  EXPECT_EQ(formatMac(*mac), "02:00:0a:0b:0c:ff");
  EXPECT_FALSE(parseMac("02:00:0a:0b:0c").ok());
}

}  // namespace
}  // namespace ecsim
