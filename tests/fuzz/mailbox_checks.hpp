// Properties the fuzz targets check on every input offered as a mailbox buffer: no decoder
// reads out of bounds (AddressSanitizer), and whatever decodes re-encodes into bytes that
// decode to the same value. A broken property traps, which libFuzzer reports as a crash.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "protocol/coe.hpp"
#include "protocol/mailbox.hpp"
#include "protocol/sdo.hpp"
#include "protocol/sdo_info.hpp"

namespace ecsim::fuzz {

inline void require(bool property) {
  if (!property) __builtin_trap();
}

// Re-encoding may shorten a message (bytes a decoder ignores are not written back), so the
// length is the one header field allowed to differ.
inline bool sameRouting(const MailboxHeader& a, const MailboxHeader& b) {
  return a.address == b.address && a.channel == b.channel && a.priority == b.priority &&
         a.type == b.type && a.counter == b.counter;
}

inline void checkMailboxHeader(ConstBytes in) {
  auto header = MailboxHeader::decode(in);
  if (!header) return;
  std::uint8_t out[kMailboxHeaderSize];
  require(header->encode(out).ok());
  for (std::size_t i = 0; i < 5; ++i) require(out[i] == in[i]);
  require(out[5] == (in[5] & 0x7F));  // bit 7 is reserved
}

inline void checkSdo(ConstBytes in) {
  std::vector<std::uint8_t> out(in.size() + 16);
  if (auto req = decodeSdoRequestMailbox(in)) {
    auto n = encodeSdoRequestMailbox(out, req->sdo, req->mailbox);
    require(n.ok() && *n <= in.size());
    auto again = decodeSdoRequestMailbox(ConstBytes(out).first(*n));
    require(again.ok() && again->sdo == req->sdo && sameRouting(again->mailbox, req->mailbox));
  }
  if (auto resp = decodeSdoResponseMailbox(in)) {
    auto n = encodeSdoResponseMailbox(out, resp->sdo, resp->mailbox);
    require(n.ok() && *n <= in.size());
    auto again = decodeSdoResponseMailbox(ConstBytes(out).first(*n));
    require(again.ok() && again->sdo == resp->sdo && sameRouting(again->mailbox, resp->mailbox));
  }
}

inline void checkSdoInfo(ConstBytes in) {
  auto message = decodeSdoInfoMailbox(in);
  if (!message) return;
  std::vector<std::uint8_t> out(in.size() + 64);
  if (auto req = decodeSdoInfoRequest(*message)) {
    auto n = encodeSdoInfoRequestMailbox(out, *req, message->mailbox);
    require(n.ok());
    auto again = decodeSdoInfoMailbox(ConstBytes(out).first(*n));
    require(again.ok());
    auto reqAgain = decodeSdoInfoRequest(*again);
    require(reqAgain.ok() && *reqAgain == *req);
  }
  (void)decodeSdoInfoResponse(*message);
  if (auto resp = decodeSdoInfoResponse(message->header.opcode, message->data)) {
    auto n = encodeSdoInfoResponseMailbox(out, *resp, message->mailbox);
    require(n.ok());
    auto again = decodeSdoInfoMailbox(ConstBytes(out).first(*n));
    require(again.ok());
    auto respAgain = decodeSdoInfoResponse(*again);
    require(respAgain.ok() && *respAgain == *resp);
  }
}

inline void checkOthers(ConstBytes in) {
  if (auto emergency = decodeEmergencyMailbox(in)) {
    std::uint8_t out[kCoeBodyOffset + Emergency::kSize];
    require(encodeEmergencyMailbox(out, *emergency).ok());
    auto again = decodeEmergencyMailbox(out);
    require(again.ok() && *again == *emergency);
  }
  if (auto message = decodeMailbox(in); message && message->header.type == MailboxType::kError) {
    if (auto reply = MailboxErrorReply::decode(message->payload)) {
      (void)mailboxErrorText(reply->detail);
    }
  }
  if (auto coe = decodeCoeMailbox(in)) {
    (void)toString(coe->coe.service);
    if (coe->body.size() >= 4) (void)sdoAbortText(readLe32(coe->body, 0));
  }
}

// Everything a received SyncManager buffer goes through.
inline void checkMailboxBuffer(ConstBytes in) {
  checkMailboxHeader(in);
  checkSdo(in);
  checkSdoInfo(in);
  checkOthers(in);
}

// Reads `in` as consecutive mailboxes and joins the SDO-information ones.
inline void checkReassembly(ConstBytes in) {
  SdoInfoReassembler joiner;
  for (int i = 0; i < 16 && !in.empty(); ++i) {
    auto message = decodeMailbox(in);
    if (!message) return;
    const std::size_t used = kMailboxHeaderSize + message->header.length;
    if (auto info = decodeSdoInfoMailbox(in.first(used))) {
      if (joiner.add(*info).ok() && joiner.complete()) {
        (void)decodeSdoInfoResponse(joiner.opcode(), joiner.data());
        joiner.reset();
      }
    }
    in = in.subspan(used);
  }
}

// Splits `data` over mailboxes of a size taken from the input and joins them again.
inline void checkFragmentation(ConstBytes in) {
  if (in.size() < 2) return;
  const std::size_t mailboxSize = kSdoInfoDataOffset + 2 + in[0];
  const ConstBytes data = in.subspan(1);
  auto fragmenter = SdoInfoFragmenter::create(SdoInfoOpcode::kGetOdListResponse, data, mailboxSize);
  require(fragmenter.ok());
  require(fragmenter->fragmentCapacity() % 2 == 0);
  SdoInfoReassembler joiner;
  std::vector<std::uint8_t> sm(mailboxSize);
  for (std::size_t i = 0; i < fragmenter->fragmentCount(); ++i) {
    auto n = fragmenter->encodeFragment(i, sm);
    require(n.ok() && *n <= mailboxSize);
    auto message = decodeSdoInfoMailbox(ConstBytes(sm).first(*n));
    require(message.ok());
    require(joiner.add(*message).ok());
  }
  require(joiner.complete());
  require(joiner.data().size() == data.size());
  for (std::size_t i = 0; i < data.size(); ++i) require(joiner.data()[i] == data[i]);
}

}  // namespace ecsim::fuzz
