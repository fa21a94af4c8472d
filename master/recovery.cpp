#include "master/recovery.hpp"

#include <array>

#include "master/esc_config.hpp"

namespace ecsim::master {
namespace {

// One status read covers 0x0502 (control/status), 0x0504 (address) and 0x0508 (data).
constexpr std::uint16_t kEepromReadLength = static_cast<std::uint16_t>(
    reg::kSiiData.address + reg::kSiiData.width - reg::kSiiControlStatus.address);
constexpr std::size_t kEepromDataOffset = reg::kSiiData.address - reg::kSiiControlStatus.address;
constexpr std::size_t kIdentityBytes = 8;               // vendor id, product code
constexpr std::uint16_t kPdoAssignmentBase = 0x1C10;    // + SM number
constexpr std::uint16_t kSpeedCounterRestart = 0x1000;  // 0x0930, as the DC set-up writes it

std::string hex(unsigned v, int digits) {
  static constexpr char kDigits[] = "0123456789ABCDEF";
  std::string s = "0x";
  for (int d = digits - 1; d >= 0; --d) s += kDigits[(v >> (4 * d)) & 0xF];
  return s;
}

SetupWrite sdoWrite(std::uint16_t index, std::uint8_t subindex, std::vector<std::uint8_t> data) {
  SetupWrite w;
  w.kind = SetupWrite::Kind::kSdo;
  w.index = index;
  w.subindex = subindex;
  w.data = std::move(data);
  w.what = "PDO assignment " + hex(index, 4) + ":" + hex(subindex, 2).substr(2);
  return w;
}

}  // namespace

std::vector<SetupWrite> pdoAssignmentWrites(const SlaveProcessData& data) {
  std::vector<SetupWrite> writes;
  if (data.source != PdoSource::kCoe) return writes;
  for (const SmPdoAssignment& sm : data.sms) {
    const auto index = static_cast<std::uint16_t>(kPdoAssignmentBase + sm.sm);
    writes.push_back(sdoWrite(index, 0, {0}));
    std::uint8_t sub = 0;
    for (const PdoInfo& pdo : sm.pdos) {
      std::vector<std::uint8_t> value(2);
      writeLe16(value, 0, pdo.index);
      writes.push_back(sdoWrite(index, ++sub, std::move(value)));
    }
    writes.push_back(sdoWrite(index, 0, {sub}));
  }
  return writes;
}

namespace {

bool isWrite(Command c) {
  return c == Command::kApwr || c == Command::kFpwr || c == Command::kBwr || c == Command::kAprw ||
         c == Command::kFprw || c == Command::kBrw;
}

// An ENI's init commands of one slave for from -> to: register writes (at the slave's station
// address; AL control and the station address are the recovery's own) and CoE downloads.
void addEniWrites(std::vector<SetupWrite>& out, const EniConfig& eni, const EniSlave& slave,
                  char from, char to, bool registers, bool coe) {
  const std::string transition{from, to};
  if (registers) {
    for (const EniRegisterCmd& c : slave.initCmds) {
      if (c.ado == reg::kAlControl.address || c.ado == reg::kConfiguredStationAddress.address) {
        continue;
      }
      if (!isWrite(static_cast<Command>(c.cmd)) || c.data.empty()) continue;
      // addEniRegisterCmds() decides which transitions a command belongs to: ask it.
      EniSlave one;
      one.initCmds.push_back(c);
      DatagramBatch probe;
      if (addEniRegisterCmds(probe, one, from, to) == 0) continue;
      SetupWrite w;
      w.kind = SetupWrite::Kind::kRegister;
      w.index = c.ado;
      w.data = c.data;
      w.what = "register init command " + hex(c.ado, 4) + " (" + transition + "), " +
               eni.file.string() + " line " + std::to_string(c.line);
      out.push_back(std::move(w));
    }
  }
  if (coe) {
    for (const EniCoeCmd* c : eniCoeCmds(slave, from, to)) {
      if (c->ccs != 1) continue;  // uploads only read
      SetupWrite w;
      w.kind = SetupWrite::Kind::kSdo;
      w.index = c->index;
      w.subindex = c->subIndex;
      w.completeAccess = c->completeAccess;
      w.data = c->data;
      w.what = "CoE init command " + hex(c->index, 4) + ":" + std::to_string(c->subIndex) + " (" +
               transition + "), " + eni.file.string() + " line " + std::to_string(c->line);
      out.push_back(std::move(w));
    }
  }
}

}  // namespace

std::vector<SetupWrite> MasterSlaveSetup::writesFor(const SlaveInfo& slave, AlState target) const {
  std::vector<SetupWrite> out;
  if (config_ && config_->eni && slave.position < config_->eni->slaves.size()) {
    const EniConfig& eni = *config_->eni;
    const EniSlave& want = eni.slaves[slave.position];
    switch (target) {
      case AlState::kPreOp:
        addEniWrites(out, eni, want, 'I', 'P', true, false);
        break;
      case AlState::kSafeOp:
        addEniWrites(out, eni, want, 'I', 'P', false, true);  // a mailbox exists from PREOP on
        addEniWrites(out, eni, want, 'P', 'S', true, true);
        break;
      case AlState::kOp:
        addEniWrites(out, eni, want, 'S', 'O', true, true);
        break;
      case AlState::kInit:
      case AlState::kBootstrap:
        break;
    }
    return out;
  }
  if (target == AlState::kSafeOp && slave.position < processData_.size()) {
    out = pdoAssignmentWrites(processData_[slave.position]);
  }
  return out;
}

std::optional<DcRecovery> MasterSlaveSetup::dcRecovery(const SlaveInfo& slave) const {
  if (dc_ == nullptr || slaves_ == nullptr) return std::nullopt;
  return dcRecoveryFor(*dc_, *slaves_, slave.position, sync0Margin_);
}

std::string_view toString(SlaveRecoveryTask::Stage stage) {
  switch (stage) {
    case SlaveRecoveryTask::Stage::kAddress:
      return "station address";
    case SlaveRecoveryTask::Stage::kIdentity:
      return "identity";
    case SlaveRecoveryTask::Stage::kMailbox:
      return "mailbox and PREOP";
    case SlaveRecoveryTask::Stage::kDc:
      return "distributed clock";
    case SlaveRecoveryTask::Stage::kProcess:
      return "process data and SAFEOP";
    case SlaveRecoveryTask::Stage::kOp:
      return "OP";
    case SlaveRecoveryTask::Stage::kDone:
      return "done";
    case SlaveRecoveryTask::Stage::kFailed:
      return "failed";
  }
  return "?";
}

SlaveRecoveryTask::SlaveRecoveryTask(Transport& transport, SlaveInfo& slave,
                                     const ProcessImageLayout& layout, StateChangeOptions options,
                                     const SlaveSetup* setup, MailboxOptions mailbox)
    : transport_(transport),
      slave_(slave),
      layout_(layout),
      options_(options),
      setup_(setup),
      mailbox_(mailbox) {}

void SlaveRecoveryTask::start(Stage first, SimTime now, SimTime timeout) {
  status_ = okStatus();
  deadline_ = now + timeout;
  enter(first, now);
}

std::optional<SimTime> SlaveRecoveryTask::wakeAt() const {
  if (change_) return change_->wakeAt();
  if (sdo_) return sdo_->wakeAt();
  return std::nullopt;
}

void SlaveRecoveryTask::fail(Status status) {
  // The event that reports it names the slave.
  status_ = makeError(status.error().code, "recovery (" + std::string(toString(stage_)) +
                                               "): " + status.error().context);
  stage_ = Stage::kFailed;
  change_.reset();
  sdo_.reset();
}

void SlaveRecoveryTask::enter(Stage stage, SimTime now) {
  stage_ = stage;
  sub_ = Sub::kStart;
  batch_.clear();
  change_.reset();
  sdo_.reset();
  writes_.clear();
  switch (stage) {
    case Stage::kAddress: {
      batch_.add().write(Command::kApwr, Datagram::autoIncrement(slave_.position),
                         reg::kConfiguredStationAddress, slave_.station);
      break;
    }
    case Stage::kIdentity: {
      batch_.add().fpwr(slave_.station, reg::kSiiConfiguration, std::uint8_t{0});  // ECAT side
      identity_.clear();
      queueEepromRead(sii::kWordVendorId);
      return;
    }
    case Stage::kMailbox:
      addMailboxSetup(batch_, slave_);
      break;
    case Stage::kDc:
      dc_ = setup_ != nullptr ? setup_->dcRecovery(slave_) : std::nullopt;
      if (!dc_) {
        enter(Stage::kProcess, now);
        return;
      }
      // Its drift loop restarted first: until it has its offset it is not in the group, but
      // its clock was written times meant for the others (an FRMW's write reaches every slave
      // but the addressed one, and a power-cycled slave has lost its address), which a real
      // ESC follows at its fastest rate. Then one datagram latches the source clock's and this
      // slave's local time (0x0918) at the same point of the frame; the count of slaves that
      // latch is not checked.
      batch_.add().fpwr(slave_.station, reg::kSpeedCounterStart, kSpeedCounterRestart);
      batch_.add().write(Command::kBwr, 0, reg::kReceiveTimePort0, std::uint32_t{0}, 0);
      batch_.queueAll(transport_);
      sub_ = Sub::kDcLatch;
      return;
    case Stage::kProcess:
      startWrites(AlState::kSafeOp);  // then the SMs and FMMUs (queueProcessDataSetup)
      return;
    case Stage::kOp:
      startWrites(AlState::kOp);
      return;
    case Stage::kDone:
    case Stage::kFailed:
      break;
  }
  (void)now;
  batch_.queueAll(transport_);
  sub_ = Sub::kWait;
}

void SlaveRecoveryTask::queueProcessDataSetup() {
  batch_.clear();
  for (const auto& sl : layout_.slaves) {
    if (sl.position != slave_.position) continue;
    ProcessImageLayout mine;
    mine.slaves.push_back(sl);
    addProcessDataSetup(batch_, mine);
  }
  batch_.queueAll(transport_);
  sub_ = Sub::kWait;
}

void SlaveRecoveryTask::startWrites(AlState target) {
  writes_.clear();
  if (setup_ != nullptr) writes_ = setup_->writesFor(slave_, target);
  write_ = 0;
  writeQueued_ = false;
  sdo_.reset();
  sub_ = Sub::kWrites;
}

// One write after the other; false when all are done or one failed (stage_ says which).
bool SlaveRecoveryTask::stepWrites(SimTime now) {
  while (write_ < writes_.size()) {
    const SetupWrite& w = writes_[write_];
    Status done = okStatus();
    if (w.kind == SetupWrite::Kind::kSdo) {
      if (!sdo_) {
        sdo_ = std::make_unique<SdoTask>(transport_, slave_, nullptr, mailbox_);
        done = sdo_->startDownload(w.index, w.subindex, w.data, w.completeAccess, now);
      }
      if (done.ok()) {
        if (sdo_->step(now)) return true;
        done = sdo_->status();
      }
      sdo_.reset();
    } else {
      if (!writeQueued_) {
        batch_.clear();
        batch_.add().fpwr(slave_.station, w.index, w.data);
        batch_.queueAll(transport_);
        writeQueued_ = true;
      }
      if (batch_.pending()) return true;
      writeQueued_ = false;
      done = batch_.check();
    }
    if (!done.ok()) {
      fail(makeError(done.error().code, w.what + ": " + done.error().context));
      return false;
    }
    ++write_;
  }
  return false;
}

void SlaveRecoveryTask::queueEepromRead(std::uint32_t word) {
  eepromWord_ = word;
  std::array<std::uint8_t, 6> command{};
  writeLe16(command, 0, reg::sii::kCommandRead);
  writeLe32(command, 2, word);
  batch_.add().fpwr(slave_.station, reg::kSiiControlStatus.address, command);
  batch_.queueAll(transport_);
  sub_ = Sub::kEepromCommand;
}

bool SlaveRecoveryTask::stepIdentity(SimTime now) {
  if (batch_.pending()) return true;
  if (auto s = batch_.check(); !s.ok()) {
    fail(s);
    return false;
  }
  if (sub_ == Sub::kAlias || sub_ == Sub::kDeviceId) return stepIdentification(now);
  if (sub_ == Sub::kEepromPoll) {
    const ConstBytes answer = batch_[0].data();
    const std::uint16_t status = readLe16(answer, 0);
    if ((status & (reg::sii::kBusy | reg::sii::kErrorMask)) == 0) {
      const std::size_t n = (status & reg::sii::kReadSize8Bytes) != 0 ? 8 : 4;
      for (std::size_t i = 0; i < n && identity_.size() < kIdentityBytes; ++i) {
        identity_.push_back(answer[kEepromDataOffset + i]);
      }
      if (identity_.size() >= kIdentityBytes) {
        const SiiIdentity& known = slave_.identity();
        const std::uint32_t vendor = readLe32(identity_, 0);
        const std::uint32_t product = readLe32(identity_, 4);
        if (vendor != known.vendorId || product != known.productCode) {
          SiiIdentity found = known;
          found.vendorId = vendor;
          found.productCode = product;
          fail(makeError(ErrorCode::kInvalidArgument, "another device answers at position " +
                                                          std::to_string(slave_.position) + ": " +
                                                          describeIdentity(found) + ", expected " +
                                                          describeIdentity(known)));
          return false;
        }
        // The same kind of device; is it the same one? Its alias, and its Explicit Device ID
        // when it showed one at the scan (a tool changer's tools are alike but for these).
        batch_.clear();
        batch_.add().fprd(slave_.station, reg::kConfiguredStationAlias);
        if (slave_.deviceId) {
          batch_.add().fpwr(slave_.station, reg::kAlControl,
                            static_cast<std::uint16_t>(static_cast<std::uint16_t>(AlState::kInit) |
                                                       reg::al::kDeviceIdentification));
        }
        batch_.queueAll(transport_);
        sub_ = Sub::kAlias;
        return true;
      }
      batch_.clear();
      queueEepromRead(eepromWord_ + static_cast<std::uint32_t>(n / 2));
      return true;
    }
    if ((status & reg::sii::kChecksumError) != 0) {
      fail(makeError(ErrorCode::kIo,
                     "EEPROM checksum error (0x0502 bit 11): the ESC did not load its "
                     "configuration, the slave cannot leave INIT"));
      return false;
    }
    if ((status & reg::sii::kErrorMask) != 0) {
      fail(makeError(ErrorCode::kIo, "EEPROM read of word " + std::to_string(eepromWord_) +
                                         " reports error bits (0x0502 = " + hex(status, 4) + ")"));
      return false;
    }
  }
  // Command accepted (or still busy): read the status, address and data.
  batch_.clear();
  batch_.add().fprd(slave_.station, reg::kSiiControlStatus.address, kEepromReadLength);
  batch_.queueAll(transport_);
  sub_ = Sub::kEepromPoll;
  return true;
}

// Alias read (and ID requested), then the AL status polled until the ID shows (ETG.1020
// §22.2.2: AL status bit 5 with the ID in 0x0134); the recovery's deadline bounds the wait.
bool SlaveRecoveryTask::stepIdentification(SimTime now) {
  auto differs = [&](const char* what, unsigned found, unsigned expected) {
    fail(makeError(ErrorCode::kInvalidArgument,
                   "another device answers at position " + std::to_string(slave_.position) + ": " +
                       describeIdentity(slave_.identity()) + " with " + what + " " +
                       std::to_string(found) + ", expected " + std::to_string(expected)));
    return false;
  };
  if (sub_ == Sub::kAlias) {
    const std::uint16_t alias = batch_[0].get(reg::kConfiguredStationAlias);
    if (alias != slave_.alias) return differs("station alias (0x0012)", alias, slave_.alias);
    if (!slave_.deviceId) {
      enter(Stage::kMailbox, now);
      return true;
    }
  } else {
    if (const auto id =
            explicitDeviceId(batch_[0].get(reg::kAlStatus), batch_[0].get(reg::kAlStatusCode))) {
      if (*id != *slave_.deviceId) {
        return differs("explicit device ID (0x0134)", *id, *slave_.deviceId);
      }
      enter(Stage::kMailbox, now);  // its INIT->PREOP request withdraws the ID request
      return true;
    }
  }
  batch_.clear();
  batch_.add().fprd(slave_.station, reg::kAlStatus, reg::kAlStatusCode);
  batch_.queueAll(transport_);
  sub_ = Sub::kDeviceId;
  return true;
}

bool SlaveRecoveryTask::stepStateChange(AlState target, Stage next, SimTime now) {
  if (!change_) {
    one_.assign(1, slave_);
    one_[0].position = 0;  // StateChangeTask indexes its vector by position
    change_ = std::make_unique<StateChangeTask>(transport_, one_, options_);
    change_->start(target, now);
  }
  if (change_->step(now)) return true;
  slave_.alStatus = one_[0].alStatus;
  slave_.alStatusCode = one_[0].alStatusCode;
  slave_.mailboxCounter = one_[0].mailboxCounter;
  if (!change_->status().ok()) {
    fail(change_->status());
    return false;
  }
  if (next == Stage::kDone) {
    stage_ = Stage::kDone;
    change_.reset();
    return false;
  }
  enter(next, now);
  return true;
}

bool SlaveRecoveryTask::stepDc(SimTime now) {
  if (batch_.pending()) return true;
  const DcRecovery& dc = *dc_;
  if (sub_ == Sub::kDcLatch) {
    if (!batch_[0].wkcOk()) {
      fail(makeError(ErrorCode::kWorkingCounter, "drift loop restart: " + batch_[0].describe()));
      return false;
    }
    if (!batch_[1].received()) {
      fail(makeError(ErrorCode::kTimeout, "time latch: " + batch_[1].describe()));
      return false;
    }
    batch_.clear();
    // The source clock's latched local time 0x0918 and its offset 0x0920 in one read.
    batch_.add().fprd(dc.sourceStation, reg::kReceiveTimeEcatProcessingUnit,
                      reg::kSystemTimeOffset);
    batch_.add().fprd(slave_.station, reg::kReceiveTimeEcatProcessingUnit);
    batch_.queueAll(transport_);
    sub_ = Sub::kDcRead;
    return true;
  }
  if (auto s = batch_.check(); !s.ok()) {
    fail(makeError(s.error().code, (sub_ == Sub::kDcRead ? "latched times (clock of " +
                                                               hex(dc.sourceStation, 4) + "): "
                                                         : std::string("DC registers: ")) +
                                       s.error().context));
    return false;
  }
  if (sub_ == Sub::kDcWrite) {
    enter(Stage::kProcess, now);
    return true;
  }
  // kDcRead answered: the source's system time at the latch, and this slave's local time.
  const std::uint64_t sourceLocal = batch_[0].get(reg::kReceiveTimeEcatProcessingUnit);
  const std::uint64_t sourceOffset = batch_[0].get(reg::kSystemTimeOffset);
  const std::uint64_t slaveLocal = batch_[1].get(reg::kReceiveTimeEcatProcessingUnit);
  const std::uint64_t sourceTime = sourceLocal + sourceOffset;
  batch_.clear();
  batch_.add().fpwr(slave_.station, reg::kSystemTimeDelay, static_cast<std::uint32_t>(dc.delay));
  batch_.add().fpwr(
      slave_.station, reg::kSystemTimeOffset,
      recoveredDcOffset(sourceLocal, sourceOffset, slaveLocal, dc.delay - dc.sourceDelay));
  batch_.add().fpwr(slave_.station, reg::kSpeedCounterStart, kSpeedCounterRestart);
  if (dc.sync0) {
    const std::uint64_t start = nextSync0Time(
        dc.sync0Start, dc.sync0Cycle, sourceTime + static_cast<std::uint64_t>(dc.sync0Margin));
    batch_.add().fpwr(slave_.station, reg::kDcActivation, std::uint8_t{0});
    batch_.add().fpwr(slave_.station, reg::kSync0CycleTime,
                      static_cast<std::uint32_t>(dc.sync0Cycle));
    batch_.add().fpwr(slave_.station, reg::kStartTimeCyclicOperation, start);
    batch_.add().fpwr(slave_.station, reg::kCyclicUnitControl.address,
                      leBytes(dc.assignActivate, 2));
  }
  batch_.queueAll(transport_);
  sub_ = Sub::kDcWrite;
  return true;
}

bool SlaveRecoveryTask::step(SimTime now) {
  if (done()) return false;
  if (now > deadline_) {
    fail(makeError(ErrorCode::kTimeout, "not back in OP in time"));
    return false;
  }
  switch (stage_) {
    case Stage::kAddress:
      if (batch_.pending()) return true;
      if (auto s = batch_.check(); !s.ok()) {
        fail(s);
        return false;
      }
      enter(Stage::kIdentity, now);
      return true;
    case Stage::kIdentity:
      return stepIdentity(now);
    case Stage::kDc:
      return stepDc(now);
    case Stage::kMailbox:  // SMs, writes, PREOP
    case Stage::kProcess:  // writes, SMs and FMMUs, SAFEOP
      if (sub_ == Sub::kWait) {
        if (batch_.pending()) return true;
        if (auto s = batch_.check(); !s.ok()) {
          fail(s);
          return false;
        }
        if (stage_ == Stage::kMailbox) {
          startWrites(AlState::kPreOp);
        } else {
          sub_ = Sub::kStart;
        }
      }
      if (sub_ == Sub::kWrites) {
        if (stepWrites(now)) return true;
        if (stage_ == Stage::kFailed) return false;
        if (stage_ == Stage::kProcess) {
          queueProcessDataSetup();
          return true;
        }
        sub_ = Sub::kStart;
      }
      return stage_ == Stage::kMailbox ? stepStateChange(AlState::kPreOp, Stage::kDc, now)
                                       : stepStateChange(AlState::kSafeOp, Stage::kOp, now);
    case Stage::kOp:
      if (sub_ == Sub::kWrites) {
        if (stepWrites(now)) return true;
        if (stage_ == Stage::kFailed) return false;
        sub_ = Sub::kStart;
      }
      return stepStateChange(AlState::kOp, Stage::kDone, now);
    case Stage::kDone:
    case Stage::kFailed:
      break;
  }
  return false;
}

}  // namespace ecsim::master
