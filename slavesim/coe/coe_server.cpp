#include "slavesim/coe/coe_server.hpp"

#include <algorithm>

#include "protocol/sdo_info.hpp"
#include "slavesim/al_state_machine.hpp"
#include "slavesim/coe/sdo_access.hpp"
#include "slavesim/coe/standard_objects.hpp"

namespace ecsim::slavesim::coe {
namespace {

constexpr std::size_t kMinimumBuffer = 64;  // room for any fixed-size reply

// The SM in mailbox mode the master reads (normally SM1): its length bounds every response.
std::size_t sendMailboxSize(const Esc& esc) {
  for (unsigned s = 0; s < esc.type().syncManagers; ++s) {
    const Esc::SmConfig c = esc.smConfig(s);
    if (c.enabled && c.length > 0 && c.control.isMailbox() && !c.control.isEcatWrite()) {
      return c.length;
    }
  }
  return 0;
}

bool isEmergency(const std::vector<std::uint8_t>& message) {
  return message.size() >= kCoeBodyOffset &&
         (message[5] & 0x0F) == static_cast<std::uint8_t>(MailboxType::kCoe) &&
         (message[7] >> 4) == static_cast<std::uint8_t>(CoeService::kEmergency);
}

constexpr std::uint32_t code(SdoAbortCode c) {
  return static_cast<std::uint32_t>(c);
}

}  // namespace

CoeServer::CoeServer(std::shared_ptr<ObjectDictionary> od, CoeServerOptions options)
    : od_(std::move(od)), options_(options) {}

void CoeServer::addProtocol(std::unique_ptr<MailboxProtocol> protocol) {
  if (protocol == nullptr) return;
  for (auto& p : protocols_) {
    if (p->type() == protocol->type()) {
      p = std::move(protocol);
      return;
    }
  }
  protocols_.push_back(std::move(protocol));
}

MailboxProtocol* CoeServer::protocol(MailboxType type) {
  for (auto& p : protocols_) {
    if (p->type() == type) return p.get();
  }
  return nullptr;
}

void CoeServer::reset() {
  for (auto& p : protocols_) p->reset();
  outbox_.clear();
  lastRequest_.clear();
  lastResponses_.clear();
  upload_ = {};
  download_ = {};
}

void CoeServer::poll(Esc& esc, SimTime now) {
  const bool available = esc.pdiMailboxAvailable();
  if (!available) {
    if (mailboxWasAvailable_) reset();
    mailboxWasAvailable_ = false;
    return;
  }
  mailboxWasAvailable_ = true;
  if (!protocols_.empty()) {
    mailboxSize_ = sendMailboxSize(esc);
    for (auto& p : protocols_) p->poll(esc, *this, now);
  }
  trySend(esc);
}

void CoeServer::trySend(Esc& esc) {
  while (!outbox_.empty() && esc.pdiMailboxAvailable() && !esc.pdiMailboxResponsePending()) {
    if (!esc.pdiMailboxSend(outbox_.front())) break;
    if (isEmergency(outbox_.front())) ++counters_.emergenciesSent;
    outbox_.pop_front();
  }
}

void CoeServer::queue(std::vector<std::uint8_t> message) {
  if (message.size() >= kMailboxHeaderSize) {
    responseCounter_ = nextMailboxCounter(responseCounter_);
    message[5] = static_cast<std::uint8_t>((message[5] & 0x8F) | (responseCounter_ << 4));
  }
  if (recording_) lastResponses_.push_back(message);
  outbox_.push_back(std::move(message));
}

void CoeServer::pushEmergency(const Emergency& emergency) {
  if (outbox_.size() >= options_.maxQueuedMessages) {
    ++counters_.emergenciesDropped;
    return;
  }
  std::vector<std::uint8_t> message(kCoeBodyOffset + Emergency::kSize, 0);
  auto n = encodeEmergencyMailbox(message, emergency);
  if (!n.ok()) return;
  message.resize(*n);
  queue(std::move(message));
}

void CoeServer::onRequest(Esc& esc, ConstBytes mailbox, SimTime now) {
  ++counters_.requests;
  mailboxWasAvailable_ = true;
  mailboxSize_ = sendMailboxSize(esc);
  std::size_t used = mailbox.size();
  std::uint8_t counter = 0;
  if (auto header = MailboxHeader::decode(mailbox); header.ok()) {
    counter = header->counter;
    used = std::min(mailbox.size(), kMailboxHeaderSize + header->length);
  }
  const ConstBytes request = mailbox.first(used);
  if (counter != 0 && !lastRequest_.empty() &&
      std::equal(request.begin(), request.end(), lastRequest_.begin(), lastRequest_.end())) {
    ++counters_.repeatedRequests;  // a retry: answer again, do not execute again
    for (const auto& m : lastResponses_) outbox_.push_back(m);
    trySend(esc);
    return;
  }
  lastResponses_.clear();
  if (counter != 0) {
    lastRequest_.assign(request.begin(), request.end());
  } else {
    lastRequest_.clear();
  }
  recording_ = true;
  handle(esc, mailbox, now);
  recording_ = false;
  trySend(esc);
}

void CoeServer::handle(Esc& esc, ConstBytes mailbox, SimTime now) {
  auto message = decodeMailbox(mailbox);
  if (!message.ok()) return sendMailboxError(MailboxErrorCode::kInvalidSize);
  // BOOT: the bootloader speaks FoE only (Beckhoff's EtherCAT state machine description:
  // in Bootstrap "mailbox communication via FoE is possible, but no other mailbox
  // communication"); CoE and the rest get "unsupported protocol" there.
  const bool boot = AlStateMachine::state(esc) == AlState::kBootstrap;
  if (boot && message->header.type != MailboxType::kFoe) {
    return sendMailboxError(MailboxErrorCode::kUnsupportedProtocol);
  }
  if (message->header.type != MailboxType::kCoe) {
    if (MailboxProtocol* p = protocol(message->header.type); p != nullptr) {
      return p->onMessage(esc, *message, *this, now);
    }
  }
  if (message->header.type != MailboxType::kCoe || !options_.coe) {
    return sendMailboxError(MailboxErrorCode::kUnsupportedProtocol);
  }
  if (message->payload.size() < kCoeHeaderSize) {
    return sendMailboxError(MailboxErrorCode::kSizeTooShort);
  }
  const CoeHeader coe = CoeHeader::fromRaw(readLe16(message->payload, 0));
  const ConstBytes body = message->payload.subspan(kCoeHeaderSize);
  switch (coe.service) {
    case CoeService::kSdoRequest:
      return handleSdo(esc, body);
    case CoeService::kSdoInformation:
      if (options_.sdoInfo) return handleSdoInfo(esc, body);
      return sendMailboxError(MailboxErrorCode::kServiceNotSupported);
    default:
      return sendMailboxError(MailboxErrorCode::kServiceNotSupported);
  }
}

// ---- replies ---------------------------------------------------------------------------------

void CoeServer::sendMailboxError(MailboxErrorCode detail) {
  ++counters_.mailboxErrors;
  std::vector<std::uint8_t> message(kMailboxHeaderSize + kMailboxErrorSize, 0);
  auto n = encodeMailboxError(message, detail);
  if (!n.ok()) return;
  message.resize(*n);
  queue(std::move(message));
}

void CoeServer::sendSdo(const SdoResponse& response) {
  std::vector<std::uint8_t> message(std::max(mailboxSize_, kMinimumBuffer), 0);
  auto n = encodeSdoResponseMailbox(message, response);
  if (!n.ok()) return;
  message.resize(*n);
  queue(std::move(message));
}

// Goes out as CoE service 2, an SDO request, as real slaves send it (encodeSdoResponseMailbox;
// ETG.1000.6, SOES SDO_abort()): SOEM takes a service-3 abort for success.
void CoeServer::sendAbort(std::uint16_t index, std::uint8_t subindex, std::uint32_t abort) {
  ++counters_.aborts;
  sendSdo(SdoAbort{index, subindex, abort});
}

void CoeServer::sendSdoInfoError(std::uint32_t abort) {
  ++counters_.aborts;
  std::vector<std::uint8_t> message(kMinimumBuffer, 0);
  auto n = encodeSdoInfoResponseMailbox(message, SdoInfoError{abort});
  if (!n.ok()) return;
  message.resize(*n);
  queue(std::move(message));
}

void CoeServer::sendSdoInfo(SdoInfoOpcode opcode, ConstBytes serviceData) {
  auto fragmenter = SdoInfoFragmenter::create(opcode, serviceData, mailboxSize_);
  if (!fragmenter.ok()) return sendSdoInfoError(code(SdoAbortCode::kObjectLengthExceedsMailbox));
  for (std::size_t f = 0; f < fragmenter->fragmentCount(); ++f) {
    std::vector<std::uint8_t> message(mailboxSize_, 0);
    auto n = fragmenter->encodeFragment(f, message);
    if (!n.ok()) return;
    message.resize(*n);
    queue(std::move(message));
  }
}

// ---- SDO -------------------------------------------------------------------------------------

std::uint32_t CoeServer::store(Esc& esc, std::uint16_t index, std::uint8_t subindex,
                               bool completeAccess, ConstBytes data) {
  const AlState state = AlStateMachine::state(esc);
  if (!completeAccess && subindex >= 1 &&
      (index == kStoreParametersIndex || index == kRestoreDefaultsIndex)) {
    if (const Entry* e = od_->findEntry(index, subindex); e != nullptr && e->writable(state)) {
      return storeParameters(index, subindex, data);
    }
  }
  return completeAccess ? sdoWriteComplete(*od_, index, subindex, data, state)
                        : sdoWrite(*od_, index, subindex, data, state);
}

// CiA 301 §7.5.2.13/14: "save" (0x65766173) written to 0x1010:n, "load" (0x64616F6C) to
// 0x1011:n; sub 1 all parameters, 2 communication (0x1000-0x1FFF), 3 application
// (0x6000-0x9FFF), 4 and up manufacturer (0x2000-0x5FFF). The entry itself is not written (it
// reads the device's capabilities); any other value is refused.
std::uint32_t CoeServer::storeParameters(std::uint16_t index, std::uint8_t subindex,
                                         ConstBytes data) {
  constexpr std::uint32_t kSave = 0x65766173;
  constexpr std::uint32_t kLoad = 0x64616F6C;
  const std::uint32_t signature = index == kStoreParametersIndex ? kSave : kLoad;
  if (data.size() != 4 || readLe32(data, 0) != signature) {
    return code(SdoAbortCode::kDataCannotBeTransferred);
  }
  std::uint16_t first = 0x0000;
  std::uint16_t last = 0xFFFF;
  if (subindex == 2) {
    first = 0x1000;
    last = 0x1FFF;
  } else if (subindex == 3) {
    first = 0x6000;
    last = 0x9FFF;
  } else if (subindex >= 4) {
    first = 0x2000;
    last = 0x5FFF;
  }
  if (index == kStoreParametersIndex) {
    od_->storePowerUpValues(first, last);
  } else {
    od_->defaultPowerUpValues(first, last);
  }
  return kSdoOk;
}

void CoeServer::handleSdo(Esc& esc, ConstBytes body) {
  if (body.size() < kSdoMinBodySize) return sendMailboxError(MailboxErrorCode::kSizeTooShort);
  auto request = decodeSdoRequest(body);
  if (!request.ok()) {
    return sendAbort(readLe16(body, 1), body[3], code(SdoAbortCode::kInvalidCommandSpecifier));
  }
  std::visit(
      [&](const auto& r) {
        using T = std::decay_t<decltype(r)>;
        if constexpr (std::is_same_v<T, SdoInitiateUploadRequest>) {
          upload(esc, r);
        } else if constexpr (std::is_same_v<T, SdoUploadSegmentRequest>) {
          uploadSegment(esc, r);
        } else if constexpr (std::is_same_v<T, SdoInitiateDownloadRequest>) {
          download(esc, r);
        } else if constexpr (std::is_same_v<T, SdoDownloadSegmentRequest>) {
          downloadSegment(esc, r);
        } else {  // the master aborts: forget the transfer, no answer
          upload_ = {};
          download_ = {};
        }
      },
      *request);
}

void CoeServer::upload(Esc& esc, const SdoInitiateUploadRequest& r) {
  upload_ = {};
  download_ = {};
  const AlState state = AlStateMachine::state(esc);
  std::vector<std::uint8_t> data;
  std::uint32_t result = kSdoOk;
  if (r.completeAccess) {
    result = options_.completeAccess ? sdoReadComplete(*od_, r.index, r.subindex, state, data)
                                     : code(SdoAbortCode::kCompleteAccessNotSupported);
  } else {
    const Entry* entry = nullptr;
    result = sdoRead(*od_, r.index, r.subindex, state, &entry);
    if (result == kSdoOk) data = entry->value;
  }
  if (result != kSdoOk) return sendAbort(r.index, r.subindex, result);
  SdoInitiateUploadResponse response{r.index, r.subindex, r.completeAccess,
                                     false,   true,       static_cast<std::uint32_t>(data.size()),
                                     {}};
  if (!data.empty() && data.size() <= kSdoExpeditedMaxData) {
    response.expedited = true;
    response.data = data;
    return sendSdo(response);
  }
  const std::size_t capacity = sdoNormalDataCapacity(mailboxSize_);
  if (capacity == 0 || sdoSegmentDataCapacity(mailboxSize_) == 0) {
    return sendAbort(r.index, r.subindex, code(SdoAbortCode::kObjectLengthExceedsMailbox));
  }
  const std::size_t first = std::min(capacity, data.size());
  response.data = ConstBytes(data).first(first);
  sendSdo(response);
  if (first < data.size()) {
    upload_ = {true, r.index, r.subindex, std::move(data), first, false};
  }
}

void CoeServer::uploadSegment(Esc& /*esc*/, const SdoUploadSegmentRequest& r) {
  if (!upload_.active) return sendAbort(0, 0, code(SdoAbortCode::kInvalidCommandSpecifier));
  if (r.toggle != upload_.toggle) {
    const Upload failed = std::move(upload_);
    upload_ = {};
    return sendAbort(failed.index, failed.subindex, code(SdoAbortCode::kToggleBitNotAlternated));
  }
  const std::size_t n =
      std::min(sdoSegmentDataCapacity(mailboxSize_), upload_.data.size() - upload_.offset);
  const bool last = upload_.offset + n == upload_.data.size();
  sendSdo(SdoUploadSegmentResponse{r.toggle, last,
                                   ConstBytes(upload_.data).subspan(upload_.offset, n)});
  upload_.offset += n;
  upload_.toggle = !upload_.toggle;
  if (last) upload_ = {};
}

void CoeServer::download(Esc& esc, const SdoInitiateDownloadRequest& r) {
  upload_ = {};
  download_ = {};
  if (r.completeAccess && !options_.completeAccess) {
    return sendAbort(r.index, r.subindex, code(SdoAbortCode::kCompleteAccessNotSupported));
  }
  ConstBytes data = r.data;
  if (r.expedited && !r.sizeIndicated && !r.completeAccess) {
    // Size not indicated: the 4 bytes carry the object's value, as long as it is.
    if (const Entry* e = od_->findEntry(r.index, r.subindex); e != nullptr) {
      data = data.first(std::min(data.size(), e->byteSize()));
    }
  }
  if (r.expedited || data.size() >= r.completeSize) {
    if (!r.expedited) data = data.first(r.completeSize);
    const std::uint32_t result = store(esc, r.index, r.subindex, r.completeAccess, data);
    if (result != kSdoOk) return sendAbort(r.index, r.subindex, result);
    return sendSdo(SdoInitiateDownloadResponse{r.index, r.subindex, r.completeAccess});
  }
  // Segmented: refuse at once what cannot succeed.
  if (!r.completeAccess) {
    const Object* o = od_->find(r.index);
    const Entry* e = o == nullptr ? nullptr : o->entry(r.subindex);
    std::uint32_t result = kSdoOk;
    if (o == nullptr) {
      result = code(SdoAbortCode::kObjectDoesNotExist);
    } else if (e == nullptr) {
      result = code(SdoAbortCode::kSubindexDoesNotExist);
    } else if (!e->writableSomewhere()) {
      result = code(SdoAbortCode::kWriteOfReadOnly);
    } else if (!e->writable(AlStateMachine::state(esc))) {
      result = code(SdoAbortCode::kDataCannotBeTransferredDeviceState);
    } else if (r.completeSize > e->byteSize()) {
      result = code(SdoAbortCode::kDataTypeLengthTooHigh);
    }
    if (result != kSdoOk) return sendAbort(r.index, r.subindex, result);
  } else if (!od_->contains(r.index)) {
    return sendAbort(r.index, r.subindex, code(SdoAbortCode::kObjectDoesNotExist));
  }
  download_ = {true,           r.index,
               r.subindex,     r.completeAccess,
               r.completeSize, std::vector<std::uint8_t>(data.begin(), data.end()),
               false};
  sendSdo(SdoInitiateDownloadResponse{r.index, r.subindex, r.completeAccess});
}

void CoeServer::downloadSegment(Esc& esc, const SdoDownloadSegmentRequest& r) {
  if (!download_.active) return sendAbort(0, 0, code(SdoAbortCode::kInvalidCommandSpecifier));
  const Download current = download_;
  if (r.toggle != download_.toggle) {
    download_ = {};
    return sendAbort(current.index, current.subindex, code(SdoAbortCode::kToggleBitNotAlternated));
  }
  download_.data.insert(download_.data.end(), r.data.begin(), r.data.end());
  if (download_.data.size() > download_.completeSize) {
    download_ = {};
    return sendAbort(current.index, current.subindex, code(SdoAbortCode::kDataTypeLengthTooHigh));
  }
  if (!r.last) {
    download_.toggle = !download_.toggle;
    return sendSdo(SdoDownloadSegmentResponse{r.toggle});
  }
  Download done = std::move(download_);
  download_ = {};
  if (done.data.size() != done.completeSize) {
    return sendAbort(done.index, done.subindex, code(SdoAbortCode::kDataTypeMismatch));
  }
  const std::uint32_t result =
      store(esc, done.index, done.subindex, done.completeAccess, done.data);
  if (result != kSdoOk) return sendAbort(done.index, done.subindex, result);
  sendSdo(SdoDownloadSegmentResponse{r.toggle});
}

// ---- SDO information -------------------------------------------------------------------------

void CoeServer::handleSdoInfo(Esc& /*esc*/, ConstBytes body) {
  auto header = SdoInfoHeader::decode(body);
  if (!header.ok() || body.size() < kSdoInfoHeaderSize) {
    return sendMailboxError(MailboxErrorCode::kSizeTooShort);
  }
  const ConstBytes data = body.subspan(kSdoInfoHeaderSize);
  const std::uint32_t malformed = code(SdoAbortCode::kInvalidCommandSpecifier);
  switch (header->opcode) {
    case SdoInfoOpcode::kGetOdListRequest: {
      auto request = OdListRequest::decode(data);
      if (!request.ok()) return sendSdoInfoError(malformed);
      OdList list;
      list.listType = request->listType;
      auto matches = [](const Object& o, std::uint16_t type) {
        std::uint16_t bits = 0;
        for (const auto& e : o.entries) bits |= e.access;
        switch (static_cast<OdListType>(type)) {
          case OdListType::kAll:
            return true;
          case OdListType::kRxPdoMappable:
            return (bits & kAccessRxPdoMappable) != 0;
          case OdListType::kTxPdoMappable:
            return (bits & kAccessTxPdoMappable) != 0;
          case OdListType::kBackup:
            return (bits & kAccessBackup) != 0;
          case OdListType::kSettings:
            return (bits & kAccessSettings) != 0;
          default:
            return false;
        }
      };
      if (list.listType == static_cast<std::uint16_t>(OdListType::kLengths)) {
        for (std::uint16_t type = 1; type <= 5; ++type) {
          std::uint16_t count = 0;
          for (const auto& [index, o] : od_->objects())
            if (matches(o, type)) ++count;
          list.indexes.push_back(count);
        }
      } else if (list.listType >= 1 && list.listType <= 5) {
        for (const auto& [index, o] : od_->objects()) {
          if (matches(o, list.listType)) list.indexes.push_back(index);
        }
      } else {
        return sendSdoInfoError(code(SdoAbortCode::kValueRangeExceeded));
      }
      std::vector<std::uint8_t> bytes(list.encodedSize());
      if (!list.encode(bytes).ok()) return sendSdoInfoError(code(SdoAbortCode::kGeneralError));
      return sendSdoInfo(SdoInfoOpcode::kGetOdListResponse, bytes);
    }
    case SdoInfoOpcode::kGetObjectDescriptionRequest: {
      auto request = ObjectDescriptionRequest::decode(data);
      if (!request.ok()) return sendSdoInfoError(malformed);
      const Object* o = od_->find(request->index);
      if (o == nullptr) return sendSdoInfoError(code(SdoAbortCode::kObjectDoesNotExist));
      ObjectDescription d{o->index, o->dataType, o->maxSubindex(),
                          static_cast<std::uint8_t>(o->code), o->name};
      std::vector<std::uint8_t> bytes(d.encodedSize());
      if (!d.encode(bytes).ok()) return sendSdoInfoError(code(SdoAbortCode::kGeneralError));
      return sendSdoInfo(SdoInfoOpcode::kGetObjectDescriptionResponse, bytes);
    }
    case SdoInfoOpcode::kGetEntryDescriptionRequest: {
      auto request = EntryDescriptionRequest::decode(data);
      if (!request.ok()) return sendSdoInfoError(malformed);
      const Object* o = od_->find(request->index);
      if (o == nullptr) return sendSdoInfoError(code(SdoAbortCode::kObjectDoesNotExist));
      const Entry* e = o->entry(request->subindex);
      if (e == nullptr) return sendSdoInfoError(code(SdoAbortCode::kSubindexDoesNotExist));
      EntryDescription d;
      d.index = o->index;
      d.subindex = e->subindex;
      d.valueInfo = request->valueInfo;
      d.dataType = e->dataType;
      d.bitLength = e->bitLength;
      d.objectAccess = e->access;
      if ((d.valueInfo & kValueInfoDefault) != 0) d.defaultValue = e->defaultValue;
      if ((d.valueInfo & kValueInfoMinimum) != 0) {
        if (e->minimum.empty()) d.valueInfo &= static_cast<std::uint8_t>(~kValueInfoMinimum);
        d.minimumValue = e->minimum;
      }
      if ((d.valueInfo & kValueInfoMaximum) != 0) {
        if (e->maximum.empty()) d.valueInfo &= static_cast<std::uint8_t>(~kValueInfoMaximum);
        d.maximumValue = e->maximum;
      }
      d.name = e->name;
      std::vector<std::uint8_t> bytes(d.encodedSize());
      if (!d.encode(bytes).ok()) return sendSdoInfoError(code(SdoAbortCode::kGeneralError));
      return sendSdoInfo(SdoInfoOpcode::kGetEntryDescriptionResponse, bytes);
    }
    default:
      return sendSdoInfoError(malformed);
  }
}

}  // namespace ecsim::slavesim::coe
