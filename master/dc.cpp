#include "master/dc.hpp"

#include <algorithm>
#include <cstdlib>

#include "master/master.hpp"
#include "protocol/registers.hpp"

namespace ecsim::master {
namespace {

// ESI AssignActivate: one word over 0x0980 (cyclic unit control) and 0x0981 (activation).
constexpr std::uint16_t kAssignActivateLength =
    reg::spanWidth(reg::kCyclicUnitControl, reg::kDcActivation);
constexpr std::array<unsigned, 4> kPortOrder{0, 3, 1, 2};

bool portOpen(const SlaveInfo& s, unsigned port) {
  return (s.activePorts >> port & 1u) != 0;
}

}  // namespace

std::vector<SimTime> computeDcDelays(const std::vector<SlaveInfo>& slaves,
                                     const std::vector<PortTimes>& times) {
  const std::size_t n = std::min(slaves.size(), times.size());
  std::vector<SimTime> delay(n, 0);
  auto diff = [](std::uint32_t later, std::uint32_t earlier) {
    return static_cast<SimTime>(static_cast<std::uint32_t>(later - earlier));  // wraps at 2^32
  };
  auto loop = [&](std::size_t i) -> SimTime {
    unsigned last = 0;
    for (unsigned p : kPortOrder) {
      if (p != 0 && portOpen(slaves[i], p)) last = p;
    }
    return last == 0 ? 0 : diff(times[i][last], times[i][0]);
  };
  std::vector<std::size_t> childrenSeen(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const int parent = slaves[i].parent;
    if (parent < 0 || static_cast<std::size_t>(parent) >= n) continue;
    const auto p = static_cast<std::size_t>(parent);
    // The parent's open ports other than 0, in processing order; this child takes the next.
    std::size_t k = childrenSeen[p]++;
    unsigned previous = 0;
    unsigned port = 0;
    for (unsigned candidate : {3u, 1u, 2u}) {
      if (!portOpen(slaves[p], candidate)) continue;
      if (k == 0) {
        port = candidate;
        break;
      }
      previous = candidate;
      --k;
    }
    if (port == 0) continue;  // more children than open ports: the scan saw another wiring
    const SimTime before = diff(times[p][previous], times[p][0]);
    const SimTime below = diff(times[p][port], times[p][previous]);
    delay[i] = delay[p] + before + (below - loop(i)) / 2;
  }
  return delay;
}

std::optional<DcRecovery> dcRecoveryFor(const DcSetup& setup, const std::vector<SlaveInfo>& slaves,
                                        std::size_t position, SimTime sync0Margin) {
  if (!setup.reference || *setup.reference >= slaves.size() || position >= setup.dc.size() ||
      !setup.dc[position] || position >= setup.delays.size()) {
    return std::nullopt;
  }
  std::size_t source = *setup.reference;
  if (position == source) {
    // The reference clock itself: the time is in the others' clocks.
    std::optional<std::size_t> other;
    for (std::size_t i = 0; i < setup.dc.size() && i < slaves.size() && i < setup.delays.size();
         ++i) {
      if (setup.dc[i] && i != position) {
        other = i;
        break;
      }
    }
    if (!other) return std::nullopt;
    source = *other;
  }
  DcRecovery r;
  r.sourceStation = slaves[source].station;
  r.sourceDelay = setup.delays[source];
  r.delay = setup.delays[position];
  r.sync0Margin = sync0Margin;
  if (std::find(setup.sync0.begin(), setup.sync0.end(), position) != setup.sync0.end() &&
      position < setup.assignActivate.size() && setup.sync0Cycle > 0) {
    r.sync0 = true;
    r.assignActivate = setup.assignActivate[position];
    r.sync0Start = setup.sync0Start;
    r.sync0Cycle = setup.sync0Cycle;
  }
  return r;
}

std::uint64_t recoveredDcOffset(std::uint64_t sourceLocal, std::uint64_t sourceOffset,
                                std::uint64_t slaveLocal, SimTime delay) {
  return sourceLocal + sourceOffset + static_cast<std::uint64_t>(delay) - slaveLocal;
}

std::uint64_t nextSync0Time(std::uint64_t gridStart, SimTime cycle, std::uint64_t earliest) {
  if (cycle <= 0 || static_cast<std::int64_t>(earliest - gridStart) <= 0) return gridStart;
  const auto c = static_cast<std::uint64_t>(cycle);
  const std::uint64_t since = earliest - gridStart;
  return gridStart + (since + c - 1) / c * c;
}

DcInitTask::DcInitTask(Transport& transport, std::vector<SlaveInfo>& slaves, DcOptions options,
                       SimTime cycleTime, std::vector<std::uint16_t> assignActivate)
    : transport_(transport),
      slaves_(slaves),
      options_(options),
      cycleTime_(options.sync0Cycle > 0 ? options.sync0Cycle : cycleTime),
      assignActivate_(std::move(assignActivate)) {}

bool DcInitTask::fail(Error error) {
  status_ = makeError(error.code, "DC set-up: " + error.context);
  phase_ = Phase::kDone;
  return false;
}

void DcInitTask::start(SimTime now) {
  status_ = okStatus();
  setup_ = {};
  driftSent_ = 0;
  driftLostInRow_ = 0;
  setup_.dc.assign(slaves_.size(), false);
  setup_.assignActivate.assign(slaves_.size(), 0);
  for (const auto& s : slaves_) {
    setup_.dc[s.position] = s.hasDc();
    if (s.hasDc() && !setup_.reference) setup_.reference = s.position;
  }
  if (!setup_.reference) {
    status_ = makeError(ErrorCode::kNotFound, "DC set-up: no slave has distributed clocks");
    phase_ = Phase::kDone;
    return;
  }
  enter(Phase::kLatch, now);
}

void DcInitTask::enter(Phase phase, SimTime now) {
  phase_ = phase;
  batch_.clear();
  const std::uint16_t reference = slaves_[*setup_.reference].station;
  switch (phase) {
    case Phase::kLatch:
      masterTime_ = options_.masterTime.value_or(static_cast<std::uint64_t>(now));
      // Every slave counts (DC or not); the count is not checked.
      batch_.add().write(Command::kBwr, 0, reg::kReceiveTimePort0, 0, 0);
      break;
    case Phase::kRead:
      for (const auto& s : slaves_) {
        if (!setup_.dc[s.position]) continue;
        batch_.add().fprd(s.station, reg::kReceiveTimePort0, reg::kReceiveTimePort3);
        batch_.add().fprd(s.station, reg::kReceiveTimeEcatProcessingUnit);
      }
      break;
    case Phase::kWrite:
      for (const auto& s : slaves_) {
        if (!setup_.dc[s.position]) continue;
        batch_.add().fpwr(s.station, reg::kSystemTimeOffset, setup_.offsets[s.position]);
        batch_.add().fpwr(s.station, reg::kSystemTimeDelay,
                          static_cast<std::uint32_t>(setup_.delays[s.position]));
      }
      // Restart the drift filters (speed counter start 0x1000, datasheet section II).
      batch_.add().write(Command::kBwr, 0, reg::kSpeedCounterStart, 0x1000, 0);
      break;
    case Phase::kDrift:
      batch_.add().read(Command::kFrmw, reference, reg::kSystemTime, 0);
      ++driftSent_;
      break;
    case Phase::kSync0Time:
      batch_.add().fprd(reference, reg::kSystemTime);
      break;
    case Phase::kSync0:
      for (std::size_t position : setup_.sync0) {
        const std::uint16_t station = slaves_[position].station;
        batch_.add().fpwr(station, reg::kDcActivation, 0);
        batch_.add().fpwr(station, reg::kSync0CycleTime,
                          static_cast<std::uint32_t>(setup_.sync0Cycle));
        batch_.add().fpwr(station, reg::kStartTimeCyclicOperation, setup_.sync0Start);
        batch_.add().fpwr(station, reg::kCyclicUnitControl.address,
                          leBytes(assignActivate_[position], kAssignActivateLength));
      }
      break;
    case Phase::kDone:
      return;
  }
  if (!batch_.empty()) batch_.queueAll(transport_);
}

bool DcInitTask::step(SimTime now) {
  if (phase_ == Phase::kDone) return false;
  if (batch_.pending()) return true;
  // BWR/FRMW counts vary with the network; only their arrival matters.
  if (phase_ == Phase::kDrift && !batch_[0].received()) {
    ++setup_.driftFramesLost;
    if (++driftLostInRow_ >= options_.maxDriftFramesLostInRow) {
      return fail(makeError(ErrorCode::kTimeout,
                            batch_[0].describe() + ": " + std::to_string(driftLostInRow_) +
                                " static drift frames lost in a row (" +
                                std::to_string(setup_.driftFramesLost) + " of " +
                                std::to_string(driftSent_) + " sent)"));
    }
  } else if (phase_ == Phase::kDrift) {
    driftLostInRow_ = 0;
  } else if (phase_ == Phase::kLatch) {
    if (!batch_[0].received()) return fail(makeError(ErrorCode::kTimeout, batch_[0].describe()));
  } else if (phase_ == Phase::kWrite) {
    for (std::size_t i = 0; i + 1 < batch_.size(); ++i) {
      if (auto s = batch_[i].check(); !s.ok()) return fail(s.takeError());
    }
  } else if (auto s = batch_.check(); !s.ok()) {
    return fail(s.takeError());
  }
  switch (phase_) {
    case Phase::kLatch:
      enter(Phase::kRead, now);
      return true;
    case Phase::kRead: {
      std::vector<PortTimes> times(slaves_.size(), PortTimes{});
      std::vector<std::uint64_t> epu(slaves_.size(), 0);
      std::size_t d = 0;
      for (const auto& s : slaves_) {
        if (!setup_.dc[s.position]) continue;
        for (unsigned p = 0; p < 4; ++p) {
          times[s.position][p] = batch_[d].get(reg::kReceiveTimePorts[p]);
        }
        epu[s.position] = batch_[d + 1].get(reg::kReceiveTimeEcatProcessingUnit);
        d += 2;
      }
      const std::vector<SimTime> absolute = computeDcDelays(slaves_, times);
      const SimTime base = absolute[*setup_.reference];
      setup_.delays.assign(slaves_.size(), 0);
      setup_.offsets.assign(slaves_.size(), 0);
      for (std::size_t i = 0; i < slaves_.size(); ++i) {
        setup_.delays[i] = std::max<SimTime>(0, absolute[i] - base);
        setup_.offsets[i] = masterTime_ - epu[i];  // modulo 2^64, as the ESC adds it
      }
      enter(Phase::kWrite, now);
      return true;
    }
    case Phase::kWrite:
    case Phase::kDrift:
      if (driftSent_ < options_.staticDriftFrames) {
        enter(Phase::kDrift, now);
        return true;
      }
      for (std::size_t i = 0; i < slaves_.size() && i < assignActivate_.size(); ++i) {
        if (options_.activateSync0 && setup_.dc[i] && assignActivate_[i] != 0) {
          setup_.sync0.push_back(i);
          setup_.assignActivate[i] = assignActivate_[i];
        }
      }
      if (setup_.sync0.empty() || cycleTime_ <= 0) {
        phase_ = Phase::kDone;
        return false;
      }
      enter(Phase::kSync0Time, now);
      return true;
    case Phase::kSync0Time: {
      const std::uint64_t t = batch_[0].get(reg::kSystemTime);
      const auto cycle = static_cast<std::uint64_t>(cycleTime_);
      const std::uint64_t ahead = t + static_cast<std::uint64_t>(options_.sync0StartDelay);
      setup_.sync0Cycle = cycleTime_;
      setup_.sync0Start =
          (ahead / cycle + 1) * cycle + static_cast<std::uint64_t>(options_.sync0Shift);
      enter(Phase::kSync0, now);
      return true;
    }
    case Phase::kSync0:
    case Phase::kDone:
      phase_ = Phase::kDone;
      return false;
  }
  return false;
}

void addDcSyncErrorReads(DatagramBatch& batch, const std::vector<SlaveInfo>& slaves,
                         const DcSetup& setup) {
  for (const auto& s : slaves) {
    if (s.position >= setup.dc.size() || !setup.dc[s.position]) continue;
    if (setup.reference && s.position == *setup.reference) continue;
    batch.add().fprd(s.station, reg::kSystemTimeDifference);
  }
}

Result<SimTime> dcSyncErrorFrom(const DatagramBatch& batch) {
  ECSIM_TRY(batch.check());
  SimTime worst = 0;
  for (std::size_t i = 0; i < batch.size(); ++i) {
    const std::uint32_t raw = batch[i].get(reg::kSystemTimeDifference);
    worst = std::max<SimTime>(worst, static_cast<SimTime>(raw & 0x7FFFFFFFu));  // sign-magnitude
  }
  return worst;
}

// ---- the Master's use of it --------------------------------------------------------------------

Status Master::initDc() {
  std::vector<std::uint16_t> assign(slaves_.size(), 0);
  const EniConfig* eni = config_ && config_->eni ? &*config_->eni : nullptr;
  for (const auto& s : slaves_) {
    if (eni != nullptr) {
      if (s.position < eni->slaves.size() && eni->slaves[s.position].dcCapable) {
        assign[s.position] = 0x0300;
      }
      continue;
    }
    for (const auto& mode : s.siiContents.dcOpModes) {
      if ((mode.assignActivate & 0x0200) != 0) assign[s.position] = mode.assignActivate;
    }
  }
  DcInitTask task(transport_, slaves_, options_.dc, options_.cycleTime, std::move(assign));
  task.start(bus_.now());
  const SimTime timeout = options_.scanTimeout;
  ECSIM_TRY(run(task, timeout, "DC set-up"));
  ECSIM_TRY(task.status());
  dc_ = task.result();
  cyclic_.setDcReference(slaves_[*dc_.reference].station);
  if (cyclic_.built() && cyclic_.frameCount() > 0) {
    ECSIM_TRY(cyclic_.build(layout_, options_.transport.source));
  }
  return okStatus();
}

Result<SimTime> Master::dcSyncError() {
  if (!dc_.reference) return makeError(ErrorCode::kState, "distributed clocks are not set up");
  DatagramBatch batch;
  addDcSyncErrorReads(batch, slaves_, dc_);
  if (batch.empty()) return SimTime{0};
  batch.queueAll(transport_);
  BatchWait wait(batch);
  ECSIM_TRY(run(wait, options_.state.timeout, "DC time differences"));
  return dcSyncErrorFrom(batch);
}

}  // namespace ecsim::master
