// FoE server (ETG.1000.6 §5.7) behind a slave's mailbox endpoint (MailboxProtocol, added to
// the slave's coe::CoeServer). Files live in a FoeFiles store shared with the device.
//
//   write  WRQ(password, name) -> ACK 0; DATA n -> ACK n; a DATA packet shorter than the data
//          one packet can carry through SM0 (its length - 12) ends the file, which is then
//          stored (a file written in BOOT becomes the firmware installed at the next power
//          cycle, foe_files.hpp). With busyResponses > 0 the first DATA packet is answered
//          with BUSY that many times (a bootloader erasing flash) and the master sends it
//          again.
//   read   RRQ(password, name) -> DATA 1 with as much as SM1 holds (its length - 12); ACK n ->
//          DATA n+1; the transfer ends with the ACK of the first packet shorter than that
//          (an empty one when the size is a multiple of it).
//   errors (ERR with the code and its text): unknown file on read 0x8001 (not found); a
//          password other than the configured one 0x800A (no rights, as SOES); a packet number
//          other than the expected 0x8005; DATA or ACK without a transfer, an unknown opcode
//          or an empty file name 0x8004 (illegal); a file beyond maxFileSize 0x8003 (disk
//          full; so is a file the host cannot write into the slave's FoE folder,
//          foe_folder.hpp); any FoE request outside BOOT on a device whose FoE lives only in its
//          bootloader (ESI BootStrap without Mailbox/FoE) 0x8008 (bootstrap only). An ERR from
//          the master ends the transfer without an answer.
// Each request gets at most one answer (the final ACK of a read none), so the endpoint's retry
// memory covers FoE too.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "protocol/foe.hpp"
#include "slavesim/coe/object_dictionary.hpp"
#include "slavesim/foe/foe_files.hpp"
#include "slavesim/mailbox_protocol.hpp"

namespace ecsim::slavesim::foe {

// A power cycle of a slave with FoE files: the image written in BOOT becomes the running
// firmware (FoeFiles::installPending) and the version it carries, if any, is what 0x100A
// reports (the object keeps its name and access; its length follows the text).
// An error: the folder the files are kept in could not record it (foe_folder.hpp).
Status installFirmware(FoeFiles& files, coe::ObjectDictionary& od);

struct FoeServerOptions {
  bool outsideBoot{true};  // FoE also in PREOP, SAFEOP and OP (ESI Mailbox/FoE)
  std::uint32_t password{0};
  std::size_t maxFileSize{kMaxFoeFileBytes};
  unsigned busyResponses{0};
};

struct FoeServerCounters {
  std::uint64_t filesWritten{0};
  std::uint64_t filesRead{0};
  std::uint64_t errorsSent{0};
  std::uint64_t busySent{0};
};

class FoeServer final : public MailboxProtocol {
 public:
  explicit FoeServer(std::shared_ptr<FoeFiles> files, FoeServerOptions options = {});

  MailboxType type() const override { return MailboxType::kFoe; }
  void onMessage(Esc& esc, const MailboxMessage& message, MailboxReplies& replies,
                 SimTime now) override;
  void reset() override;

  FoeFiles& files() { return *files_; }
  std::shared_ptr<FoeFiles> sharedFiles() { return files_; }
  const FoeServerOptions& options() const { return options_; }
  const FoeServerCounters& counters() const { return counters_; }

 private:
  enum class Transfer { kIdle, kWriting, kReading };

  void onWriteRequest(const Esc& esc, const FoePacket& p, MailboxReplies& replies);
  void onReadRequest(const Esc& esc, const FoePacket& p, MailboxReplies& replies);
  void onData(const Esc& esc, const FoePacket& p, MailboxReplies& replies);
  void onAck(const FoePacket& p, MailboxReplies& replies);
  void sendData(MailboxReplies& replies);
  void sendError(MailboxReplies& replies, FoeErrorCode code);

  std::shared_ptr<FoeFiles> files_;
  FoeServerOptions options_;
  FoeServerCounters counters_{};
  Transfer transfer_{Transfer::kIdle};
  std::string name_;
  FoeFile writing_;                         // write: the bytes taken so far
  std::shared_ptr<const FoeFile> reading_;  // read: the file being sent
  std::vector<std::uint8_t> packetData_;    // read: one packet's bytes (kept, not reallocated)
  std::uint32_t packet_{0};                 // last packet acknowledged (write) or sent (read)
  std::size_t offset_{0};                   // read: bytes sent so far
  bool lastSent_{false};                    // read: the final (short) packet is out
  bool writingInBoot_{false};
  unsigned busyLeft_{0};
};

}  // namespace ecsim::slavesim::foe
