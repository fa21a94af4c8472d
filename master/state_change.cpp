#include "master/state_change.hpp"

#include "protocol/registers.hpp"

namespace ecsim::master {
std::string StateRefusal::describe() const {
  SlaveInfo who;
  who.position = position;
  who.station = station;
  who.name = name;
  std::string s = who.label() + " refused " + std::string(toString(requested)) +
                  ": AL status code " + describeAlStatusCode(alStatusCode) + ", stays " +
                  describeAlStatus(static_cast<std::uint16_t>(alStatus & ~kAlErrorFlag));
  if (acknowledged) s += " (error acknowledged)";
  return s;
}

StateChangeTask::StateChangeTask(Transport& transport, std::vector<SlaveInfo>& slaves,
                                 StateChangeOptions options)
    : transport_(transport), slaves_(slaves), options_(options) {}

void StateChangeTask::start(AlState target, SimTime now) {
  target_ = target;
  startedAt_ = now;
  status_ = okStatus();
  refusals_.clear();
  outcome_.assign(slaves_.size(), Outcome::kPending);
  wakeAt_.reset();
  acks_.clear();
  if (slaves_.empty()) {
    state_ = State::kDone;
    return;
  }
  queueReads(false);
  state_ = State::kRead;
}

void StateChangeTask::queueReads(bool onlyPending) {
  batch_.clear();
  reading_.clear();
  for (const auto& slave : slaves_) {
    if (onlyPending && outcome_[slave.position] != Outcome::kPending) continue;
    batch_.add().fprd(slave.station, reg::kAlStatus, reg::kAlStatusCode);
    reading_.push_back(slave.position);
  }
  batch_.queueAll(transport_);
}

bool StateChangeTask::takeReads(SimTime /*now*/) {
  if (auto s = batch_.check(); !s.ok()) {
    status_ = makeError(s.error().code, "AL status: " + s.error().context);
    return false;
  }
  for (std::size_t i = 0; i < reading_.size(); ++i) {
    SlaveInfo& slave = slaves_[reading_[i]];
    slave.alStatus = batch_[i].get(reg::kAlStatus);
    slave.alStatusCode = batch_[i].get(reg::kAlStatusCode);
  }
  return true;
}

bool StateChangeTask::finish() {
  state_ = State::kDone;
  wakeAt_.reset();
  if (!status_.ok()) return false;  // already says everything
  if (!refusals_.empty()) {
    std::string context;
    for (const auto& r : refusals_) context += (context.empty() ? "" : "; ") + r.describe();
    status_ = makeError(ErrorCode::kAborted, context);
  }
  return false;
}

bool StateChangeTask::step(SimTime now) {
  switch (state_) {
    case State::kIdle:
    case State::kDone:
      return false;
    case State::kRead: {
      if (batch_.pending()) return true;
      if (!takeReads(now)) return finish();
      batch_.clear();
      ackSent_.assign(slaves_.size(), false);
      for (std::size_t i = 0; i < slaves_.size(); ++i) {
        const auto& slave = slaves_[i];
        std::uint16_t value = static_cast<std::uint16_t>(target_);
        if (slave.alError() && options_.acknowledgeErrors) {
          value |= kAlErrorFlag;
          ackSent_[i] = true;
        }
        batch_.add().fpwr(slave.station, reg::kAlControl, value);
      }
      batch_.queueAll(transport_);
      state_ = State::kRequest;
      return true;
    }
    case State::kRequest: {
      if (batch_.pending()) return true;
      if (auto s = batch_.check(); !s.ok()) {
        status_ = makeError(s.error().code, "AL control " + std::string(toString(target_)) + ": " +
                                                s.error().context);
        return finish();
      }
      queueReads(false);
      state_ = State::kPoll;
      return true;
    }
    case State::kPoll: {
      if (wakeAt_) {
        if (now < *wakeAt_) return true;
        wakeAt_.reset();
        queueReads(true);
        return true;
      }
      if (batch_.pending()) return true;
      if (!takeReads(now)) return finish();
      acks_.clear();
      bool pending = false;
      for (std::size_t position : reading_) {
        SlaveInfo& slave = slaves_[position];
        // The echo of our own request: target state with the error flag, code 0, or exactly
        // the value we wrote with the acknowledge bit (a device-emulation ESC copies AL control
        // and never writes the code register, which keeps whatever it held).
        const bool echo = slave.alError() && slave.state() == target_ &&
                          (slave.alStatusCode == 0 ||
                           (position < ackSent_.size() && ackSent_[position]));
        if (echo) {
          // Device emulation (ESC datasheet section II 0x0120): the ESC copies AL control into
          // AL status as written, so an acknowledge bit sent with the request comes back as
          // the error flag (a real EL1004: soem-sdinfo-ek1100-el1004.pcapng frames 289/293).
          // The state is reached; writing it once more without the bit clears the flag.
          acks_.add().fpwr(slave.station, reg::kAlControl, static_cast<std::uint16_t>(target_));
          outcome_[position] = Outcome::kReached;
          slave.alStatus = static_cast<std::uint16_t>(slave.alStatus & ~kAlErrorFlag);
        } else if (slave.alError()) {
          StateRefusal r;
          r.position = position;
          r.station = slave.station;
          r.name = slave.displayName();
          r.requested = target_;
          r.alStatus = slave.alStatus;
          r.alStatusCode = slave.alStatusCode;
          r.acknowledged = options_.acknowledgeErrors;
          refusals_.push_back(std::move(r));
          outcome_[position] = Outcome::kRefused;
          if (options_.acknowledgeErrors) {
            acks_.add().fpwr(slave.station, reg::kAlControl,
                             static_cast<std::uint16_t>((slave.alStatus & kAlStateMask) |
                                                        kAlErrorFlag));
          }
        } else if (slave.state() == target_) {
          outcome_[position] = Outcome::kReached;
        } else {
          pending = true;
        }
      }
      if (!acks_.empty()) {
        acks_.queueAll(transport_);
        state_ = State::kAcknowledge;
        return true;
      }
      if (!pending) return finish();
      if (now - startedAt_ >= options_.timeout) {
        std::string context;
        for (const auto& slave : slaves_) {
          if (outcome_[slave.position] != Outcome::kPending) continue;
          context += (context.empty() ? "" : "; ") + slave.label() + " still " +
                     describeAlStatus(slave.alStatus) + " after " +
                     std::to_string(options_.timeout / kNsPerMs) + " ms";
        }
        // Refusals, if any, come first and make the code kAborted.
        std::string refused;
        for (const auto& r : refusals_) refused += (refused.empty() ? "" : "; ") + r.describe();
        status_ = refusals_.empty()
                      ? makeError(ErrorCode::kTimeout,
                                  "requested " + std::string(toString(target_)) + ": " + context)
                      : makeError(ErrorCode::kAborted, refused + "; " + context);
        return finish();
      }
      wakeAt_ = now + options_.pollInterval;
      return true;
    }
    case State::kAcknowledge: {
      if (acks_.pending()) return true;
      if (auto s = acks_.check(); !s.ok()) {
        status_ = makeError(s.error().code, "error acknowledge: " + s.error().context);
        return finish();
      }
      acks_.clear();
      for (auto& slave : slaves_) {
        if (outcome_[slave.position] == Outcome::kRefused) {
          slave.alStatus = static_cast<std::uint16_t>(slave.alStatus & ~kAlErrorFlag);
        }
      }
      bool pending = false;
      for (auto o : outcome_) pending = pending || o == Outcome::kPending;
      if (!pending) return finish();
      wakeAt_.reset();
      queueReads(true);
      state_ = State::kPoll;
      return true;
    }
  }
  return false;
}

}  // namespace ecsim::master
