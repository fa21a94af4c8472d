#include "master/health.hpp"

#include <algorithm>

namespace ecsim::master {
namespace {

// Where a recovery starts for a slave that answers at its station address.
SlaveRecoveryTask::Stage firstStage(const SlaveInfo& slave) {
  switch (slave.state().value_or(AlState::kInit)) {
    case AlState::kInit:
    case AlState::kBootstrap:
      return SlaveRecoveryTask::Stage::kIdentity;
    case AlState::kPreOp:
      return SlaveRecoveryTask::Stage::kDc;  // nothing there for a slave without DC set-up
    case AlState::kSafeOp:
    case AlState::kOp:
      break;
  }
  return SlaveRecoveryTask::Stage::kOp;
}

}  // namespace

std::string_view toString(SlaveCondition condition) {
  switch (condition) {
    case SlaveCondition::kOperational:
      return "operational";
    case SlaveCondition::kLost:
      return "lost";
    case SlaveCondition::kRecovering:
      return "recovering";
    case SlaveCondition::kFailed:
      return "failed";
  }
  return "?";
}

std::string_view toString(MasterEventKind kind) {
  switch (kind) {
    case MasterEventKind::kSlaveLost:
      return "lost";
    case MasterEventKind::kSlaveReturned:
      return "returned";
    case MasterEventKind::kSlaveReset:
      return "reset";
    case MasterEventKind::kSlaveError:
      return "error";
    case MasterEventKind::kSlaveRecovered:
      return "recovered";
    case MasterEventKind::kRecoveryFailed:
      return "recovery failed";
    case MasterEventKind::kRingBroken:
      return "ring broken";
    case MasterEventKind::kRingWhole:
      return "ring whole";
  }
  return "?";
}

bool MasterHealth::allOperational() const {
  return std::all_of(slaves.begin(), slaves.end(), [](const SlaveHealth& s) {
    return s.condition == SlaveCondition::kOperational;
  });
}

HealthMonitor::HealthMonitor(Transport& transport, std::vector<SlaveInfo>& slaves,
                             const ProcessImageLayout& layout, CyclicExchange& cyclic,
                             bool recovery, HealthOptions options, StateChangeOptions state,
                             std::unique_ptr<SlaveSetup> setup, MailboxOptions mailbox)
    : transport_(transport),
      slaveInfos_(slaves),
      layout_(layout),
      cyclic_(cyclic),
      recovery_(recovery),
      options_(options),
      state_(state),
      setup_(std::move(setup)),
      mailbox_(mailbox),
      slaves_(slaves.size()) {
  for (std::size_t i = 0; i < slaves.size(); ++i) {
    SlaveHealth& h = slaves_[i].health;
    h.position = slaves[i].position;
    h.station = slaves[i].station;
    h.name = slaves[i].displayName();
    h.alStatus = slaves[i].alStatus;
    h.alStatusCode = slaves[i].alStatusCode;
  }
  // The status reads and probes are made once, so that queueing them never allocates.
  for (std::size_t i = 0; i < slaves.size(); ++i) {
    reads_.add().fprd(slaves[i].station, reg::kAlStatus, reg::kAlStatusCode);
    probes_.add().read(Command::kAprd, Datagram::autoIncrement(i), reg::kConfiguredStationAddress);
  }
  readPositions_.reserve(slaves.size());
  probed_.reserve(slaves.size());
  events_.reserve(64);
  options_.statusInterval = std::max<std::uint64_t>(options_.statusInterval, 1);
  options_.lostAfter = std::max(options_.lostAfter, 1u);
}

void HealthMonitor::event(MasterEventKind kind, std::size_t position, std::uint64_t cycle,
                          SimTime now, const std::string& what) {
  slaves_[position].health.lastEventCycle = cycle;
  events_.push_back(
      {kind, cycle, now, position,
       slaveInfos_[position].label() + " " + what + " at cycle " + std::to_string(cycle)});
}

void HealthMonitor::markRecovered(std::size_t position, std::uint64_t cycle, SimTime now) {
  Watch& w = slaves_[position];
  w.health.condition = SlaveCondition::kOperational;
  ++w.health.recoveredCount;
  ++slavesRecovered_;
  w.lastFailure.clear();
  event(MasterEventKind::kSlaveRecovered, position, cycle, now, "back in OP");
}

void HealthMonitor::watchRing(std::uint64_t cycle, SimTime now) {
  const RingState ring = transport_.ring();
  if (ring == ringSeen_ || slaveInfos_.empty()) return;
  const RingState before = ringSeen_;
  ringSeen_ = ring;
  const std::string at = " at cycle " + std::to_string(cycle);
  if (ring == RingState::kBroken) {
    const std::size_t behind = transport_.slavesBehindBreak();
    if (behind >= slaveInfos_.size()) {
      events_.push_back({MasterEventKind::kRingBroken, cycle, now, 0,
                         "ring broken" + at + ": the primary port reaches no slave; the break " +
                             "lies between it and " + slaveInfos_[0].label() + ", " +
                             std::to_string(behind) + " slave(s) answer at the second port"});
      return;
    }
    const std::size_t last = slaveInfos_.size() - 1 - behind;
    events_.push_back({MasterEventKind::kRingBroken, cycle, now, last,
                       "ring broken" + at + ": frames come back at the primary port; the break " +
                           "lies behind " + slaveInfos_[last].label() + ", " +
                           std::to_string(behind) + " slave(s) answer at the second port"});
  } else if (ring == RingState::kWhole && before == RingState::kBroken) {
    events_.push_back({MasterEventKind::kRingWhole, cycle, now, slaveInfos_.size() - 1,
                       "ring whole again" + at + ": frames come round to the second port"});
  }
}

void HealthMonitor::afterCycle(const CycleResult& result, std::uint64_t cycle, SimTime now) {
  watchRing(cycle, now);
  if (!recovery_) return;
  if (!result.ok()) suspicious_ = true;
  if (readsOut_ && !reads_.pending()) {
    readsOut_ = false;
    takeStatusReads(cycle, now);
  }
  if (probesOut_ && !probes_.pending()) {
    probesOut_ = false;
    takeProbes(cycle, now);
  }
  bool changed = false;
  for (std::size_t i = 0; i < slaves_.size(); ++i) {
    Watch& w = slaves_[i];
    if (!w.recovery || w.recovery->step(now)) continue;
    if (w.recovery->status().ok()) {
      markRecovered(i, cycle, now);
    } else {
      // Tried again every retryAfter cycles; reported once per reason, not at every attempt.
      w.health.condition = SlaveCondition::kFailed;
      ++w.health.failedAttempts;
      w.retryAt = cycle + options_.retryAfter;
      const std::string& reason = w.recovery->status().error().context;
      if (reason != w.lastFailure) {
        w.lastFailure = reason;
        event(MasterEventKind::kRecoveryFailed, i, cycle, now,
              "not recovered: " + reason + "; tried again every " +
                  std::to_string(options_.retryAfter) + " cycles");
      }
    }
    w.misses = 0;
    w.recovery.reset();
    changed = true;
  }
  if (changed) updateExpectations();
  const bool anyMissing = std::any_of(slaves_.begin(), slaves_.end(), [](const Watch& w) {
    return w.health.condition == SlaveCondition::kLost ||
           w.health.condition == SlaveCondition::kFailed;
  });
  const std::uint64_t interval = anyMissing
                                     ? std::max<std::uint64_t>(options_.statusInterval / 10, 1)
                                     : options_.statusInterval;
  if (!readsOut_ && !probesOut_ && (suspicious_ || cycle - lastRead_ >= interval)) {
    suspicious_ = false;
    lastRead_ = cycle;
    queueStatusReads();
  }
}

void HealthMonitor::queueStatusReads() {
  readPositions_.clear();
  probed_.clear();
  for (std::size_t i = 0; i < slaves_.size(); ++i) {
    const Watch& w = slaves_[i];
    if (w.recovery) continue;
    reads_[readPositions_.size()].fprd(slaveInfos_[i].station, reg::kAlStatus, reg::kAlStatusCode);
    reads_.queue(readPositions_.size(), transport_);
    readPositions_.push_back(i);
    if (w.health.condition == SlaveCondition::kLost ||
        w.health.condition == SlaveCondition::kFailed) {
      probes_[probed_.size()].read(Command::kAprd, Datagram::autoIncrement(i),
                                   reg::kConfiguredStationAddress);
      probes_.queue(probed_.size(), transport_);
      probed_.push_back(i);
    }
  }
  readsOut_ = !readPositions_.empty();
  probesOut_ = !probed_.empty();
}

void HealthMonitor::takeStatusReads(std::uint64_t cycle, SimTime now) {
  bool changed = false;
  for (std::size_t k = 0; k < readPositions_.size(); ++k) {
    const std::size_t i = readPositions_[k];
    Watch& w = slaves_[i];
    SlaveInfo& info = slaveInfos_[i];
    const Datagram& d = reads_[k];
    if (w.recovery) continue;  // started meanwhile (by a probe)
    if (d.wkcOk()) {
      info.alStatus = d.get(reg::kAlStatus);
      info.alStatusCode = d.get(reg::kAlStatusCode);
      w.health.alStatus = info.alStatus;
      w.health.alStatusCode = info.alStatusCode;
      w.misses = 0;
      const bool inOp = info.state() == AlState::kOp && !info.alError();
      switch (w.health.condition) {
        case SlaveCondition::kOperational:
          if (inOp) break;
          ++w.health.errorCount;
          event(MasterEventKind::kSlaveError, i, cycle, now,
                "shows " + describeAlStatus(info.alStatus) + ", AL status code " +
                    describeAlStatusCode(info.alStatusCode));
          startRecovery(i, firstStage(info), now);
          changed = true;
          break;
        case SlaveCondition::kFailed:
          // Another attempt, without a new event: it says something when it succeeds or fails
          // for another reason.
          if (cycle < w.retryAt) break;
          if (inOp) {
            markRecovered(i, cycle, now);
          } else {
            startRecovery(i, firstStage(info), now);
          }
          changed = true;
          break;
        case SlaveCondition::kLost:
          event(MasterEventKind::kSlaveReturned, i, cycle, now,
                "answers again (" + describeAlStatus(info.alStatus) + ")");
          if (inOp) {
            markRecovered(i, cycle, now);
          } else {
            startRecovery(i, firstStage(info), now);
          }
          changed = true;
          break;
        case SlaveCondition::kRecovering:
          break;
      }
      continue;
    }
    if (w.health.condition != SlaveCondition::kOperational) continue;
    if (++w.misses < options_.lostAfter) {
      suspicious_ = true;  // read again at once
      continue;
    }
    w.health.condition = SlaveCondition::kLost;
    ++w.health.lostCount;
    ++slavesLost_;
    event(MasterEventKind::kSlaveLost, i, cycle, now, "lost");
    changed = true;
  }
  if (changed) updateExpectations();
}

void HealthMonitor::takeProbes(std::uint64_t cycle, SimTime now) {
  bool changed = false;
  for (std::size_t k = 0; k < probed_.size(); ++k) {
    const std::size_t i = probed_[k];
    Watch& w = slaves_[i];
    const Datagram& d = probes_[k];
    if (w.recovery || !d.wkcOk()) continue;
    if (w.health.condition == SlaveCondition::kOperational) continue;
    if (w.health.condition == SlaveCondition::kFailed && cycle < w.retryAt) continue;
    const std::uint16_t station = d.get(reg::kConfiguredStationAddress);
    if (station == slaveInfos_[i].station) continue;  // the status read will see it
    event(MasterEventKind::kSlaveReset, i, cycle, now,
          "answers at its position with station address " + std::to_string(station) +
              " (power cycle)");
    startRecovery(i, SlaveRecoveryTask::Stage::kAddress, now);
    changed = true;
  }
  if (changed) updateExpectations();
}

void HealthMonitor::startRecovery(std::size_t position, SlaveRecoveryTask::Stage first,
                                  SimTime now) {
  Watch& w = slaves_[position];
  w.health.condition = SlaveCondition::kRecovering;
  w.recovery = std::make_unique<SlaveRecoveryTask>(transport_, slaveInfos_[position], layout_,
                                                   state_, setup_.get(), mailbox_);
  w.recovery->start(first, now, options_.recoveryTimeout);
}

void HealthMonitor::updateExpectations() {
  // From the datagram's own expectation (planned, or an ENI's Cnt): a lost slave's share is
  // taken out, a recovering or failed slave's share may or may not be there.
  for (std::size_t i = 0; i < layout_.datagrams.size(); ++i) {
    const LogicalDatagram& d = layout_.datagrams[i];
    if (!d.checkWkc) continue;
    std::uint32_t missing = 0;
    std::uint32_t maybe = 0;
    for (std::size_t k = 0; k < d.slaves.size() && k < d.contributions.size(); ++k) {
      if (d.slaves[k] >= slaves_.size()) continue;
      switch (slaves_[d.slaves[k]].health.condition) {
        case SlaveCondition::kOperational:
          break;
        case SlaveCondition::kRecovering:
        case SlaveCondition::kFailed:
          maybe += d.contributions[k];
          break;
        case SlaveCondition::kLost:
          missing += d.contributions[k];
          break;
      }
    }
    const std::uint32_t most = d.expectedWkc > missing ? d.expectedWkc - missing : 0u;
    const std::uint32_t least = most > maybe ? most - maybe : 0u;
    cyclic_.setExpectedWkc(i, static_cast<std::uint16_t>(least), static_cast<std::uint16_t>(most));
  }
  // A reference clock that is out may come back power-cycled, its system time started over:
  // its time is not distributed until its recovery has given it back its offset.
  const auto reference = setup_ ? setup_->dcReference() : std::nullopt;
  cyclic_.holdDcDistribution(reference && *reference < slaves_.size() &&
                             slaves_[*reference].health.condition != SlaveCondition::kOperational);
}

MasterHealth HealthMonitor::health(const TransportCounters& transport) const {
  MasterHealth h;
  const CyclicStatistics& st = cyclic_.statistics();
  h.cycles = st.cycles;
  h.framesLost = transport.framesLost;
  h.framesLate = st.framesLate + transport.framesLate;
  h.wkcErrors = st.wkcErrors;
  h.cyclesWithErrors = st.cyclesWithErrors;
  h.slavesLost = slavesLost_;
  h.slavesRecovered = slavesRecovered_;
  h.ring = transport_.ring();
  h.ringBreaks = transport.ringBreaks;
  h.slaves.reserve(slaves_.size());
  for (const auto& w : slaves_) h.slaves.push_back(w.health);
  return h;
}

}  // namespace ecsim::master
