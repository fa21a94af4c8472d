// CoE client (ETG.1000.6 §5.6.2-5.6.3) over MailboxExchange, as non-blocking state machines:
//
//   SdoTask      upload and download of one object entry (or, with complete access, of a
//                whole object from subindex 0 or 1): expedited for up to 4 bytes, normal when
//                the data fits one mailbox, segmented beyond (toggle bit checked); an abort
//                from the slave ends the transfer with its code and text
//   SdoInfoTask  SDO information: OD list, object description, entry description; responses
//                split over several mailboxes are reassembled
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "master/mailbox_exchange.hpp"
#include "protocol/sdo.hpp"
#include "protocol/sdo_info.hpp"

namespace ecsim::master {

// "0x06020000 (Object does not exist)"
std::string describeSdoAbort(std::uint32_t code);

class SdoTask final : public Task {
 public:
  SdoTask(Transport& transport, SlaveInfo& slave, std::vector<ReceivedEmergency>* emergencies,
          MailboxOptions options = {});

  Status startUpload(std::uint16_t index, std::uint8_t subindex, bool completeAccess, SimTime now);
  Status startDownload(std::uint16_t index, std::uint8_t subindex, ConstBytes data,
                       bool completeAccess, SimTime now);

  bool step(SimTime now) override;
  std::optional<SimTime> wakeAt() const override { return exchange_.wakeAt(); }
  bool done() const { return state_ == State::kDone; }
  // kAborted with the abort code and its text when the slave aborted; the context names the
  // slave and the object.
  const Status& status() const { return status_; }
  std::optional<std::uint32_t> abortCode() const { return abortCode_; }
  const std::vector<std::uint8_t>& data() const { return data_; }  // uploaded bytes
  std::uint64_t segments() const { return segments_; }
  bool expedited() const { return expedited_; }
  // Mailbox repeat requests made for lost responses.
  std::uint64_t repeats() const { return exchange_.repeats(); }

 private:
  enum class State {
    kIdle,
    kUploadInitiate,
    kUploadSegment,
    kDownloadInitiate,
    kDownloadSegment,
    kDone
  };

  Status send(const SdoRequest& request, SimTime now);
  bool fail(ErrorCode code, const std::string& what);
  bool onResponse(const SdoResponse& response, SimTime now);
  bool sendNextSegment(SimTime now);
  std::string object() const;

  MailboxExchange exchange_;
  SlaveInfo& slave_;
  State state_{State::kIdle};
  Status status_;
  std::uint16_t index_{0};
  std::uint8_t subindex_{0};
  bool completeAccess_{false};
  bool upload_{true};
  bool toggle_{false};
  bool expedited_{false};
  std::uint32_t completeSize_{0};
  std::size_t offset_{0};
  std::vector<std::uint8_t> data_;
  std::vector<std::uint8_t> message_;
  std::optional<std::uint32_t> abortCode_;
  std::uint64_t segments_{0};
};

class SdoInfoTask final : public Task {
 public:
  SdoInfoTask(Transport& transport, SlaveInfo& slave, std::vector<ReceivedEmergency>* emergencies,
              MailboxOptions options = {});

  Status startOdList(OdListType type, SimTime now);
  Status startObjectDescription(std::uint16_t index, SimTime now);
  Status startEntryDescription(std::uint16_t index, std::uint8_t subindex, std::uint8_t valueInfo,
                               SimTime now);

  bool step(SimTime now) override;
  std::optional<SimTime> wakeAt() const override { return exchange_.wakeAt(); }
  bool done() const { return done_; }
  // kAborted with the SDO-information error code and its text.
  const Status& status() const { return status_; }
  const std::optional<SdoInfoResponse>& response() const { return response_; }
  std::size_t fragments() const { return fragments_; }

 private:
  Status send(const SdoInfoRequest& request, std::string what, SimTime now);
  bool fail(ErrorCode code, const std::string& what);

  MailboxExchange exchange_;
  SlaveInfo& slave_;
  Status status_;
  bool done_{true};
  std::string what_;
  SdoInfoReassembler reassembler_;
  std::optional<SdoInfoResponse> response_;
  std::vector<std::uint8_t> message_;
  std::size_t fragments_{0};
};

}  // namespace ecsim::master
