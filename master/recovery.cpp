#include "master/recovery.hpp"

#include <array>

#include "master/esc_config.hpp"

namespace ecsim::master {
namespace {

// One status read covers 0x0502 (control/status), 0x0504 (address) and 0x0508 (data).
constexpr std::uint16_t kEepromReadLength = static_cast<std::uint16_t>(
    reg::kSiiData.address + reg::kSiiData.width - reg::kSiiControlStatus.address);
constexpr std::size_t kEepromDataOffset = reg::kSiiData.address - reg::kSiiControlStatus.address;
constexpr std::size_t kIdentityBytes = 8;  // vendor id, product code

}  // namespace

std::string_view toString(SlaveRecoveryTask::Stage stage) {
  switch (stage) {
    case SlaveRecoveryTask::Stage::kAddress:
      return "station address";
    case SlaveRecoveryTask::Stage::kIdentity:
      return "identity";
    case SlaveRecoveryTask::Stage::kMailbox:
      return "mailbox and PREOP";
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
                                     const ProcessImageLayout& layout, StateChangeOptions options)
    : transport_(transport), slave_(slave), layout_(layout), options_(options) {}

void SlaveRecoveryTask::start(Stage first, SimTime now, SimTime timeout) {
  status_ = okStatus();
  deadline_ = now + timeout;
  enter(first, now);
}

std::optional<SimTime> SlaveRecoveryTask::wakeAt() const {
  if (change_) return change_->wakeAt();
  return std::nullopt;
}

void SlaveRecoveryTask::fail(Status status) {
  status_ = makeError(status.error().code, slave_.label() + " recovery (" +
                                               std::string(toString(stage_)) +
                                               "): " + status.error().context);
  stage_ = Stage::kFailed;
  change_.reset();
}

void SlaveRecoveryTask::enter(Stage stage, SimTime now) {
  stage_ = stage;
  sub_ = Sub::kStart;
  batch_.clear();
  change_.reset();
  switch (stage) {
    case Stage::kAddress: {
      std::array<std::uint8_t, 2> station{};
      writeLe16(station, 0, slave_.station);
      batch_.add().prepare(Command::kApwr,
                           DatagramHeader::physical(Datagram::autoIncrement(slave_.position),
                                                    reg::kConfiguredStationAddress.address),
                           station, 1);
      break;
    }
    case Stage::kIdentity: {
      const std::array<std::uint8_t, 1> ecatOwnsEeprom{0};
      batch_.add().fpwr(slave_.station, reg::kSiiConfiguration.address, ecatOwnsEeprom);
      identity_.clear();
      queueEepromRead(sii::kWordVendorId);
      return;
    }
    case Stage::kMailbox:
      addMailboxSetup(batch_, slave_);
      break;
    case Stage::kProcess:
      for (const auto& sl : layout_.slaves) {
        if (sl.position != slave_.position) continue;
        ProcessImageLayout mine;
        mine.slaves.push_back(sl);
        addProcessDataSetup(batch_, mine);
      }
      break;
    case Stage::kOp:
    case Stage::kDone:
    case Stage::kFailed:
      break;
  }
  (void)now;
  batch_.queueAll(transport_);
  sub_ = Sub::kWait;
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
        enter(Stage::kMailbox, now);
        return true;
      }
      batch_.clear();
      queueEepromRead(eepromWord_ + static_cast<std::uint32_t>(n / 2));
      return true;
    }
    if ((status & reg::sii::kErrorMask) != 0) {
      fail(makeError(ErrorCode::kIo,
                     "EEPROM read of word " + std::to_string(eepromWord_) + " reports error bits"));
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
    case Stage::kMailbox:
      if (sub_ == Sub::kWait) {
        if (batch_.pending()) return true;
        if (auto s = batch_.check(); !s.ok()) {
          fail(s);
          return false;
        }
        sub_ = Sub::kStart;
      }
      return stepStateChange(AlState::kPreOp, Stage::kProcess, now);
    case Stage::kProcess:
      if (sub_ == Sub::kWait) {
        if (batch_.pending()) return true;
        if (auto s = batch_.check(); !s.ok()) {
          fail(s);
          return false;
        }
        sub_ = Sub::kStart;
      }
      return stepStateChange(AlState::kSafeOp, Stage::kOp, now);
    case Stage::kOp:
      return stepStateChange(AlState::kOp, Stage::kDone, now);
    case Stage::kDone:
    case Stage::kFailed:
      break;
  }
  return false;
}

}  // namespace ecsim::master
