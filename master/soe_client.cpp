#include "master/soe_client.hpp"

#include <cstdio>

namespace ecsim::master {

std::string describeSoeError(std::uint16_t code) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%04X", code);
  return std::string(buf) + " (" + std::string(soeErrorText(code)) + ")";
}

SoeTask::SoeTask(Transport& transport, SlaveInfo& slave,
                 std::vector<ReceivedEmergency>* emergencies, MailboxOptions options)
    : exchange_(transport, slave, emergencies, options), slave_(slave) {}

bool SoeTask::fail(ErrorCode code, const std::string& what) {
  const bool read = request_.opcode == SoeOpcode::kReadRequest;
  status_ =
      makeError(code, std::string(read ? "SoE read of " : "SoE write of ") +
                          formatIdn(request_.idn) + " (drive " + std::to_string(request_.driveNo) +
                          ") " + (read ? "from " : "to ") + slave_.label() + ": " + what);
  done_ = true;
  return false;
}

Status SoeTask::send(SimTime now) {
  if (!slave_.mailbox) {
    return makeError(ErrorCode::kUnsupported, slave_.label() + " has no mailbox");
  }
  ECSIM_ASSIGN_OR_RETURN(auto message, encodeSoeMailbox(request_, value_));
  if (message.size() > slave_.mailbox->outSize) {
    return makeError(ErrorCode::kTooLarge,
                     "SoE write of " + std::to_string(value_.size()) + " bytes to " +
                         formatIdn(request_.idn) + " does not fit " + slave_.label() + "'s " +
                         std::to_string(slave_.mailbox->outSize) +
                         "-byte mailbox (fragmented writes are not supported)");
  }
  status_ = okStatus();
  errorCode_.reset();
  data_.clear();
  fragments_ = 0;
  ECSIM_TRY(exchange_.start(message, now));
  done_ = false;
  return okStatus();
}

Status SoeTask::startRead(std::uint8_t driveNo, std::uint8_t elements, std::uint16_t idn,
                          SimTime now) {
  request_ = {};
  request_.opcode = SoeOpcode::kReadRequest;
  request_.driveNo = driveNo;
  request_.elements = elements;
  request_.idn = idn;
  value_.clear();
  return send(now);
}

Status SoeTask::startWrite(std::uint8_t driveNo, std::uint16_t idn, ConstBytes value, SimTime now) {
  request_ = {};
  request_.opcode = SoeOpcode::kWriteRequest;
  request_.driveNo = driveNo;
  request_.elements = soe_element::kValue;
  request_.idn = idn;
  value_.assign(value.begin(), value.end());
  return send(now);
}

bool SoeTask::step(SimTime now) {
  if (done_) return false;
  if (exchange_.step(now)) return true;
  if (!exchange_.status().ok()) {
    return fail(exchange_.status().error().code, exchange_.status().error().context);
  }
  auto message = decodeSoeMailbox(exchange_.response());
  if (!message.ok()) return fail(ErrorCode::kMalformed, "response: " + message.error().context);
  const SoeHeader& h = message->soe;
  const SoeOpcode expected = request_.opcode == SoeOpcode::kReadRequest ? SoeOpcode::kReadResponse
                                                                        : SoeOpcode::kWriteResponse;
  if (h.error) {
    if (message->data.size() < kSoeErrorCodeSize) {
      return fail(ErrorCode::kMalformed, "error response without its code");
    }
    errorCode_ = readLe16(message->data, message->data.size() - kSoeErrorCodeSize);
    return fail(ErrorCode::kAborted, "error " + describeSoeError(*errorCode_));
  }
  if (h.opcode != expected || h.driveNo != request_.driveNo || h.elements != request_.elements) {
    return fail(ErrorCode::kMalformed, "unexpected response: " + std::string(toString(h.opcode)) +
                                           ", drive " + std::to_string(h.driveNo) + ", elements " +
                                           std::to_string(h.elements));
  }
  data_.insert(data_.end(), message->data.begin(), message->data.end());
  ++fragments_;
  if (h.incomplete) {
    if (auto s = exchange_.startReceive(now); !s.ok()) {
      return fail(s.error().code, s.error().context);
    }
    return true;
  }
  if (h.idn != request_.idn) {
    return fail(ErrorCode::kMalformed, "response names " + formatIdn(h.idn));
  }
  done_ = true;
  return false;
}

}  // namespace ecsim::master
