// CoE mailbox server (ETG.1000.6 §5.6): answers the SDO and SDO-information requests a master
// writes into SM0 with responses in SM1, and sends emergencies queued by the device.
//
//   - mailbox header: a type other than CoE gets a mailbox error reply "unsupported protocol"
//     (0x0002), a length running past SM0 "invalid size" (0x0008), a CoE body too short for
//     its service "size too short" (0x0006), an unsupported CoE service "service not
//     supported" (0x0004);
//   - mailbox counter (ETG.1000.4 §5.6): a request carrying the same non-zero counter and the
//     same bytes as the previous one is a retry: its response(s) are sent again, it is not
//     executed again;
//   - SDO upload: expedited with the entry's real size (1 byte 0x4F, 2 bytes 0x4B, 3 bytes
//     0x47, 4 bytes 0x43), normal above 4 bytes with as much data as SM1 holds, segmented
//     for the rest (toggle starts at 0, a wrong toggle aborts with 0x05030000);
//   - SDO download: expedited, normal and segmented the same way;
//   - complete access on any ARRAY/RECORD (sdo_access.hpp), or abort 0x06010004 when the
//     device does not support it (ESI <CoE CompleteAccess>);
//   - SDO information: OD list (all types, fragmented over SM1-sized mailboxes), object
//     description, entry description (value info bits 3-6 add unit/default/min/max; SOEM
//     asks with 0x07 and gets the name right after the access word);
//   - emergencies: pushEmergency() queues; queued messages go out one at a time whenever SM1
//     is free (responses and emergencies in the order they were queued).
//   - store / restore parameters (CiA 301 0x1010 / 0x1011, when the dictionary has them):
//     "save" / "load" written to sub n makes the current values / the defaults the power-up
//     values of the objects that sub covers (ObjectDictionary::storePowerUpValues), so they
//     survive (or are reset by) the next power cycle; another value aborts 0x08000020.
//   - other protocols (FoE, EoE, SoE: slavesim/mailbox_protocol.hpp) are added with
//     addProtocol(); their requests reach them through the same counter, retry and queue.
// When the mailbox SyncManagers are switched off (INIT, a master resetting the slave) every
// pending transfer, queued message and the retry memory are dropped.
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <vector>

#include "protocol/coe.hpp"
#include "protocol/mailbox.hpp"
#include "protocol/sdo.hpp"
#include "slavesim/coe/object_dictionary.hpp"
#include "slavesim/mailbox_protocol.hpp"
#include "slavesim/slave.hpp"

namespace ecsim::slavesim::coe {

struct CoeServerOptions {
  // false: the device has a mailbox without CoE; every request, CoE included, gets the
  // "unsupported protocol" mailbox error.
  bool coe{true};
  bool sdoInfo{true};
  bool completeAccess{true};
  std::size_t maxQueuedMessages{64};  // further emergencies are dropped (counted)
};

struct CoeServerCounters {
  std::uint64_t requests{0};
  std::uint64_t repeatedRequests{0};
  std::uint64_t aborts{0};
  std::uint64_t mailboxErrors{0};
  std::uint64_t emergenciesSent{0};
  std::uint64_t emergenciesDropped{0};
};

class CoeServer final : public MailboxServer, private MailboxReplies {
 public:
  explicit CoeServer(std::shared_ptr<ObjectDictionary> od, CoeServerOptions options = {});

  // Answers the requests of protocol->type() from now on (one protocol per type; a second one
  // for the same type replaces the first).
  void addProtocol(std::unique_ptr<MailboxProtocol> protocol);
  // The protocol answering `type`, or null.
  MailboxProtocol* protocol(MailboxType type);

  void onRequest(Esc& esc, ConstBytes mailbox, SimTime now) override;
  void poll(Esc& esc, SimTime now) override;

  // Queues an emergency (CoE service 1) for the master.
  void pushEmergency(const Emergency& emergency);

  ObjectDictionary& dictionary() { return *od_; }
  const CoeServerOptions& options() const { return options_; }
  const CoeServerCounters& counters() const { return counters_; }
  std::size_t queuedMessages() const override { return outbox_.size(); }

 private:
  struct Upload {
    bool active{false};
    std::uint16_t index{0};
    std::uint8_t subindex{0};
    std::vector<std::uint8_t> data;
    std::size_t offset{0};
    bool toggle{false};  // expected in the next segment request
  };
  struct Download {
    bool active{false};
    std::uint16_t index{0};
    std::uint8_t subindex{0};
    bool completeAccess{false};
    std::uint32_t completeSize{0};
    std::vector<std::uint8_t> data;
    bool toggle{false};
  };

  // MailboxReplies, for the added protocols.
  void send(std::vector<std::uint8_t> message) override { queue(std::move(message)); }
  std::size_t mailboxSize() const override { return mailboxSize_; }

  void handle(Esc& esc, ConstBytes mailbox, SimTime now);
  void handleSdo(Esc& esc, ConstBytes body);
  void handleSdoInfo(Esc& esc, ConstBytes body);
  void upload(Esc& esc, const SdoInitiateUploadRequest& request);
  void uploadSegment(Esc& esc, const SdoUploadSegmentRequest& request);
  void download(Esc& esc, const SdoInitiateDownloadRequest& request);
  void downloadSegment(Esc& esc, const SdoDownloadSegmentRequest& request);
  std::uint32_t store(Esc& esc, std::uint16_t index, std::uint8_t subindex, bool completeAccess,
                      ConstBytes data);
  std::uint32_t storeParameters(std::uint16_t index, std::uint8_t subindex, ConstBytes data);

  void sendAbort(std::uint16_t index, std::uint8_t subindex, std::uint32_t code);
  void sendSdo(const SdoResponse& response);
  void sendMailboxError(MailboxErrorCode code);
  void sendSdoInfoError(std::uint32_t code);
  void sendSdoInfo(SdoInfoOpcode opcode, ConstBytes serviceData);
  // Queues a complete mailbox message (its header counter is set here).
  void queue(std::vector<std::uint8_t> message);
  void trySend(Esc& esc);
  void reset();

  std::shared_ptr<ObjectDictionary> od_;
  CoeServerOptions options_;
  std::vector<std::unique_ptr<MailboxProtocol>> protocols_;
  CoeServerCounters counters_{};
  std::deque<std::vector<std::uint8_t>> outbox_;
  std::size_t mailboxSize_{0};  // SM1 length of the request being handled
  std::uint8_t responseCounter_{0};
  // Retry detection: the previous request and what it produced.
  std::vector<std::uint8_t> lastRequest_;
  std::vector<std::vector<std::uint8_t>> lastResponses_;
  bool recording_{false};
  bool mailboxWasAvailable_{false};
  Upload upload_;
  Download download_;
};

}  // namespace ecsim::slavesim::coe
