#include "master/coe_client.hpp"

#include <algorithm>
#include <cstdio>

namespace ecsim::master {
namespace {

std::string hex(std::uint32_t v, int digits) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%0*X", digits, v);
  return buf;
}

}  // namespace

std::string describeSdoAbort(std::uint32_t code) {
  return hex(code, 8) + " (" + std::string(sdoAbortText(code)) + ")";
}

// ---- SdoTask ----------------------------------------------------------------------------------

SdoTask::SdoTask(Transport& transport, SlaveInfo& slave,
                 std::vector<ReceivedEmergency>* emergencies, MailboxOptions options)
    : exchange_(transport, slave, emergencies, options), slave_(slave) {}

std::string SdoTask::object() const {
  return hex(index_, 4) + ":" + hex(subindex_, 2).substr(2) +
         (completeAccess_ ? " (complete)" : "");
}

bool SdoTask::fail(ErrorCode code, const std::string& what) {
  status_ =
      makeError(code, std::string(upload_ ? "SDO upload of " : "SDO download of ") + object() +
                          (upload_ ? " from " : " to ") + slave_.label() + ": " + what);
  state_ = State::kDone;
  return false;
}

Status SdoTask::send(const SdoRequest& request, SimTime now) {
  if (!slave_.mailbox) {
    return makeError(ErrorCode::kUnsupported, slave_.label() + " has no mailbox");
  }
  message_.assign(slave_.mailbox->outSize, 0);
  auto n = encodeSdoRequestMailbox(message_, request);
  if (!n.ok()) return n.takeError();
  return exchange_.start(ConstBytes(message_.data(), *n), now);
}

Status SdoTask::startUpload(std::uint16_t index, std::uint8_t subindex, bool completeAccess,
                            SimTime now) {
  index_ = index;
  subindex_ = subindex;
  completeAccess_ = completeAccess;
  upload_ = true;
  expedited_ = false;
  data_.clear();
  abortCode_.reset();
  segments_ = 0;
  completeSize_ = 0;
  status_ = okStatus();
  ECSIM_TRY(send(SdoInitiateUploadRequest{index, subindex, completeAccess}, now));
  state_ = State::kUploadInitiate;
  return okStatus();
}

Status SdoTask::startDownload(std::uint16_t index, std::uint8_t subindex, ConstBytes data,
                              bool completeAccess, SimTime now) {
  index_ = index;
  subindex_ = subindex;
  completeAccess_ = completeAccess;
  upload_ = false;
  abortCode_.reset();
  segments_ = 0;
  status_ = okStatus();
  if (data.empty()) return makeError(ErrorCode::kInvalidArgument, "SDO download of no data");
  if (!slave_.mailbox) {
    return makeError(ErrorCode::kUnsupported, slave_.label() + " has no mailbox");
  }
  data_.assign(data.begin(), data.end());
  completeSize_ = static_cast<std::uint32_t>(data_.size());
  SdoInitiateDownloadRequest request;
  request.index = index;
  request.subindex = subindex;
  request.completeAccess = completeAccess;
  request.sizeIndicated = true;
  request.completeSize = completeSize_;
  expedited_ = !completeAccess && data_.size() <= kSdoExpeditedMaxData;
  request.expedited = expedited_;
  offset_ = expedited_ ? data_.size()
                       : std::min(data_.size(), sdoNormalDataCapacity(slave_.mailbox->outSize));
  request.data = ConstBytes(data_.data(), offset_);
  ECSIM_TRY(send(request, now));
  state_ = State::kDownloadInitiate;
  return okStatus();
}

bool SdoTask::sendNextSegment(SimTime now) {
  const std::size_t capacity = sdoSegmentDataCapacity(slave_.mailbox->outSize);
  const std::size_t chunk = std::min(data_.size() - offset_, capacity);
  SdoDownloadSegmentRequest request;
  request.toggle = toggle_;
  request.last = offset_ + chunk == data_.size();
  request.data = ConstBytes(data_.data() + offset_, chunk);
  offset_ += chunk;
  ++segments_;
  if (auto s = send(request, now); !s.ok()) return fail(s.error().code, s.error().context);
  state_ = State::kDownloadSegment;
  return true;
}

bool SdoTask::onResponse(const SdoResponse& response, SimTime now) {
  if (const auto* abort = std::get_if<SdoAbort>(&response)) {
    abortCode_ = abort->abortCode;
    return fail(ErrorCode::kAborted, "abort " + describeSdoAbort(abort->abortCode));
  }
  switch (state_) {
    case State::kUploadInitiate: {
      const auto* r = std::get_if<SdoInitiateUploadResponse>(&response);
      if (r == nullptr) return fail(ErrorCode::kMalformed, "unexpected response to initiate");
      if (r->index != index_) {
        return fail(ErrorCode::kMalformed, "response names object " + hex(r->index, 4));
      }
      data_.assign(r->data.begin(), r->data.end());
      expedited_ = r->expedited;
      if (r->expedited) {
        state_ = State::kDone;
        return false;
      }
      completeSize_ = r->completeSize;
      if (data_.size() >= completeSize_) {
        data_.resize(completeSize_);
        state_ = State::kDone;
        return false;
      }
      toggle_ = false;
      if (auto s = send(SdoUploadSegmentRequest{toggle_}, now); !s.ok()) {
        return fail(s.error().code, s.error().context);
      }
      state_ = State::kUploadSegment;
      return true;
    }
    case State::kUploadSegment: {
      const auto* r = std::get_if<SdoUploadSegmentResponse>(&response);
      if (r == nullptr) return fail(ErrorCode::kMalformed, "unexpected response to a segment");
      if (r->toggle != toggle_) return fail(ErrorCode::kMalformed, "toggle bit not alternated");
      data_.insert(data_.end(), r->data.begin(), r->data.end());
      ++segments_;
      if (r->last || data_.size() >= completeSize_) {
        if (data_.size() > completeSize_) data_.resize(completeSize_);
        if (data_.size() < completeSize_) {
          return fail(ErrorCode::kTruncated, "last segment after " + std::to_string(data_.size()) +
                                                 " of " + std::to_string(completeSize_) + " bytes");
        }
        state_ = State::kDone;
        return false;
      }
      toggle_ = !toggle_;
      if (auto s = send(SdoUploadSegmentRequest{toggle_}, now); !s.ok()) {
        return fail(s.error().code, s.error().context);
      }
      return true;
    }
    case State::kDownloadInitiate: {
      const auto* r = std::get_if<SdoInitiateDownloadResponse>(&response);
      if (r == nullptr) return fail(ErrorCode::kMalformed, "unexpected response to initiate");
      if (r->index != index_) {
        return fail(ErrorCode::kMalformed, "response names object " + hex(r->index, 4));
      }
      if (offset_ >= data_.size()) {
        state_ = State::kDone;
        return false;
      }
      toggle_ = false;
      return sendNextSegment(now);
    }
    case State::kDownloadSegment: {
      const auto* r = std::get_if<SdoDownloadSegmentResponse>(&response);
      if (r == nullptr) return fail(ErrorCode::kMalformed, "unexpected response to a segment");
      if (r->toggle != toggle_) return fail(ErrorCode::kMalformed, "toggle bit not alternated");
      toggle_ = !toggle_;
      if (offset_ >= data_.size()) {
        state_ = State::kDone;
        return false;
      }
      return sendNextSegment(now);
    }
    case State::kIdle:
    case State::kDone:
      break;
  }
  return false;
}

bool SdoTask::step(SimTime now) {
  if (state_ == State::kIdle || state_ == State::kDone) return false;
  if (exchange_.step(now)) return true;
  if (!exchange_.status().ok()) {
    return fail(exchange_.status().error().code, exchange_.status().error().context);
  }
  auto message = decodeSdoResponseMailbox(exchange_.response());
  if (!message.ok()) {
    return fail(ErrorCode::kMalformed, "response: " + message.error().context);
  }
  return onResponse(message->sdo, now);
}

// ---- SdoInfoTask ------------------------------------------------------------------------------

SdoInfoTask::SdoInfoTask(Transport& transport, SlaveInfo& slave,
                         std::vector<ReceivedEmergency>* emergencies, MailboxOptions options)
    : exchange_(transport, slave, emergencies, options), slave_(slave) {}

bool SdoInfoTask::fail(ErrorCode code, const std::string& what) {
  status_ = makeError(code, "SDO information (" + what_ + ") from " + slave_.label() + ": " + what);
  done_ = true;
  return false;
}

Status SdoInfoTask::send(const SdoInfoRequest& request, std::string what, SimTime now) {
  what_ = std::move(what);
  status_ = okStatus();
  response_.reset();
  reassembler_.reset();
  fragments_ = 0;
  if (!slave_.mailbox) {
    return makeError(ErrorCode::kUnsupported, slave_.label() + " has no mailbox");
  }
  message_.assign(slave_.mailbox->outSize, 0);
  auto n = encodeSdoInfoRequestMailbox(message_, request);
  if (!n.ok()) return n.takeError();
  ECSIM_TRY(exchange_.start(ConstBytes(message_.data(), *n), now));
  done_ = false;
  return okStatus();
}

Status SdoInfoTask::startOdList(OdListType type, SimTime now) {
  return send(OdListRequest{static_cast<std::uint16_t>(type)}, "OD list", now);
}

Status SdoInfoTask::startObjectDescription(std::uint16_t index, SimTime now) {
  return send(ObjectDescriptionRequest{index}, "object " + hex(index, 4), now);
}

Status SdoInfoTask::startEntryDescription(std::uint16_t index, std::uint8_t subindex,
                                          std::uint8_t valueInfo, SimTime now) {
  return send(EntryDescriptionRequest{index, subindex, valueInfo},
              "entry " + hex(index, 4) + ":" + hex(subindex, 2).substr(2), now);
}

bool SdoInfoTask::step(SimTime now) {
  if (done_) return false;
  if (exchange_.step(now)) return true;
  if (!exchange_.status().ok()) {
    return fail(exchange_.status().error().code, exchange_.status().error().context);
  }
  auto fragment = decodeSdoInfoMailbox(exchange_.response());
  if (!fragment.ok()) return fail(ErrorCode::kMalformed, fragment.error().context);
  if (auto added = reassembler_.add(*fragment); !added.ok()) {
    return fail(ErrorCode::kMalformed, added.error().context);
  }
  ++fragments_;
  if (!reassembler_.complete()) {
    if (auto s = exchange_.startReceive(now); !s.ok())
      return fail(s.error().code, s.error().context);
    return true;
  }
  auto response = decodeSdoInfoResponse(reassembler_.opcode(), reassembler_.data());
  if (!response.ok()) return fail(ErrorCode::kMalformed, response.error().context);
  if (const auto* error = std::get_if<SdoInfoError>(&*response)) {
    return fail(ErrorCode::kAborted, "error " + describeSdoAbort(error->abortCode));
  }
  response_ = std::move(response).value();
  done_ = true;
  return false;
}

}  // namespace ecsim::master
