// Protocols other than CoE behind the mailbox endpoint (slavesim/mailbox_protocol.hpp): a
// request of a claimed type reaches its protocol with the decoded header and payload, its
// answers go out through SM1 with the endpoint's counter, a retry (same counter, same bytes;
// ETG.1000.4 §5.6) is answered again without reaching the protocol twice, and a type nobody
// claims still gets the "unsupported protocol" mailbox error (detail 0x0002).
#include <gtest/gtest.h>

#include "slavesim/mailbox_protocol.hpp"
#include "tests/slavesim/coe_test_support.hpp"

namespace ecsim::testing {
namespace {

// Answers each VoE request with its payload reversed, and says how often it was asked.
class ReversingProtocol final : public slavesim::MailboxProtocol {
 public:
  explicit ReversingProtocol(int* calls, int* resets) : calls_(calls), resets_(resets) {}
  MailboxType type() const override { return MailboxType::kVoe; }
  void onMessage(slavesim::Esc& /*esc*/, const MailboxMessage& message,
                 slavesim::MailboxReplies& replies, SimTime /*now*/) override {
    ++*calls_;
    std::vector<std::uint8_t> answer(kMailboxHeaderSize + message.payload.size(), 0);
    MailboxHeader h;
    h.type = MailboxType::kVoe;
    h.length = static_cast<std::uint16_t>(message.payload.size());
    (void)h.encode(answer);
    std::reverse_copy(message.payload.begin(), message.payload.end(),
                      answer.begin() + kMailboxHeaderSize);
    EXPECT_GE(replies.mailboxSize(), answer.size());
    replies.send(std::move(answer));
  }
  void reset() override { ++*resets_; }

 private:
  int* calls_;
  int* resets_;
};

std::vector<std::uint8_t> request(MailboxType type, std::uint8_t counter,
                                  std::vector<std::uint8_t> payload) {
  std::vector<std::uint8_t> m(kMailboxHeaderSize + payload.size(), 0);
  MailboxHeader h;
  h.type = type;
  h.counter = counter;
  h.length = static_cast<std::uint16_t>(payload.size());
  (void)h.encode(m);
  std::copy(payload.begin(), payload.end(), m.begin() + kMailboxHeaderSize);
  return m;
}

TEST(MailboxProtocol, ClaimedTypeReachesItsProtocolOnceAndIsRepeatedOnRetry) {
  CoeTestSlave t;
  int calls = 0;
  int resets = 0;
  t.server->addProtocol(std::make_unique<ReversingProtocol>(&calls, &resets));

  const auto voe = request(MailboxType::kVoe, 3, {1, 2, 3, 4, 5});
  auto reply = t.master->transact(voe);
  ASSERT_TRUE(reply);
  auto decoded = decodeMailbox(*reply);
  ASSERT_TRUE(decoded.ok());
  EXPECT_EQ(decoded->header.type, MailboxType::kVoe);
  EXPECT_NE(decoded->header.counter, 0) << "the endpoint numbers the protocol's answers";
  EXPECT_EQ(std::vector<std::uint8_t>(decoded->payload.begin(), decoded->payload.end()),
            (std::vector<std::uint8_t>{5, 4, 3, 2, 1}));
  EXPECT_EQ(calls, 1);

  auto again = t.master->transact(voe);  // the master lost the answer and retries
  ASSERT_TRUE(again);
  EXPECT_EQ(*again, *reply) << "the same answer, byte for byte";
  EXPECT_EQ(calls, 1) << "a retry is not executed again";
  EXPECT_EQ(t.server->counters().repeatedRequests, 1u);

  // A type nobody claims: the mailbox error as before.
  auto foe = t.master->transact(request(MailboxType::kFoe, 4, {0, 0}));
  ASSERT_TRUE(foe);
  auto error = decodeMailbox(*foe);
  ASSERT_TRUE(error.ok());
  EXPECT_EQ(error->header.type, MailboxType::kError);
  EXPECT_EQ(MailboxErrorReply::decode(error->payload)->detail, 0x0002);

  // The master switches the mailbox SMs off (as it does on the way to INIT): transfers in
  // progress are dropped.
  requestState(t.seg, kStation, 0x0001);
  for (unsigned sm = 0; sm < 2; ++sm) {
    one(t.seg, Command::kFpwr, phys(kStation, reg::smChannel(sm)), std::vector<std::uint8_t>(8, 0));
  }
  t.seg.pollSlaves(0);
  EXPECT_EQ(resets, 1);
}

}  // namespace
}  // namespace ecsim::testing
