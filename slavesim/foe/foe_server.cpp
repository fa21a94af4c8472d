#include "slavesim/foe/foe_server.hpp"

#include <algorithm>

#include "slavesim/al_state_machine.hpp"
#include "slavesim/coe/standard_objects.hpp"
#include "slavesim/esc.hpp"

namespace ecsim::slavesim::foe {
namespace {

// The mailbox SM the master writes (normally SM0): its length bounds what one DATA packet of a
// write carries.
std::size_t receiveMailboxSize(const Esc& esc) {
  for (unsigned s = 0; s < esc.type().syncManagers; ++s) {
    const Esc::SmConfig c = esc.smConfig(s);
    if (c.enabled && c.length > 0 && c.control.isMailbox() && c.control.isEcatWrite()) {
      return c.length;
    }
  }
  return 0;
}

bool inBoot(const Esc& esc) {
  return AlStateMachine::state(esc) == AlState::kBootstrap;
}

}  // namespace

Status installFirmware(FoeFiles& files, coe::ObjectDictionary& od) {
  ECSIM_TRY(files.installPending());
  const std::optional<std::string>& version = files.installedVersion();
  if (!version) return okStatus();
  std::string name = "Software version";
  std::uint16_t accessBits = coe::access::kReadOnly;
  if (const coe::Object* o = od.find(coe::kSoftwareVersionIndex); o != nullptr) {
    name = o->name;
    if (!o->entries.empty()) accessBits = o->entries.front().access;
  }
  od.addString(coe::kSoftwareVersionIndex, name, *version, accessBits);
  return okStatus();
}

FoeServer::FoeServer(std::shared_ptr<FoeFiles> files, FoeServerOptions options)
    : files_(files ? std::move(files) : std::make_shared<FoeFiles>()), options_(options) {}

void FoeServer::reset() {
  if (transfer_ == Transfer::kWriting) files_->abandonWrite();
  transfer_ = Transfer::kIdle;
  name_.clear();
  writing_ = FoeFile();
  reading_.reset();
  packet_ = 0;
  offset_ = 0;
  lastSent_ = false;
}

void FoeServer::sendError(MailboxReplies& replies, FoeErrorCode code) {
  ++counters_.errorsSent;
  reset();
  replies.send(encodeFoeMailbox(FoeOpcode::kError, static_cast<std::uint32_t>(code),
                                foeErrorText(static_cast<std::uint32_t>(code))));
}

void FoeServer::onMessage(Esc& esc, const MailboxMessage& message, MailboxReplies& replies,
                          SimTime /*now*/) {
  auto p = decodeFoe(message.payload);
  if (!p.ok()) return sendError(replies, FoeErrorCode::kIllegal);
  if (!options_.outsideBoot && !inBoot(esc)) {
    return sendError(replies, FoeErrorCode::kBootstrapOnly);
  }
  switch (p->opcode) {
    case FoeOpcode::kWrite:
      return onWriteRequest(esc, *p, replies);
    case FoeOpcode::kRead:
      return onReadRequest(esc, *p, replies);
    case FoeOpcode::kData:
      return onData(esc, *p, replies);
    case FoeOpcode::kAck:
      return onAck(*p, replies);
    case FoeOpcode::kError:
      reset();  // the master gave up: no answer (ETG.1000.6 §5.7, SSC "FOE 1")
      return;
    case FoeOpcode::kBusy:
      break;
  }
  sendError(replies, FoeErrorCode::kIllegal);
}

void FoeServer::onWriteRequest(const Esc& esc, const FoePacket& p, MailboxReplies& replies) {
  reset();
  if (p.data.empty()) return sendError(replies, FoeErrorCode::kIllegal);
  if (p.value != options_.password) return sendError(replies, FoeErrorCode::kNoRights);
  transfer_ = Transfer::kWriting;
  name_.assign(p.text());
  writingInBoot_ = inBoot(esc);
  busyLeft_ = options_.busyResponses;
  if (!files_->beginWrite(name_).ok()) return sendError(replies, FoeErrorCode::kDiskFull);
  replies.send(encodeFoeMailbox(FoeOpcode::kAck, 0));
}

void FoeServer::onData(const Esc& esc, const FoePacket& p, MailboxReplies& replies) {
  if (transfer_ != Transfer::kWriting) return sendError(replies, FoeErrorCode::kIllegal);
  if (p.value != packet_ + 1) return sendError(replies, FoeErrorCode::kPacketNumberWrong);
  if (busyLeft_ > 0) {
    // Not taken: the master sends this packet again.
    --busyLeft_;
    ++counters_.busySent;
    replies.send(encodeFoeMailbox(FoeOpcode::kBusy,
                                  foeBusyValue(static_cast<std::uint16_t>(busyLeft_), 100)));
    return;
  }
  if (writing_.size() + p.data.size() > options_.maxFileSize) {
    return sendError(replies, FoeErrorCode::kDiskFull);
  }
  if (!files_->appendWrite(p.data).ok()) return sendError(replies, FoeErrorCode::kDiskFull);
  writing_.append(p.data);
  packet_ = p.value;
  const bool last = p.data.size() < foeDataPerPacket(receiveMailboxSize(esc));
  if (last) {
    transfer_ = Transfer::kIdle;  // stored or failed: nothing left to abandon
    if (!files_->store(name_, std::move(writing_), writingInBoot_).ok()) {
      return sendError(replies, FoeErrorCode::kDiskFull);
    }
    ++counters_.filesWritten;
    const std::uint32_t n = packet_;
    reset();
    replies.send(encodeFoeMailbox(FoeOpcode::kAck, n));
    return;
  }
  replies.send(encodeFoeMailbox(FoeOpcode::kAck, packet_));
}

void FoeServer::onReadRequest(const Esc& /*esc*/, const FoePacket& p, MailboxReplies& replies) {
  reset();
  if (p.data.empty()) return sendError(replies, FoeErrorCode::kIllegal);
  const std::string name(p.text());
  std::shared_ptr<const FoeFile> file = files_->share(name);
  if (file == nullptr) return sendError(replies, FoeErrorCode::kNotFound);
  if (p.value != options_.password) return sendError(replies, FoeErrorCode::kNoRights);
  transfer_ = Transfer::kReading;
  name_ = name;
  reading_ = std::move(file);
  sendData(replies);
}

void FoeServer::sendData(MailboxReplies& replies) {
  const std::size_t perPacket = foeDataPerPacket(replies.mailboxSize());
  packetData_.resize(perPacket);
  const std::size_t n = reading_->copyOut(offset_, packetData_);
  ++packet_;
  replies.send(encodeFoeMailbox(FoeOpcode::kData, packet_, ConstBytes(packetData_).first(n)));
  offset_ += n;
  lastSent_ = n < perPacket;
}

void FoeServer::onAck(const FoePacket& p, MailboxReplies& replies) {
  if (transfer_ != Transfer::kReading) return sendError(replies, FoeErrorCode::kIllegal);
  if (p.value != packet_) return sendError(replies, FoeErrorCode::kPacketNumberWrong);
  if (lastSent_) {
    // The master has the whole file: its ACK of the last packet gets no answer (SOEM's
    // ecx_FOEread sends it and returns).
    ++counters_.filesRead;
    reset();
    return;
  }
  sendData(replies);
}

}  // namespace ecsim::slavesim::foe
