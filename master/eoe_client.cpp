#include "master/eoe_client.hpp"

#include <fmt/core.h>

namespace ecsim::master {

EoeIpTask::EoeIpTask(Transport& transport, SlaveInfo& slave,
                     std::vector<ReceivedEmergency>* emergencies, MailboxOptions options)
    : exchange_(transport, slave, emergencies, options), slave_(slave) {}

bool EoeIpTask::fail(ErrorCode code, const std::string& what) {
  const bool set = expected_ == EoeFrameType::kSetIpResponse;
  status_ =
      makeError(code, std::string(set ? "EoE Set IP Parameter to " : "EoE Get IP Parameter from ") +
                          slave_.label() + ": " + what);
  done_ = true;
  return false;
}

Status EoeIpTask::send(EoeFrameType type, std::uint8_t port, ConstBytes body, SimTime now) {
  if (!slave_.mailbox)
    return makeError(ErrorCode::kUnsupported, slave_.label() + " has no mailbox");
  EoeHeader h;
  h.type = static_cast<std::uint8_t>(type);
  h.port = port;
  ECSIM_ASSIGN_OR_RETURN(auto message, encodeEoeMessage(h, body));
  done_ = false;
  status_ = okStatus();
  return exchange_.start(message, now);
}

Status EoeIpTask::startSet(const EoeIpParameters& parameters, std::uint8_t port, SimTime now) {
  expected_ = EoeFrameType::kSetIpResponse;
  ECSIM_ASSIGN_OR_RETURN(auto body, parameters.encode());
  return send(EoeFrameType::kSetIpRequest, port, body, now);
}

Status EoeIpTask::startGet(std::uint8_t port, SimTime now) {
  expected_ = EoeFrameType::kGetIpResponse;
  return send(EoeFrameType::kGetIpRequest, port, {}, now);
}

bool EoeIpTask::step(SimTime now) {
  if (done_) return false;
  if (exchange_.step(now)) return true;
  if (!exchange_.status().ok()) {
    return fail(exchange_.status().error().code, exchange_.status().error().context);
  }
  auto message = decodeMailbox(exchange_.response());
  if (!message.ok()) return fail(ErrorCode::kMalformed, message.error().context);
  if (message->header.type != MailboxType::kEoe) {
    return fail(ErrorCode::kMalformed,
                fmt::format("answered with a {} mailbox", toString(message->header.type)));
  }
  auto h = EoeHeader::decode(message->payload);
  if (!h.ok()) return fail(ErrorCode::kMalformed, h.error().context);
  if (h->frameType() != expected_) {
    return fail(ErrorCode::kMalformed,
                fmt::format("answered with EoE frame type {} ({}) where {} was due", h->type,
                            toString(h->frameType()), toString(expected_)));
  }
  if (expected_ == EoeFrameType::kSetIpResponse) {
    if (h->result != 0) {
      return fail(ErrorCode::kAborted,
                  fmt::format("result 0x{:04x} ({})", h->result, eoeResultText(h->result)));
    }
  } else {
    auto p = EoeIpParameters::decode(message->payload.subspan(kEoeHeaderSize));
    if (!p.ok()) return fail(ErrorCode::kMalformed, p.error().context);
    parameters_ = std::move(*p);
  }
  done_ = true;
  return false;
}

}  // namespace ecsim::master
