#include "master/mailbox_exchange.hpp"

#include <algorithm>
#include <array>

#include "protocol/registers.hpp"

namespace ecsim::master {
namespace {

constexpr std::uint16_t kSm0Status = reg::smChannel(0) + reg::sm::kStatus.address;
constexpr std::uint16_t kSm1Status = reg::smChannel(1) + reg::sm::kStatus.address;
constexpr std::uint16_t kSm1Activate = reg::smChannel(1) + reg::sm::kActivate.address;
constexpr std::uint16_t kSm1PdiControl = reg::smChannel(1) + reg::sm::kPdiControl.address;
constexpr std::size_t kCounterByte = 5;  // mailbox header: type in bits 0-3, counter in 4-6
constexpr std::uint8_t kCounterMask = 0x70;

}  // namespace

MailboxExchange::MailboxExchange(Transport& transport, SlaveInfo& slave,
                                 std::vector<ReceivedEmergency>* emergencies,
                                 MailboxOptions options)
    : transport_(transport), slave_(slave), emergencies_(emergencies), options_(options) {}

Status MailboxExchange::start(ConstBytes message, SimTime now) {
  if (!slave_.mailbox) {
    return makeError(ErrorCode::kUnsupported, slave_.label() + " has no mailbox");
  }
  if (message.size() < kMailboxHeaderSize || message.size() > slave_.mailbox->outSize) {
    return makeError(ErrorCode::kInvalidArgument,
                     "mailbox message of " + std::to_string(message.size()) +
                         " bytes does not fit the " + std::to_string(slave_.mailbox->outSize) +
                         "-byte mailbox of " + slave_.label());
  }
  sendOnly_ = false;
  request_.assign(slave_.mailbox->outSize, 0);
  std::copy(message.begin(), message.end(), request_.begin());
  slave_.mailboxCounter = nextMailboxCounter(slave_.mailboxCounter);
  request_[kCounterByte] = static_cast<std::uint8_t>((request_[kCounterByte] & ~kCounterMask) |
                                                     (slave_.mailboxCounter << 4));
  status_ = okStatus();
  response_.clear();
  repeatsLeft_ = options_.repeatRequests;
  phaseStart_ = now;
  wakeAt_.reset();
  queueCheck();
  state_ = State::kCheck;
  return okStatus();
}

Status MailboxExchange::send(ConstBytes message, SimTime now) {
  ECSIM_TRY(start(message, now));
  sendOnly_ = true;
  return okStatus();
}

Status MailboxExchange::startReceive(SimTime now) {
  if (!slave_.mailbox) {
    return makeError(ErrorCode::kUnsupported, slave_.label() + " has no mailbox");
  }
  sendOnly_ = false;
  status_ = okStatus();
  response_.clear();
  repeatsLeft_ = options_.repeatRequests;
  phaseStart_ = now;
  wakeAt_.reset();
  queuePoll();
  state_ = State::kPoll;
  return okStatus();
}

bool MailboxExchange::fail(ErrorCode code, const std::string& what) {
  status_ = makeError(code, "mailbox of " + slave_.label() + ": " + what);
  state_ = State::kDone;
  wakeAt_.reset();
  return false;
}

bool MailboxExchange::datagramFailed(const Datagram& d, std::string_view what) {
  auto s = d.check();
  return fail(s.ok() ? ErrorCode::kIo : s.error().code,
              std::string(what) + ": " + (s.ok() ? std::string("failed") : s.error().context));
}

void MailboxExchange::queueCheck() {
  first_.fprd(slave_.station, kSm0Status, 1);
  second_.fprd(slave_.station, kSm1Status, 1);
  transport_.queue(first_);
  transport_.queue(second_);
}

void MailboxExchange::queuePoll() {
  first_.fprd(slave_.station, kSm1Status, 1);
  transport_.queue(first_);
}

void MailboxExchange::queueRead() {
  second_.fprd(slave_.station, slave_.mailbox->inStart, slave_.mailbox->inSize);
  transport_.queue(second_);
}

bool MailboxExchange::wait(SimTime now, SimTime until) {
  wakeAt_ = std::max(until, now + 1);
  return true;
}

bool MailboxExchange::startRepeat(SimTime now) {
  if (repeatsLeft_ == 0) {
    return fail(ErrorCode::kTimeout, "response lost and not repeated after " +
                                         std::to_string(options_.repeatRequests) +
                                         " repeat requests");
  }
  --repeatsLeft_;
  ++repeats_;
  phaseStart_ = now;
  first_.fprd(slave_.station, kSm1Activate, 2);  // activate and PDI control
  transport_.queue(first_);
  state_ = State::kRepeatRead;
  return true;
}

bool MailboxExchange::takeMessage(SimTime now) {
  ConstBytes buffer = second_.data();
  auto header = MailboxHeader::decode(buffer);
  if (!header.ok() || kMailboxHeaderSize + header->length > buffer.size()) {
    return fail(ErrorCode::kMalformed, "response header: length runs past the mailbox");
  }
  if (header->type == MailboxType::kCoe) {
    auto coe = decodeCoeMailbox(buffer);
    if (coe.ok() && coe->coe.service == CoeService::kEmergency) {
      if (auto e = Emergency::decode(coe->body); e.ok() && emergencies_ != nullptr) {
        emergencies_->push_back({slave_.position, slave_.station, *e, now});
      }
      return false;
    }
  }
  if (state_ == State::kFlush) return false;  // a stale answer nobody waits for
  if (header->type == MailboxType::kError) {
    auto reply = MailboxErrorReply::decode(buffer.subspan(
        kMailboxHeaderSize, std::min<std::size_t>(header->length, buffer.size() - 6)));
    const std::uint16_t detail = reply.ok() ? reply->detail : 0;
    fail(ErrorCode::kAborted, "mailbox error " + std::to_string(detail) + " (" +
                                  std::string(mailboxErrorText(detail)) + ")");
    return true;
  }
  response_.assign(buffer.begin(), buffer.end());
  state_ = State::kDone;
  wakeAt_.reset();
  return true;
}

bool MailboxExchange::step(SimTime now) {
  if (wakeAt_) {
    if (now < *wakeAt_) return true;
    wakeAt_.reset();
    switch (state_) {
      case State::kCheck:
        queueCheck();
        break;
      case State::kPoll:
        queuePoll();
        break;
      case State::kRepeatWait:
        first_.fprd(slave_.station, kSm1PdiControl, 1);
        transport_.queue(first_);
        break;
      default:
        break;
    }
    return true;
  }
  switch (state_) {
    case State::kIdle:
    case State::kDone:
      return false;
    case State::kCheck: {
      if (first_.pending() || second_.pending()) return true;
      if (!first_.wkcOk()) return datagramFailed(first_, "SM0 status");
      if (!second_.wkcOk()) return datagramFailed(second_, "SM1 status");
      if ((second_.data()[0] & reg::sm::kStatusMailboxFull) != 0) {
        queueRead();
        state_ = State::kFlush;
        return true;
      }
      if ((first_.data()[0] & reg::sm::kStatusMailboxFull) != 0) {
        if (now - phaseStart_ > options_.sendTimeout) {
          return fail(
              ErrorCode::kTimeout,
              "SM0 still full after " + std::to_string(options_.sendTimeout / kNsPerMs) + " ms");
        }
        return wait(now, now + options_.pollInterval);
      }
      first_.fpwr(slave_.station, slave_.mailbox->outStart, request_);
      transport_.queue(first_);
      state_ = State::kWrite;
      return true;
    }
    case State::kFlush: {
      if (second_.pending()) return true;
      if (second_.wkcOk()) (void)takeMessage(now);
      queueCheck();
      state_ = State::kCheck;
      return true;
    }
    case State::kWrite: {
      if (first_.pending()) return true;
      if (!first_.received()) return datagramFailed(first_, "request write");
      if (first_.wkc() == 0) {  // SM0 taken meanwhile: wait for it again
        if (now - phaseStart_ > options_.sendTimeout) {
          return fail(ErrorCode::kTimeout,
                      "request not accepted (SM0 full, or the mailbox is "
                      "not configured: is the slave in PREOP?)");
        }
        state_ = State::kCheck;
        return wait(now, now + options_.pollInterval);
      }
      if (sendOnly_) {
        state_ = State::kDone;
        return false;
      }
      phaseStart_ = now;
      queuePoll();
      state_ = State::kPoll;
      return true;
    }
    case State::kPoll: {
      if (first_.pending()) return true;
      if (!first_.wkcOk()) return datagramFailed(first_, "SM1 status");
      if ((first_.data()[0] & reg::sm::kStatusMailboxFull) != 0) {
        queueRead();
        state_ = State::kRead;
        return true;
      }
      if (now - phaseStart_ > options_.responseTimeout) {
        return fail(
            ErrorCode::kTimeout,
            "no response after " + std::to_string(options_.responseTimeout / kNsPerMs) + " ms");
      }
      return wait(now, now + options_.pollInterval);
    }
    case State::kRead: {
      if (second_.pending()) return true;
      if (!second_.wkcOk()) return startRepeat(now);  // read lost or came back empty
      if (takeMessage(now)) return false;
      queuePoll();  // an emergency: the response is still to come
      state_ = State::kPoll;
      return true;
    }
    case State::kRepeatRead: {
      if (first_.pending()) return true;
      if (!first_.wkcOk()) return datagramFailed(first_, "repeat request");
      const std::uint8_t activate = first_.data()[0];
      repeatBit_ = static_cast<std::uint8_t>((activate ^ reg::sm::kActivateRepeatRequest) &
                                             reg::sm::kActivateRepeatRequest);
      const std::array<std::uint8_t, 1> toggled{
          static_cast<std::uint8_t>(activate ^ reg::sm::kActivateRepeatRequest)};
      first_.fpwr(slave_.station, kSm1Activate, toggled);
      transport_.queue(first_);
      state_ = State::kRepeatWrite;
      return true;
    }
    case State::kRepeatWrite: {
      if (first_.pending()) return true;
      if (!first_.wkcOk()) return datagramFailed(first_, "repeat request");
      first_.fprd(slave_.station, kSm1PdiControl, 1);
      transport_.queue(first_);
      state_ = State::kRepeatWait;
      return true;
    }
    case State::kRepeatWait: {
      if (first_.pending()) return true;
      if (!first_.wkcOk()) return datagramFailed(first_, "repeat acknowledge");
      const bool ack = (first_.data()[0] & reg::sm::kPdiRepeatAck) != 0;
      if (ack == (repeatBit_ != 0)) {
        phaseStart_ = now;
        queuePoll();
        state_ = State::kPoll;
        return true;
      }
      if (now - phaseStart_ > options_.responseTimeout) {
        return fail(ErrorCode::kTimeout, "repeat request not acknowledged");
      }
      return wait(now, now + options_.pollInterval);
    }
  }
  return false;
}

}  // namespace ecsim::master
