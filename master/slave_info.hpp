// What the master knows about one slave after the scan: where it is, its ESC, its link
// status, its state and its SII (identity, name, mailbox, categories), plus the little
// run-time state the master keeps per slave (the mailbox counter).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "protocol/al_status.hpp"
#include "protocol/registers.hpp"
#include "protocol/result.hpp"
#include "protocol/sii.hpp"

namespace ecsim::master {

// The standard mailbox as the master programs it into SM0 (master -> slave) and SM1.
struct MailboxConfig {
  std::uint16_t outStart{0};
  std::uint16_t outSize{0};
  std::uint8_t outControl{0x26};  // mailbox, ECAT write, PDI interrupt (SOEM's default)
  std::uint16_t inStart{0};
  std::uint16_t inSize{0};
  std::uint8_t inControl{0x22};  // mailbox, ECAT read, PDI interrupt
  std::uint16_t protocols{0};    // SiiMailboxProtocol bits
};

struct SlaveInfo {
  std::size_t position{0};   // 0 = the slave next to the master
  std::uint16_t station{0};  // configured station address (0x1001 + position)
  std::uint16_t alias{0};    // 0x0012
  // Explicit Device ID (ETG.1020 §22.2.2): what the slave showed in 0x0134, with AL status
  // bit 5 and no error, for the ID request of the scan's reset; nullopt when it showed none
  // (no such ID, or its firmware did not take the request within ScanOptions::identifyWait).
  std::optional<std::uint16_t> deviceId;
  // ESC information (0x0000-0x0009)
  std::uint8_t escType{0};
  std::uint8_t escRevision{0};
  std::uint16_t escBuild{0};
  std::uint8_t fmmuCount{0};
  std::uint8_t syncManagerCount{0};
  std::uint8_t ramKb{0};
  std::uint8_t portDescriptor{0};
  std::uint16_t features{0};
  // Link and topology
  std::uint16_t dlStatus{0};
  std::uint8_t activePorts{0};  // bit n: port n has communication
  int parent{-1};               // position of the slave towards the master; -1: the master
  // Application layer, as last read
  std::uint16_t alStatus{0};
  std::uint16_t alStatusCode{0};
  // SII
  bool siiReads8Bytes{false};
  std::vector<std::uint8_t> sii;  // the bytes read, header and categories up to END
  SiiContents siiContents;
  std::optional<Error> siiDamage;  // the category scan stopped here (lenient parse)
  std::string name;
  // The name the configuration gives the slave (a topology's or ENI's slave name, "Drive1"),
  // empty when none does: variables, events and messages use it before the SII's.
  std::string configuredName;
  std::optional<MailboxConfig> mailbox;
  // While the slave is in BOOT (Master::enterBootstrap) `mailbox` is the bootstrap layout and
  // this the standard one to go back to.
  std::optional<MailboxConfig> standardMailbox;
  // Run-time
  std::uint8_t mailboxCounter{0};  // last counter used (1..7)

  const SiiIdentity& identity() const { return siiContents.identity; }
  bool hasDc() const { return (features & reg::features::kDistributedClocks) != 0; }
  bool hasCoe() const { return mailbox && (mailbox->protocols & SiiMailboxProtocol::kCoe) != 0; }
  std::uint8_t coeDetails() const {
    return siiContents.general ? siiContents.general->coeDetails : 0;
  }
  std::optional<AlState> state() const { return alStateFromRaw(alStatus); }
  bool alError() const { return (alStatus & kAlErrorFlag) != 0; }
  // configuredName, else the SII's name.
  const std::string& displayName() const { return configuredName.empty() ? name : configuredName; }
  // "slave 2 (0x1003 'DO1')", by displayName().
  std::string label() const;
};

// "PREOP", "SAFEOP+ERROR", "0x0005" for a raw value that names no state.
std::string describeAlStatus(std::uint16_t alStatus);
// "0x001D (Invalid output configuration)"
std::string describeAlStatusCode(std::uint16_t code);
// The Explicit Device ID an AL status/status code pair carries (ETG.1020 §22.2.2: bit 5 set
// and no error flag, the ID in 0x0134); nullopt otherwise (an ESC in device emulation copies
// the request bit into AL status with the error flag, and so shows none).
std::optional<std::uint16_t> explicitDeviceId(std::uint16_t alStatus, std::uint16_t alStatusCode);
// "vendor 0x00000E5C product 0x00001008 revision 0x00010000"
std::string describeIdentity(const SiiIdentity& identity);

}  // namespace ecsim::master
