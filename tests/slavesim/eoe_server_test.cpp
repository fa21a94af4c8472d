// The slave's EoE server through frames (ETG.1000.6 §5.7; requests as SOEM v1.4
// ethercateoe.c builds them): Set/Get IP Parameter, ARP and ICMP echo answered by the
// device's own stack, fragments both ways at the mailbox size, loopback of other frames (the
// SOES test slave SOEM's eoe_test expects), a broken fragment sequence dropped.
#include <gtest/gtest.h>

#include <numeric>

#include "protocol/eoe.hpp"
#include "slavesim/eoe/eoe_params.hpp"
#include "slavesim/eoe/eoe_server.hpp"
#include "tests/slavesim/coe_test_support.hpp"

namespace ecsim::testing {
namespace {

constexpr Ipv4Address kSlaveIp{192, 168, 9, 200};
constexpr Ipv4Address kHostIp{192, 168, 9, 1};
constexpr MacAddress kHostMac{0x02, 0x11, 0x22, 0x33, 0x44, 0x55};

struct EoeSlave {
  CoeTestSlave t;
  slavesim::eoe::EoeServer* eoe{nullptr};
  EoeReassembler reassembler;

  explicit EoeSlave(std::uint16_t mailboxSize = 128, slavesim::eoe::EoeServerOptions o = {})
      : t(mailboxSize) {
    auto s = std::make_unique<slavesim::eoe::EoeServer>(o);
    eoe = s.get();
    t.server->addProtocol(std::move(s));
  }

  std::vector<std::uint8_t> message(const EoeHeader& h, ConstBytes body) {
    MailboxHeader mh;
    mh.counter = t.master->nextCounter();
    auto m = encodeEoeMessage(h, body, mh);
    EXPECT_TRUE(m.ok());
    return *m;
  }
  // One request, one EoE answer: its header and body.
  std::pair<EoeHeader, std::vector<std::uint8_t>> request(EoeFrameType type, ConstBytes body) {
    EoeHeader h;
    h.type = static_cast<std::uint8_t>(type);
    auto reply = t.master->transact(message(h, body));
    EXPECT_TRUE(reply);
    if (!reply) return {};
    auto m = decodeMailbox(*reply);
    EXPECT_TRUE(m.ok());
    EXPECT_EQ(m->header.type, MailboxType::kEoe);
    auto eh = EoeHeader::decode(m->payload);
    EXPECT_TRUE(eh.ok());
    auto rest = m->payload.subspan(kEoeHeaderSize);
    return {*eh, std::vector<std::uint8_t>(rest.begin(), rest.end())};
  }
  // Sends a frame in fragments the way SOEM's ecx_EOEsend does (no answer expected).
  void sendFrame(ConstBytes frame, std::uint8_t frameNumber = 1) {
    auto fragments = fragmentEoeFrame(frame, t.master->mailboxOutSize(), 0, frameNumber);
    ASSERT_TRUE(fragments.ok()) << fragments.error().message();
    for (auto& f : *fragments) {
      f[5] = static_cast<std::uint8_t>((f[5] & 0x0F) | (t.master->nextCounter() << 4));
      EXPECT_EQ(t.master->send(f), 1);
    }
  }
  // Reads fragments until a frame is complete; counts them.
  std::optional<std::vector<std::uint8_t>> receiveFrame(int* fragments = nullptr) {
    for (int i = 0; i < 80; ++i) {
      auto r = t.master->receive();
      if (!r) continue;
      auto m = decodeMailbox(*r);
      if (!m.ok() || m->header.type != MailboxType::kEoe) continue;
      auto h = EoeHeader::decode(m->payload);
      EXPECT_TRUE(h.ok());
      EXPECT_EQ(h->frameType(), EoeFrameType::kFragment);
      if (fragments != nullptr) ++*fragments;
      auto done = reassembler.add(*h, m->payload.subspan(kEoeHeaderSize));
      EXPECT_TRUE(done.ok()) << done.error().message();
      if (done.ok() && done->has_value()) return std::move(**done);
    }
    return std::nullopt;
  }
  void setIp() {
    EoeIpParameters p;
    p.ip = kSlaveIp;
    p.subnetMask = Ipv4Address{255, 255, 255, 0};
    auto body = p.encode();
    auto [h, rest] = request(EoeFrameType::kSetIpRequest, *body);
    EXPECT_EQ(h.frameType(), EoeFrameType::kSetIpResponse);
    EXPECT_EQ(h.result, 0);
  }
};

std::vector<std::uint8_t> ethernet(const MacAddress& dst, std::uint16_t type, std::size_t size) {
  std::vector<std::uint8_t> f(size, 0);
  EthernetHeader e;
  e.destination = dst;
  e.source = kHostMac;
  e.etherType = type;
  EXPECT_TRUE(e.write(f).ok());
  return f;
}

std::vector<std::uint8_t> echoRequest(std::size_t payload, Ipv4Address to = kSlaveIp) {
  auto f = ethernet(kBroadcastMac, kEtherTypeIpv4, 14 + 20 + 8 + payload);
  Ipv4Header ip;
  ip.totalLength = static_cast<std::uint16_t>(20 + 8 + payload);
  ip.identification = 0x4242;
  ip.source = kHostIp;
  ip.destination = to;
  EXPECT_TRUE(ip.encode(Bytes(f).subspan(14)).ok());
  Bytes icmp = Bytes(f).subspan(34);
  icmp[0] = kIcmpEchoRequest;
  writeBe16(icmp, 4, 0x1234);  // identifier
  writeBe16(icmp, 6, 7);       // sequence
  for (std::size_t i = 0; i < payload; ++i) icmp[8 + i] = static_cast<std::uint8_t>(i * 7);
  writeBe16(icmp, 2, internetChecksum(icmp));
  return f;
}

TEST(EoeServer, SetIpThenGetIpReturnsWhatWasSet) {
  EoeSlave s;
  // Before any Set IP: only the MAC (station-derived, locally administered) is known.
  auto [before, beforeBody] = s.request(EoeFrameType::kGetIpRequest, {});
  EXPECT_EQ(before.frameType(), EoeFrameType::kGetIpResponse);
  auto unset = EoeIpParameters::decode(beforeBody);
  ASSERT_TRUE(unset.ok());
  EXPECT_FALSE(unset->ip);
  EXPECT_EQ(unset->mac, (MacAddress{0x02, 0, 0, 0, kStation >> 8, kStation & 0xFF}));

  s.setIp();
  EXPECT_EQ(s.eoe->counters().setIpRequests, 1u);
  auto [h, body] = s.request(EoeFrameType::kGetIpRequest, {});
  EXPECT_EQ(h.frameType(), EoeFrameType::kGetIpResponse);
  // SOEM ecx_EOEgetIp reads all 58 bytes and fails when fewer came.
  EXPECT_EQ(body.size(), kEoeIpParameterSize);
  auto got = EoeIpParameters::decode(body);
  ASSERT_TRUE(got.ok());
  EXPECT_EQ(got->ip, kSlaveIp);
  EXPECT_EQ(got->subnetMask, (Ipv4Address{255, 255, 255, 0}));
  EXPECT_FALSE(got->gateway);

  // An address filter is refused as a device without one does.
  auto [f, fbody] = s.request(EoeFrameType::kSetAddressFilterRequest, std::vector<std::uint8_t>(4));
  EXPECT_EQ(f.frameType(), EoeFrameType::kSetAddressFilterResponse);
  EXPECT_EQ(f.result, static_cast<std::uint16_t>(EoeResult::kNoFilterSupport));
}

TEST(EoeServer, AnswersArpForItsIpOnly) {
  EoeSlave s;
  s.setIp();
  auto frame = ethernet(kBroadcastMac, kEtherTypeArp, 60);
  ArpPacket who;
  who.senderMac = kHostMac;
  who.senderIp = kHostIp;
  who.targetIp = {192, 168, 9, 201};  // someone else
  ASSERT_TRUE(who.encode(Bytes(frame).subspan(14)).ok());
  s.sendFrame(frame);
  EXPECT_FALSE(s.t.master->receive(2)) << "no answer for another address";
  EXPECT_EQ(s.eoe->counters().framesIgnored, 1u);

  who.targetIp = kSlaveIp;
  ASSERT_TRUE(who.encode(Bytes(frame).subspan(14)).ok());
  s.sendFrame(frame, 2);
  auto reply = s.receiveFrame();
  ASSERT_TRUE(reply);
  ASSERT_EQ(reply->size(), kMinFrameSize);
  auto eth = EthernetHeader::parse(*reply);
  ASSERT_TRUE(eth.ok());
  EXPECT_EQ(eth->destination, kHostMac);
  EXPECT_EQ(eth->etherType, kEtherTypeArp);
  auto arp = ArpPacket::decode(ConstBytes(*reply).subspan(14));
  ASSERT_TRUE(arp.ok());
  EXPECT_EQ(arp->operation, kArpReply);
  EXPECT_EQ(arp->senderIp, kSlaveIp);
  EXPECT_EQ(arp->senderMac, eth->source);
  EXPECT_EQ(arp->targetMac, kHostMac);
  EXPECT_EQ(arp->targetIp, kHostIp);
}

TEST(EoeServer, AnswersAFragmentedPingWithAFragmentedReply) {
  // 128-byte mailboxes: 118 bytes of room, 96 a fragment; a 400-byte ICMP payload makes a
  // 442-byte frame, 5 fragments each way.
  EoeSlave s(128);
  s.setIp();
  const auto request = echoRequest(400);
  s.sendFrame(request);
  EXPECT_EQ(s.eoe->counters().fragmentsReceived, 5u);
  int fragments = 0;
  auto reply = s.receiveFrame(&fragments);
  ASSERT_TRUE(reply);
  EXPECT_EQ(fragments, 5);
  ASSERT_EQ(reply->size(), request.size());
  auto ip = Ipv4Header::decode(ConstBytes(*reply).subspan(14));  // checks the header checksum
  ASSERT_TRUE(ip.ok()) << ip.error().message();
  EXPECT_EQ(ip->source, kSlaveIp);
  EXPECT_EQ(ip->destination, kHostIp);
  const ConstBytes icmp = ConstBytes(*reply).subspan(34);
  EXPECT_EQ(icmp[0], kIcmpEchoReply);
  EXPECT_EQ(internetChecksum(icmp), 0) << "ICMP checksum";
  EXPECT_TRUE(std::equal(icmp.begin() + 4, icmp.end(), request.begin() + 38))
      << "identifier, sequence and payload come back";
  EXPECT_EQ(s.eoe->counters().echoReplies, 1u);

  // A corrupted ICMP checksum is not answered; nor is a ping to another address.
  auto bad = echoRequest(16);
  bad[40] ^= 0xFF;
  s.sendFrame(bad, 3);
  s.sendFrame(echoRequest(16, {192, 168, 9, 7}), 4);
  EXPECT_FALSE(s.t.master->receive(2));
  EXPECT_EQ(s.eoe->counters().echoReplies, 1u);
}

TEST(EoeServer, LoopsOtherFramesBackAtTheMailboxSize) {
  // SOEM eoe_test v1.4 sends a 1024-byte EtherCAT-typed frame; through 128-byte mailboxes
  // (96 bytes a fragment) it goes both ways in 11 fragments.
  slavesim::eoe::EoeServerOptions o;
  o.loopback = true;
  EoeSlave s(128, o);
  std::vector<std::uint8_t> frame = ethernet(kBroadcastMac, kEtherTypeEtherCat, 1024);
  std::iota(frame.begin() + 14, frame.end(), std::uint8_t{3});
  s.sendFrame(frame);
  int fragments = 0;
  auto back = s.receiveFrame(&fragments);
  ASSERT_TRUE(back);
  EXPECT_EQ(*back, frame);
  EXPECT_EQ(fragments, 11);  // 10 x 96 + 64
  EXPECT_EQ(s.eoe->counters().framesForwarded, 1u);
}

TEST(EoeServer, DropsABrokenFragmentSequenceAndTakesTheNextFrame) {
  EoeSlave s(128);
  s.setIp();
  auto fragments = fragmentEoeFrame(echoRequest(200), 128, 0, 1);
  ASSERT_TRUE(fragments.ok());
  ASSERT_GE(fragments->size(), 3u);
  for (std::size_t i : {std::size_t{0}, std::size_t{2}}) {  // fragment 1 lost
    auto f = (*fragments)[i];
    f[5] = static_cast<std::uint8_t>(0x02 | (s.t.master->nextCounter() << 4));
    s.t.master->send(f);
  }
  EXPECT_EQ(s.eoe->counters().reassemblyErrors, 1u);
  s.sendFrame(echoRequest(200), 2);
  auto reply = s.receiveFrame();
  ASSERT_TRUE(reply);
  EXPECT_EQ(s.eoe->counters().echoReplies, 1u);
}

TEST(EoeParams, TopologyParamsSetTheIpAndNameABadOneWithItsLine) {
  EoeSlave s;
  ASSERT_TRUE(slavesim::eoe::applyEoeParams(*s.eoe, {{"eoe.ip", "192.168.9.200", 3},
                                                     {"eoe.mac", "02:00:00:00:00:2a", 4},
                                                     {"eoe.name", "drive1", 5}})
                  .ok());
  // Get IP answers what the file said, without any Set IP from a master.
  auto [h, body] = s.request(EoeFrameType::kGetIpRequest, {});
  auto got = EoeIpParameters::decode(body);
  ASSERT_TRUE(got.ok());
  EXPECT_EQ(got->ip, kSlaveIp);
  EXPECT_EQ(got->mac, (MacAddress{2, 0, 0, 0, 0, 0x2a}));
  EXPECT_EQ(got->dnsName, "drive1");

  auto typo = slavesim::eoe::applyEoeParams(*s.eoe, {{"eoe.gatway", "10.0.0.1", 7}});
  ASSERT_FALSE(typo.ok());
  EXPECT_NE(typo.error().context.find("line 7"), std::string::npos) << typo.error().context;
  EXPECT_NE(typo.error().context.find("did you mean 'eoe.gateway'"), std::string::npos)
      << typo.error().context;
  auto bad = slavesim::eoe::applyEoeParams(*s.eoe, {{"eoe.mask", "255.255.0", 9}});
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().context.find("line 9: eoe.mask"), std::string::npos)
      << bad.error().context;
}

}  // namespace
}  // namespace ecsim::testing
