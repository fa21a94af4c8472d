#include "protocol/al_status.hpp"

#include <algorithm>
#include <iterator>
#include <utility>

namespace ecsim {

std::string_view toString(AlState state) {
  switch (state) {
    case AlState::kInit:
      return "INIT";
    case AlState::kPreOp:
      return "PREOP";
    case AlState::kBootstrap:
      return "BOOT";
    case AlState::kSafeOp:
      return "SAFEOP";
    case AlState::kOp:
      return "OP";
  }
  return "unknown";
}

std::optional<AlState> alStateFromRaw(std::uint16_t raw) {
  switch (raw & kAlStateMask) {
    case 1:
      return AlState::kInit;
    case 2:
      return AlState::kPreOp;
    case 3:
      return AlState::kBootstrap;
    case 4:
      return AlState::kSafeOp;
    case 8:
      return AlState::kOp;
    default:
      return std::nullopt;
  }
}

namespace {

using C = AlStatusCode;

// Sorted by code, for binary search.
constexpr std::pair<AlStatusCode, std::string_view> kAlStatusTexts[] = {
    {C::kNoError, "no error"},
    {C::kUnspecifiedError, "unspecified error"},
    {C::kNoMemory, "out of memory"},
    {C::kInvalidDeviceSetup, "invalid device setup"},
    {C::kInvalidRevision, "invalid revision"},
    {C::kSiiMismatchesFirmware, "SII/EEPROM content does not match the firmware"},
    {C::kFirmwareUpdateFailed, "firmware update failed"},
    {C::kLicenseError, "license error"},
    {C::kInvalidRequestedStateChange, "requested state change is not allowed"},
    {C::kUnknownRequestedState, "requested state is unknown"},
    {C::kBootstrapNotSupported, "bootstrap state not supported"},
    {C::kNoValidFirmware, "no valid firmware"},
    {C::kInvalidMailboxConfigurationBoot, "invalid mailbox configuration for BOOT"},
    {C::kInvalidMailboxConfigurationPreOp, "invalid mailbox configuration for PREOP"},
    {C::kInvalidSyncManagerConfiguration, "invalid SyncManager configuration"},
    {C::kNoValidInputs, "no valid inputs available"},
    {C::kNoValidOutputs, "no valid outputs"},
    {C::kSynchronizationError, "synchronization error"},
    {C::kSyncManagerWatchdog, "SyncManager watchdog expired"},
    {C::kInvalidSyncManagerTypes, "invalid SyncManager types"},
    {C::kInvalidOutputConfiguration, "invalid output configuration"},
    {C::kInvalidInputConfiguration, "invalid input configuration"},
    {C::kInvalidWatchdogConfiguration, "invalid watchdog configuration"},
    {C::kNeedsColdStart, "device needs a cold start"},
    {C::kNeedsInit, "device needs INIT"},
    {C::kNeedsPreOp, "device needs PREOP"},
    {C::kNeedsSafeOp, "device needs SAFEOP"},
    {C::kInvalidInputMapping, "invalid input mapping"},
    {C::kInvalidOutputMapping, "invalid output mapping"},
    {C::kInconsistentSettings, "settings are inconsistent"},
    {C::kFreeRunNotSupported, "free-run mode not supported"},
    {C::kSyncModeNotSupported, "synchronous mode not supported"},
    {C::kFreeRunNeeds3Buffer, "free-run mode needs 3-buffer mode"},
    {C::kBackgroundWatchdog, "background watchdog"},
    {C::kNoValidInputsAndOutputs, "no valid inputs and outputs"},
    {C::kFatalSyncError, "fatal synchronization error"},
    {C::kNoSyncError, "no synchronization signal"},
    {C::kInvalidInputFmmuConfiguration, "invalid input FMMU configuration"},
    {C::kInvalidDcSyncConfiguration, "invalid DC SYNC configuration"},
    {C::kInvalidDcLatchConfiguration, "invalid DC latch configuration"},
    {C::kPllError, "PLL error"},
    {C::kDcSyncIoError, "DC sync I/O error"},
    {C::kDcSyncTimeout, "DC sync timeout"},
    {C::kDcInvalidSyncCycleTime, "DC sync cycle time is invalid"},
    {C::kDcInvalidSync0CycleTime, "DC SYNC0 cycle time is invalid"},
    {C::kDcInvalidSync1CycleTime, "DC SYNC1 cycle time is invalid"},
    {C::kMailboxAoe, "mailbox error (AoE)"},
    {C::kMailboxEoe, "mailbox error (EoE)"},
    {C::kMailboxCoe, "mailbox error (CoE)"},
    {C::kMailboxFoe, "mailbox error (FoE)"},
    {C::kMailboxSoe, "mailbox error (SoE)"},
    {C::kMailboxVoe, "mailbox error (VoE)"},
    {C::kEepromNoAccess, "no access to the EEPROM"},
    {C::kEepromError, "EEPROM error"},
    {C::kExternalHardwareNotReady, "external hardware not ready"},
    {C::kSlaveRestartedLocally, "device was restarted locally"},
    {C::kDeviceIdentificationUpdated, "device identification value was updated"},
    {C::kModuleIdentListMismatch, "detected modules do not match the module ident list"},
    {C::kSupplyVoltageTooLow, "supply voltage too low"},
    {C::kSupplyVoltageTooHigh, "supply voltage too high"},
};

static_assert(
    [] {
      for (std::size_t i = 1; i < std::size(kAlStatusTexts); ++i) {
        if (kAlStatusTexts[i - 1].first >= kAlStatusTexts[i].first) return false;
      }
      return true;
    }(),
    "AL status code table must be sorted and unique");

const std::pair<AlStatusCode, std::string_view>* findAlStatus(std::uint16_t code) {
  const auto* end = std::end(kAlStatusTexts);
  const auto* it = std::lower_bound(std::begin(kAlStatusTexts), end, code,
                                    [](const auto& entry, std::uint16_t c) {
                                      return static_cast<std::uint16_t>(entry.first) < c;
                                    });
  if (it == end || static_cast<std::uint16_t>(it->first) != code) return nullptr;
  return it;
}

}  // namespace

std::string_view alStatusCodeText(std::uint16_t code) {
  const auto* entry = findAlStatus(code);
  return entry ? entry->second : "unknown AL status code";
}

bool isKnownAlStatusCode(std::uint16_t code) {
  return findAlStatus(code) != nullptr;
}

}  // namespace ecsim
