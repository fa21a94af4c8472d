// The EtherCAT state machine (ESM) as slave firmware runs it (ETG.1000.6 §6.4, ESC datasheet
// section I §10): it reacts to AL control writes, checks the SyncManager configuration a
// master made against what the device needs, and reports refusals with an AL status code.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "protocol/al_status.hpp"
#include "slavesim/esc.hpp"

namespace ecsim::slavesim {

// What the firmware expects of the master's configuration.
struct SlaveProfile {
  struct Mailbox {
    std::uint16_t outStart{0};  // master -> slave (SM0)
    std::uint16_t outSize{0};
    std::uint16_t inStart{0};  // slave -> master (SM1)
    std::uint16_t inSize{0};
  };
  std::optional<Mailbox> mailbox;           // standard mailbox, if the device has one
  std::optional<Mailbox> bootstrapMailbox;  // BOOT state supported when present
  struct ProcessDataSm {
    unsigned index{2};
    bool outputs{true};       // ECAT write direction
    std::uint16_t length{0};  // expected byte length for the active PDO assignment
  };
  std::vector<ProcessDataSm> processData;
  // Synchronisation (ETG.1020 §6; 0x1C32 SM output parameter).
  struct Sync {
    bool dcSupported{false};  // the device has DC operation modes (ESI Dc, SII DC category)
    // 0x1C32:01 sync mode now and as the device started; a value the master changed in PREOP
    // is checked against the cyclic unit's activation (0 free run, 1 SM, 2 DC SYNC0,
    // 3 DC SYNC1). kNoSyncObject: the device has no 0x1C32.
    std::uint16_t mode{kNoSyncObject};
    std::uint16_t initialMode{kNoSyncObject};
    std::uint32_t minCycleNs{0};  // 0x1C32:05, 0 = not given
  };
  static constexpr std::uint16_t kNoSyncObject = 0xFFFF;
  Sync sync;
  // Explicit Device ID (ETG.1020 §22.2.2; ESI Info/IdentificationReg134): the ID (an ID
  // switch's value) the firmware shows in 0x0134, with AL status bit 5, while AL control bit 5
  // requests it. nullopt: the device has none and ignores the request.
  std::optional<std::uint16_t> explicitDeviceId;
  // The ID kept at an address of the process memory instead (ESI Info/IdentificationAdo: an
  // EK1101's ESC, in digital I/O mode without a microcontroller, samples the ID switch into
  // 0x1000): written there through the PDI when the slave starts and at every power-up.
  struct AdoDeviceId {
    std::uint16_t address{0};
    std::uint16_t value{0};
  };
  std::optional<AdoDeviceId> adoDeviceId;
};

class AlStateMachine {
 public:
  // Handles a pending AL control write. `profile` gives the current expectations (PDO
  // assignment may change in PREOP, so the caller passes the up-to-date profile).
  void onAlControl(Esc& esc, const SlaveProfile& profile);

  // Local error raised by the firmware (SM watchdog, sync error...): drops to `state` with
  // the error flag and the code, as ETG.1000.6 Table 11 prescribes.
  void raiseError(Esc& esc, AlState state, std::uint16_t code);

  // Called by the firmware's poll: in OP, a lost SYNC0 (cyclic unit deactivated while the
  // slave runs DC-synchronous, as chosen at PREOP->SAFEOP) drops to SAFEOP with 0x002C.
  void checkSynchronisation(Esc& esc);
  bool dcSynchronous() const { return dcSynchronous_; }

  static AlState state(const Esc& esc) {
    return static_cast<AlState>(esc.alStatus() & reg::al::kStateMask);
  }

 private:
  std::uint16_t checkMailbox(const Esc& esc, const SlaveProfile::Mailbox& mbx,
                             AlStatusCode failure) const;
  std::uint16_t checkProcessData(const Esc& esc, const SlaveProfile& profile) const;
  std::uint16_t checkSyncConfiguration(const Esc& esc, const SlaveProfile& profile) const;

  bool dcSynchronous_{false};
};

}  // namespace ecsim::slavesim
