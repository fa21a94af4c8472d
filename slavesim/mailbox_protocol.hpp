// A mailbox protocol other than CoE (FoE, EoE, SoE; ETG.1000.6 §5.7-5.9) behind a slave's
// mailbox endpoint (coe::CoeServer, which owns SM0/SM1, the mailbox counter, retries and the
// outgoing queue). The endpoint decodes the mailbox header and hands each request whose type
// the protocol claims to onMessage(); a type nobody claims gets the "unsupported protocol"
// mailbox error (ETG.1000.4 §5.6, error detail 0x0002) as before.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "protocol/mailbox.hpp"
#include "protocol/time.hpp"

namespace ecsim::slavesim {

class Esc;

// Where a protocol's answers go: complete mailbox messages, header included. The endpoint
// sets each message's counter, keeps it for a retry of the same request and sends it when
// SM1 is free, in the order queued.
class MailboxReplies {
 public:
  virtual void send(std::vector<std::uint8_t> message) = 0;
  // SM1's length: the largest message the master can read at once (0 when SM1 is off).
  virtual std::size_t mailboxSize() const = 0;
  // Replies queued and not yet sent (a protocol sending several fragments can pace itself).
  virtual std::size_t queuedMessages() const = 0;

 protected:
  ~MailboxReplies() = default;
};

class MailboxProtocol {
 public:
  virtual ~MailboxProtocol() = default;
  // The mailbox type (header byte 5, low nibble) this protocol answers.
  virtual MailboxType type() const = 0;
  // One request of type(); `message.payload` is exactly the header's length.
  virtual void onMessage(Esc& esc, const MailboxMessage& message, MailboxReplies& replies,
                         SimTime now) = 0;
  // Called whenever the firmware is polled with the mailbox on (for work between requests).
  virtual void poll(Esc& /*esc*/, MailboxReplies& /*replies*/, SimTime /*now*/) {}
  // The mailbox SyncManagers were switched off (INIT, a master resetting the slave): drop
  // every transfer in progress.
  virtual void reset() {}
};

}  // namespace ecsim::slavesim
