#include "master/foe_client.hpp"

#include <algorithm>

namespace ecsim::master {

FoeTask::FoeTask(Transport& transport, SlaveInfo& slave,
                 std::vector<ReceivedEmergency>* emergencies, MailboxOptions options)
    : exchange_(transport, slave, emergencies, options), slave_(slave) {}

bool FoeTask::fail(ErrorCode code, const std::string& what) {
  status_ = makeError(code, std::string(write_ ? "FoE write of '" : "FoE read of '") + name_ +
                                (write_ ? "' to " : "' from ") + slave_.label() + ": " + what);
  state_ = State::kDone;
  return false;
}

Status FoeTask::startWrite(const std::string& name, std::uint32_t password, ConstBytes data,
                           SimTime now) {
  write_ = true;
  name_ = name;
  data_.assign(data.begin(), data.end());
  offset_ = 0;
  inFlight_ = 0;
  packet_ = 0;
  busy_ = 0;
  busyInARow_ = 0;
  errorCode_.reset();
  status_ = okStatus();
  if (!slave_.mailbox) return makeError(ErrorCode::kUnsupported, slave_.label() + " has no mailbox");
  if (name.empty()) return makeError(ErrorCode::kInvalidArgument, "FoE write without a file name");
  if (foeDataPerPacket(slave_.mailbox->outSize) == 0) {
    return makeError(ErrorCode::kUnsupported, slave_.label() + "'s mailbox is too small for FoE");
  }
  message_ = encodeFoeMailbox(FoeOpcode::kWrite, password, std::string_view(name));
  ECSIM_TRY(exchange_.start(message_, now));
  state_ = State::kWriteRequest;
  return okStatus();
}

Status FoeTask::startRead(const std::string& name, std::uint32_t password, SimTime now) {
  write_ = false;
  name_ = name;
  data_.clear();
  packet_ = 0;
  busy_ = 0;
  busyInARow_ = 0;
  errorCode_.reset();
  status_ = okStatus();
  if (!slave_.mailbox) return makeError(ErrorCode::kUnsupported, slave_.label() + " has no mailbox");
  if (name.empty()) return makeError(ErrorCode::kInvalidArgument, "FoE read without a file name");
  message_ = encodeFoeMailbox(FoeOpcode::kRead, password, std::string_view(name));
  ECSIM_TRY(exchange_.start(message_, now));
  state_ = State::kRead;
  return okStatus();
}

bool FoeTask::sendPacket(SimTime now) {
  const std::size_t per = foeDataPerPacket(slave_.mailbox->outSize);
  inFlight_ = std::min(per, data_.size() - offset_);
  message_ = encodeFoeMailbox(FoeOpcode::kData, packet_ + 1,
                              ConstBytes(data_).subspan(offset_, inFlight_));
  if (auto s = exchange_.start(message_, now); !s.ok()) return fail(s.error().code, s.error().context);
  state_ = State::kWriteData;
  return true;
}

bool FoeTask::onAnswer(const FoePacket& p, SimTime now) {
  if (p.opcode == FoeOpcode::kError) {
    errorCode_ = p.value;
    std::string text(p.text());
    text.erase(std::find(text.begin(), text.end(), '\0'), text.end());
    return fail(ErrorCode::kAborted, "slave answered ERR " + describeFoeError(p.value) +
                                         (text.empty() ? "" : ": " + text));
  }
  switch (state_) {
    case State::kWriteRequest:
      if (p.opcode != FoeOpcode::kAck || p.value != 0) {
        return fail(ErrorCode::kMalformed, std::string("answer ") + std::string(toString(p.opcode)) +
                                               " " + std::to_string(p.value) + " to WRQ");
      }
      return sendPacket(now);
    case State::kWriteData: {
      if (p.opcode == FoeOpcode::kBusy) {
        ++busy_;
        if (++busyInARow_ > kMaxBusyInARow) {
          return fail(ErrorCode::kTimeout, "still BUSY after " + std::to_string(kMaxBusyInARow) +
                                               " answers");
        }
        if (auto s = exchange_.start(message_, now); !s.ok()) {
          return fail(s.error().code, s.error().context);
        }
        return true;
      }
      busyInARow_ = 0;
      if (p.opcode != FoeOpcode::kAck || p.value != packet_ + 1) {
        return fail(ErrorCode::kMalformed, std::string("answer ") + std::string(toString(p.opcode)) +
                                               " " + std::to_string(p.value) + " to DATA " +
                                               std::to_string(packet_ + 1));
      }
      ++packet_;
      offset_ += inFlight_;
      if (inFlight_ < foeDataPerPacket(slave_.mailbox->outSize)) {
        state_ = State::kDone;
        return false;
      }
      return sendPacket(now);
    }
    case State::kRead: {
      if (p.opcode != FoeOpcode::kData || p.value != packet_ + 1) {
        return fail(ErrorCode::kMalformed, std::string("answer ") + std::string(toString(p.opcode)) +
                                               " " + std::to_string(p.value) + " where DATA " +
                                               std::to_string(packet_ + 1) + " was due");
      }
      ++packet_;
      data_.insert(data_.end(), p.data.begin(), p.data.end());
      message_ = encodeFoeMailbox(FoeOpcode::kAck, packet_);
      const bool last = p.data.size() < foeDataPerPacket(slave_.mailbox->inSize);
      auto s = last ? exchange_.send(message_, now) : exchange_.start(message_, now);
      if (!s.ok()) return fail(s.error().code, s.error().context);
      if (last) state_ = State::kFinalAck;
      return true;
    }
    case State::kIdle:
    case State::kFinalAck:
    case State::kDone:
      break;
  }
  return false;
}

bool FoeTask::step(SimTime now) {
  if (state_ == State::kIdle || state_ == State::kDone) return false;
  if (exchange_.step(now)) return true;
  if (!exchange_.status().ok()) {
    return fail(exchange_.status().error().code, exchange_.status().error().context);
  }
  if (state_ == State::kFinalAck) {
    state_ = State::kDone;
    return false;
  }
  auto mbx = decodeMailbox(exchange_.response());
  if (!mbx.ok()) return fail(mbx.error().code, mbx.error().context);
  if (mbx->header.type != MailboxType::kFoe) {
    return fail(ErrorCode::kMalformed, std::string("answer of mailbox type ") +
                                           std::string(toString(mbx->header.type)));
  }
  auto p = decodeFoe(mbx->payload);
  if (!p.ok()) return fail(p.error().code, p.error().context);
  return onAnswer(*p, now);
}

}  // namespace ecsim::master
