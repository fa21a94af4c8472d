// SoE server (ETG.1000.6 §5.9) behind the slave's mailbox endpoint (slavesim/mailbox_protocol.hpp):
// one IdnDictionary per drive number (ESI <SoE ChannelCount>).
//
//   read      the elements asked for, in element order (data state, name, attribute, unit,
//             minimum, maximum, value, default); names and units as lists (u16 current,
//             u16 maximum length, text); fixed-length values in their attribute's size, lists
//             with their header. A response longer than SM1 leaves room for goes out in
//             fragments: `incomplete` set and the fragments still to come in the IDN field,
//             the last one plain with the IDN (what SOEM's ecx_SoEread and IgH reassemble).
//   write     the value element only (the others answer "cannot be changed (read only)");
//             fragments with `incomplete` are collected without a reply until the last.
//             Checks: read-only 0x7004, write-protected in this state 0x7005 (attribute bits
//             28-30: PREOP = CP2, SAFEOP = CP3, OP = CP4), length 0x7002 / 0x7003, minimum /
//             maximum 0x7006 / 0x7007, an AT / MDT configuration naming an IDN that is not
//             configurable there (S-0-0187 / S-0-0188) 0x7008.
//   commands  a procedure command written 3 (set and enable) is in progress (data state 0x7)
//             for kCommandDuration, then executed (0x3); 1 sets it (0x1), 0 cancels (0x0);
//             3 while in progress answers 0x7010. S-0-0099 (reset class 1 diagnostic) clears
//             S-0-0011 when it executes.
//   errors    an unknown IDN 0x1001, a drive number beyond the drives 0x800A, no element
//             asked 0x800C, an element the IDN does not have 0x2001/0x4001/0x5001/0x6001/
//             0x8001; an error response is the service's response with the error bit and the
//             code as its last two bytes.
#pragma once

#include <cstdint>
#include <vector>

#include "protocol/soe.hpp"
#include "slavesim/mailbox_protocol.hpp"
#include "slavesim/soe/idn_dictionary.hpp"

namespace ecsim::slavesim::soe {

struct SoeServerCounters {
  std::uint64_t reads{0};
  std::uint64_t writes{0};
  std::uint64_t errors{0};
  std::uint64_t fragmentsSent{0};
  std::uint64_t fragmentsReceived{0};
};

class SoeServer final : public MailboxProtocol {
 public:
  // Procedure commands take this long (virtual time) from "set and enable" to "executed"; a
  // Rexroth IndraDrive acknowledges in about 2 ms (its manual's command timing figure).
  static constexpr SimTime kCommandDuration = 2 * kNsPerMs;

  explicit SoeServer(std::vector<IdnDictionary> drives);

  MailboxType type() const override { return MailboxType::kSoe; }
  void onMessage(Esc& esc, const MailboxMessage& message, MailboxReplies& replies,
                 SimTime now) override;
  void poll(Esc& esc, MailboxReplies& replies, SimTime now) override;
  void reset() override;

  std::size_t driveCount() const { return drives_.size(); }
  IdnDictionary& drive(std::size_t n) { return drives_.at(n); }
  const SoeServerCounters& counters() const { return counters_; }

 private:
  struct Incoming {
    bool active{false};
    std::uint8_t driveNo{0};
    std::uint8_t elements{0};
    std::vector<std::uint8_t> data;
  };

  void read(const SoeHeader& request, MailboxReplies& replies);
  void write(Esc& esc, const SoeHeader& request, ConstBytes data, MailboxReplies& replies,
             SimTime now);
  // 0 when written, else an SoE error code.
  std::uint16_t writeValue(Esc& esc, IdnDictionary& drive, IdnEntry& entry, ConstBytes data,
                           SimTime now);
  std::uint16_t runCommand(IdnDictionary& drive, IdnEntry& entry, std::uint16_t value, SimTime now);
  void sendError(const SoeHeader& request, std::uint16_t code, MailboxReplies& replies);
  void send(SoeHeader header, ConstBytes data, MailboxReplies& replies);

  std::vector<IdnDictionary> drives_;
  Incoming incoming_;
  SoeServerCounters counters_{};
};

}  // namespace ecsim::slavesim::soe
