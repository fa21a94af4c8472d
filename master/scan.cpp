#include "master/scan.hpp"

#include <algorithm>
#include <array>
#include <cstdio>

#include "protocol/registers.hpp"

namespace ecsim::master {
namespace {

// Register reads of the scan, in the order queued per slave.
constexpr std::size_t kReadsPerSlave = 6;

// SII General category defaults for the mailbox control bytes (SOEM's values, §3.2).
constexpr std::uint8_t kMailboxOutControl = 0x26;
constexpr std::uint8_t kMailboxInControl = 0x22;

// DL status: port n is in use when its loop is open and it has communication.
bool portActive(std::uint16_t dlStatus, unsigned port) {
  return (dlStatus & reg::dl_status::loopPort(port)) == 0 &&
         (dlStatus & reg::dl_status::communication(port)) != 0;
}

}  // namespace

void computeTopology(std::vector<SlaveInfo>& slaves) {
  struct Open {
    std::size_t position;
    int remaining;  // active ports not yet followed
  };
  std::vector<Open> stack;
  for (auto& slave : slaves) {
    slave.activePorts = 0;
    for (unsigned p = 0; p < 4; ++p) {
      if (portActive(slave.dlStatus, p)) slave.activePorts |= static_cast<std::uint8_t>(1u << p);
    }
    int active = 0;
    for (unsigned p = 0; p < 4; ++p) active += (slave.activePorts >> p) & 1;
    while (!stack.empty() && stack.back().remaining <= 0) stack.pop_back();
    if (stack.empty()) {
      slave.parent = -1;
    } else {
      slave.parent = static_cast<int>(stack.back().position);
      --stack.back().remaining;
    }
    // The port towards the parent (or master) is one of the active ones.
    stack.push_back({slave.position, std::max(0, active - 1)});
  }
}

void applySii(SlaveInfo& slave) {
  auto image = SiiImage::parseLenient(slave.sii);
  if (!image.ok()) {
    slave.siiDamage = image.error();
    slave.siiContents = {};
  } else {
    slave.siiContents = image->contents();
    slave.siiDamage = image->damage();
  }
  const SiiContents& c = slave.siiContents;
  std::string_view name;
  if (c.general && c.general->nameIndex != 0) name = c.string(c.general->nameIndex);
  if (name.empty()) name = c.string(1);  // SOEM's choice: string 1
  if (name.empty()) {
    char buf[48];
    std::snprintf(buf, sizeof buf, "? M:%08X I:%08X", c.identity.vendorId, c.identity.productCode);
    slave.name = buf;
  } else {
    slave.name = std::string(name);
  }
  slave.mailbox.reset();
  const SiiMailbox& m = c.standardMailbox;
  if (m.receiveSize > 0) {
    MailboxConfig mbx;
    mbx.outStart = m.receiveOffset;
    mbx.outSize = m.receiveSize;
    mbx.inStart = m.sendOffset;
    mbx.inSize = m.sendSize != 0 ? m.sendSize : m.receiveSize;
    mbx.outControl = kMailboxOutControl;
    mbx.inControl = kMailboxInControl;
    // The SM category has the control bytes the device wants (SOEM programs SM0/SM1 from it).
    for (const auto& sm : c.syncManagers) {
      if (sm.type == SiiSyncManagerType::kMailboxOut && sm.control != 0) {
        mbx.outControl = sm.control;
      }
      if (sm.type == SiiSyncManagerType::kMailboxIn && sm.control != 0) {
        mbx.inControl = sm.control;
      }
    }
    mbx.protocols = c.mailboxProtocols;
    slave.mailbox = mbx;
  }
}

ScanTask::ScanTask(Transport& transport, std::vector<SlaveInfo>& slaves, ScanOptions options)
    : transport_(transport), slaves_(slaves), options_(options) {}

void ScanTask::start(SimTime /*now*/) {
  slaves_.clear();
  readers_.clear();
  awaiting_.clear();
  timers_ = {};
  batch_.clear();
  status_ = okStatus();
  advice_.reset();
  count_.read(Command::kBrd, 0, reg::kType, reg::kRevision, 0);
  transport_.queue(count_);
  state_ = State::kCount;
}

bool ScanTask::fail(Status status) {
  status_ = std::move(status);
  state_ = State::kFailed;
  return false;
}

std::optional<SimTime> ScanTask::wakeAt() const {
  if (state_ != State::kSii || timers_.empty()) return std::nullopt;
  return timers_.top().first;
}

void ScanTask::adviseTimeout() {
  TimeoutAdvice advice;
  advice.slaves = slaves_.size();
  advice.roundTrip = count_.receivedAt() - count_.sentAt();
  // ESCs pass a frame on as its bits arrive: a full-size frame takes as long as the count
  // frame through the slaves and then its extra length on the wire (docs/timing.md).
  const SimTime extra = static_cast<SimTime>(kMaxFrameSize - kMinFrameSize) * kNsPerByte100Mbit;
  advice.needed =
      static_cast<SimTime>(options_.timeoutMargin * static_cast<double>(advice.roundTrip + extra));
  advice.before = transport_.options().timeout;
  if (options_.adaptTimeout && advice.needed > advice.before) {
    transport_.setTimeout(advice.needed);
    advice.raised = true;
  }
  const SimTime fullFrame = static_cast<SimTime>(kMaxFrameSize) * kNsPerByte100Mbit;
  advice.framesFitting = static_cast<std::size_t>((advice.roundTrip + fullFrame - 1) / fullFrame);
  advice.framesBefore = transport_.options().maxFramesInFlight;
  if (options_.adaptFramesInFlight && advice.framesFitting > advice.framesBefore) {
    transport_.allowFramesInFlight(advice.framesFitting);
    advice.framesRaised = transport_.options().maxFramesInFlight > advice.framesBefore;
  }
  advice_ = advice;
}

double ScanTask::timeoutScale() const {
  if (!advice_) return 1.0;
  const SimTime usual = TransportOptions{}.timeout;
  return std::max(1.0, static_cast<double>(advice_->needed) / static_cast<double>(usual));
}

void ScanTask::queueDefaults() {
  batch_.clear();
  const auto n = static_cast<std::uint16_t>(slaves_.size());
  auto bwr = [&](std::uint16_t address, std::initializer_list<std::uint8_t> bytes) {
    std::vector<std::uint8_t> data(bytes);
    batch_.add().prepare(Command::kBwr, DatagramHeader::physical(0, address), data, 0);
  };
  auto bwrZero = [&](std::uint16_t address, std::uint16_t length) {
    batch_.add().prepare(Command::kBwr, DatagramHeader::physical(0, address), length, 0);
  };
  auto set = [&](auto r, typename decltype(r)::Value value) {
    batch_.add().write(Command::kBwr, 0, r, value, 0);
  };
  // INIT with error acknowledge first; its WKC is checked (every slave must take it).
  // With the ID request (bit 5, ETG.1020 §22.2.2): a slave with an Explicit Device ID shows
  // it in 0x0134 (register read, identify); the next AL control write (INIT->PREOP) withdraws
  // it.
  batch_.add().write(Command::kBwr, 0, reg::kAlControl,
                     static_cast<std::uint16_t>(kAlErrorFlag | reg::al::kDeviceIdentification |
                                                static_cast<std::uint16_t>(AlState::kInit)),
                     n);
  // The other writes are best effort: an ESC without DC, say, need not count them.
  bwr(static_cast<std::uint16_t>(reg::kDlControl.address + 1), {0});  // loop control: auto
  bwr(static_cast<std::uint16_t>(reg::kDlControl.address + 3), {0});  // station alias off
  set(reg::kEcatEventMask, 0x0004);                                   // AL status event
  bwrZero(reg::rxErrorCounters(0), 8);
  bwrZero(reg::fmmuChannel(0), 3 * reg::kFmmuSize);
  bwrZero(reg::smChannel(0), 4 * reg::kSmSize);
  set(reg::kDcActivation, 0);
  bwrZero(reg::kSystemTime.address, 4);  // the 32-bit local time of an ESC with 32-bit DC
  set(reg::kSpeedCounterStart, 0x1000);
  // Difference filter depth 0 and speed counter filter depth 12, in one datagram (as SOEM).
  bwr(reg::kSystemTimeDifferenceFilterDepth.address, {0x00, 0x0C});
  set(reg::kSiiConfiguration, 0x02);  // force the EEPROM to the ECAT side...
  set(reg::kSiiConfiguration, 0x00);  // ...and leave it there
  batch_.queueAll(transport_);
}

void ScanTask::queueAddresses() {
  batch_.clear();
  if (!options_.resetToDefaults) {
    // Leave the slaves as they are, but the SII must be readable from the EtherCAT side.
    for (std::uint8_t value : {std::uint8_t{0x02}, std::uint8_t{0x00}}) {
      batch_.add().write(Command::kBwr, 0, reg::kSiiConfiguration, value,
                         static_cast<std::uint16_t>(slaves_.size()));
    }
  }
  for (auto& slave : slaves_) {
    batch_.add().write(Command::kApwr, Datagram::autoIncrement(slave.position),
                       reg::kConfiguredStationAddress, slave.station);
  }
  batch_.queueAll(transport_);
}

void ScanTask::queueRegisters() {
  batch_.clear();
  for (auto& slave : slaves_) {
    batch_.add().fprd(slave.station, reg::kType, reg::kEscFeatures);
    batch_.add().fprd(slave.station, reg::kConfiguredStationAlias);
    batch_.add().fprd(slave.station, reg::kDlStatus);
    batch_.add().fprd(slave.station, reg::kAlStatus, reg::kAlStatusCode);
    batch_.add().fprd(slave.station, reg::kSiiControlStatus);
    batch_.add().fprd(slave.station, reg::kAlEventRequest);
  }
  batch_.queueAll(transport_);
}

namespace {

// AL status and code as read, and the Explicit Device ID they carry (explicitDeviceId). True once
// the firmware has looked at the request: the ID shows, an error does, or it has read AL control
// (0x0220 bit 0 clear).
bool takeAlStatus(SlaveInfo& slave, std::uint16_t status, std::uint16_t code,
                  std::uint32_t alEvents) {
  slave.alStatus = status;
  slave.alStatusCode = code;
  slave.deviceId = explicitDeviceId(status, code);
  if (slave.deviceId) slave.alStatusCode = 0;  // the register holds the ID, not an error
  return slave.deviceId || (status & kAlErrorFlag) != 0 ||
         (alEvents & reg::al_event::kAlControl) == 0;
}

}  // namespace

void ScanTask::queueIdentify() {
  batch_.clear();
  for (std::size_t position : identifying_) {
    const std::uint16_t station = slaves_[position].station;
    batch_.add().fprd(station, reg::kAlStatus, reg::kAlStatusCode);
    batch_.add().fprd(station, reg::kAlEventRequest);
  }
  batch_.queueAll(transport_);
}

// False when no slave is left to wait for.
bool ScanTask::takeIdentify(SimTime now) {
  std::size_t kept = 0;
  for (std::size_t k = 0; k < identifying_.size(); ++k) {
    SlaveInfo& slave = slaves_[identifying_[k]];
    const Datagram& status = batch_[2 * k];
    if (!takeAlStatus(slave, status.get(reg::kAlStatus), status.get(reg::kAlStatusCode),
                      batch_[2 * k + 1].get(reg::kAlEventRequest))) {
      identifying_[kept++] = identifying_[k];
    }
  }
  identifying_.resize(kept);
  if (identifying_.empty() || now >= identifyUntil_) return false;
  queueIdentify();
  return true;
}

void ScanTask::takeRegisters(SimTime now) {
  identifying_.clear();
  identifyUntil_ = now + options_.identifyWait;
  for (auto& slave : slaves_) {
    const std::size_t base = slave.position * kReadsPerSlave;
    const Datagram& info = batch_[base];
    slave.escType = info.get(reg::kType);
    slave.escRevision = info.get(reg::kRevision);
    slave.escBuild = info.get(reg::kBuild);
    slave.fmmuCount = info.get(reg::kFmmusSupported);
    slave.syncManagerCount = info.get(reg::kSyncManagersSupported);
    slave.ramKb = info.get(reg::kRamSize);
    slave.portDescriptor = info.get(reg::kPortDescriptor);
    slave.features = info.get(reg::kEscFeatures);
    slave.alias = batch_[base + 1].get(reg::kConfiguredStationAlias);
    slave.dlStatus = batch_[base + 2].get(reg::kDlStatus);
    if (!takeAlStatus(slave, batch_[base + 3].get(reg::kAlStatus),
                      batch_[base + 3].get(reg::kAlStatusCode),
                      batch_[base + 5].get(reg::kAlEventRequest))) {
      identifying_.push_back(slave.position);
    }
    slave.siiReads8Bytes =
        (batch_[base + 4].get(reg::kSiiControlStatus) & reg::sii::kReadSize8Bytes) != 0;
  }
  computeTopology(slaves_);
}

void ScanTask::startSii(SimTime now) {
  readers_.clear();
  awaiting_.clear();
  timers_ = {};
  siiRunning_ = slaves_.size();
  for (auto& slave : slaves_) {
    auto& reader =
        readers_.emplace_back(transport_, slave.station, slave.siiReads8Bytes, options_.sii);
    reader.start(now);
    afterStep(static_cast<std::uint32_t>(slave.position));
  }
}

// A reader still running waits either for its poll interval or for its datagram.
void ScanTask::afterStep(std::uint32_t reader) {
  if (auto t = readers_[reader].wakeAt()) {
    timers_.emplace(*t, reader);
  } else {
    awaiting_.push_back(reader);
  }
}

bool ScanTask::stepSii(SimTime now) {
  ready_.clear();
  // Datagrams answered (or given up), up to the first one still waiting for room in a frame.
  while (!awaiting_.empty()) {
    const std::uint32_t r = awaiting_.front();
    const DatagramState state = readers_[r].datagram().state();
    if (state == DatagramState::kQueued) break;
    awaiting_.pop_front();
    (state == DatagramState::kSent ? inFlight_ : ready_).push_back(r);
  }
  for (auto it = inFlight_.rbegin(); it != inFlight_.rend(); ++it) awaiting_.push_front(*it);
  inFlight_.clear();
  while (!timers_.empty() && timers_.top().first <= now) {
    ready_.push_back(timers_.top().second);
    timers_.pop();
  }
  // In slave order, as a pass over every reader would queue their datagrams.
  std::sort(ready_.begin(), ready_.end());
  for (std::uint32_t r : ready_) {
    if (readers_[r].step(now)) {
      afterStep(r);
    } else {
      --siiRunning_;
    }
  }
  return siiRunning_ > 0;
}

void ScanTask::finishSii() {
  for (auto& slave : slaves_) {
    slave.sii = readers_[slave.position].takeImage();
    applySii(slave);
  }
  readers_.clear();
  awaiting_.clear();
  timers_ = {};
}

bool ScanTask::step(SimTime now) {
  switch (state_) {
    case State::kIdle:
    case State::kDone:
    case State::kFailed:
      return false;
    case State::kCount: {
      if (count_.pending()) return true;
      if (!count_.received()) {
        return fail(makeError(ErrorCode::kTimeout,
                              "no slaves found: no answer to the slave count (nothing connected "
                              "or the link is down): " +
                                  count_.check().error().context));
      }
      slaves_.resize(count_.wkc());
      adviseTimeout();
      for (std::size_t i = 0; i < slaves_.size(); ++i) {
        slaves_[i].position = i;
        slaves_[i].station = static_cast<std::uint16_t>(options_.firstStation + i);
      }
      if (slaves_.empty()) {
        state_ = State::kDone;
        return false;
      }
      if (options_.resetToDefaults) {
        queueDefaults();
        state_ = State::kDefaults;
      } else {
        queueAddresses();
        state_ = State::kAddresses;
      }
      return true;
    }
    case State::kDefaults: {
      if (batch_.pending()) return true;
      if (auto s = batch_[0].check(); !s.ok()) {
        return fail(makeError(s.error().code, "reset to INIT: " + s.error().context));
      }
      queueAddresses();
      state_ = State::kAddresses;
      return true;
    }
    case State::kAddresses: {
      if (batch_.pending()) return true;
      if (auto s = batch_.check(); !s.ok()) {
        return fail(makeError(s.error().code, "station addresses: " + s.error().context));
      }
      queueRegisters();
      state_ = State::kRegisters;
      return true;
    }
    case State::kRegisters: {
      if (batch_.pending()) return true;
      if (auto s = batch_.check(); !s.ok()) {
        return fail(makeError(s.error().code, "slave registers: " + s.error().context));
      }
      takeRegisters(now);
      if (!identifying_.empty()) {
        queueIdentify();
        state_ = State::kIdentify;
        return true;
      }
      [[fallthrough]];
    }
    case State::kIdentify: {
      if (state_ == State::kIdentify) {
        if (batch_.pending()) return true;
        if (auto s = batch_.check(); !s.ok()) {
          return fail(makeError(s.error().code, "explicit device IDs: " + s.error().context));
        }
        if (takeIdentify(now)) return true;
      }
      batch_.clear();
      if (!options_.readSii) {
        state_ = State::kDone;
        return false;
      }
      startSii(now);
      state_ = State::kSii;
      [[fallthrough]];
    }
    case State::kSii: {
      if (stepSii(now)) return true;
      for (std::size_t i = 0; i < readers_.size(); ++i) {
        if (!readers_[i].status().ok()) {
          return fail(makeError(readers_[i].status().error().code,
                                slaves_[i].label() + ": " + readers_[i].status().error().context));
        }
      }
      finishSii();
      state_ = State::kDone;
      return false;
    }
  }
  return false;
}

}  // namespace ecsim::master
