#include "slavesim/al_state_machine.hpp"

namespace ecsim::slavesim {
namespace {

std::uint16_t code(AlStatusCode c) {
  return static_cast<std::uint16_t>(c);
}

int rank(AlState s) {
  switch (s) {
    case AlState::kInit:
      return 0;
    case AlState::kPreOp:
      return 1;
    case AlState::kSafeOp:
      return 2;
    case AlState::kOp:
      return 3;
    case AlState::kBootstrap:
      return -1;
  }
  return -1;
}

}  // namespace

std::uint16_t AlStateMachine::checkMailbox(const Esc& esc, const SlaveProfile::Mailbox& mbx,
                                           AlStatusCode failure) const {
  // SM0 must be a mailbox the master writes, SM1 one it reads, at the SII's offsets and no
  // larger than the SII's sizes (what slave stacks check at INIT->PREOP, and at INIT->BOOT
  // against the bootstrap layout: SOES ESC_checkmbx, AL status 0x0015 for BOOT).
  auto out = esc.smConfig(0);
  auto in = esc.smConfig(1);
  auto ok = [](const Esc::SmConfig& c, std::uint16_t start, std::uint16_t size, bool write) {
    return c.enabled && c.control.isMailbox() && c.control.isEcatWrite() == write &&
           c.start == start && c.length >= 8 && c.length <= size;
  };
  if (!ok(out, mbx.outStart, mbx.outSize, true) || !ok(in, mbx.inStart, mbx.inSize, false)) {
    return code(failure);
  }
  return 0;
}

std::uint16_t AlStateMachine::checkProcessData(const Esc& esc, const SlaveProfile& profile) const {
  for (const auto& pd : profile.processData) {
    if (pd.length == 0) continue;
    auto c = esc.smConfig(pd.index);
    const bool write = c.control.isEcatWrite();
    // Process data may use a 3-buffer or a 1-buffer (mailbox-mode) SM: both are valid ESC
    // configurations (some devices' ESI ask for 1-buffer, e.g. the EL9800 evaluation board).
    const bool validMode =
        c.control.mode == SmMode::kBuffered || c.control.mode == SmMode::kMailbox;
    if (!c.enabled || !validMode || write != pd.outputs || c.length != pd.length) {
      return code(pd.outputs ? AlStatusCode::kInvalidOutputConfiguration
                             : AlStatusCode::kInvalidInputConfiguration);
    }
  }
  return 0;
}

std::uint16_t AlStateMachine::checkSyncConfiguration(const Esc& esc,
                                                     const SlaveProfile& profile) const {
  // What slave stacks check at PREOP->SAFEOP (ETG.1020 §6.4 and the AL status codes of
  // ETG.1000.6 Table 11): SYNC pulses need a device that can use them; a DC sync mode the
  // master selected in 0x1C32:01 needs the matching SYNC signal activated; a SYNC0 cycle below
  // the device's minimum cycle time (0x1C32:05) is refused.
  // Without firmware (device emulation) nothing checks the cyclic unit's configuration.
  if (esc.deviceEmulation()) return 0;
  const SlaveProfile::Sync& sync = profile.sync;
  const bool sync0 = esc.syncActive(0);
  const bool sync1 = esc.syncActive(1);
  if ((sync0 || sync1) && !sync.dcSupported) {
    return code(AlStatusCode::kInvalidDcSyncConfiguration);
  }
  const bool modeChosen = sync.mode != SlaveProfile::kNoSyncObject && sync.mode != sync.initialMode;
  if (modeChosen && ((sync.mode == 2 && !sync0) || (sync.mode == 3 && !sync1))) {
    return code(AlStatusCode::kInvalidDcSyncConfiguration);
  }
  if (sync0 && sync.minCycleNs != 0) {
    const std::uint32_t cycle = esc.reg32(reg::kSync0CycleTime.address);
    if (cycle != 0 && cycle < sync.minCycleNs) {
      return code(AlStatusCode::kDcInvalidSync0CycleTime);
    }
  }
  return 0;
}

void AlStateMachine::checkSynchronisation(Esc& esc) {
  if (!dcSynchronous_ || state(esc) != AlState::kOp) return;
  if (!esc.syncActive(0)) {
    dcSynchronous_ = false;
    raiseError(esc, AlState::kSafeOp, code(AlStatusCode::kFatalSyncError));
  }
}

void AlStateMachine::raiseError(Esc& esc, AlState target, std::uint16_t statusCode) {
  AlState current = state(esc);
  AlState next = rank(target) >= 0 && rank(target) < rank(current) ? target : current;
  esc.pdiSetAlStatus(static_cast<std::uint16_t>(static_cast<std::uint16_t>(next) | kAlErrorFlag),
                     statusCode);
}

void AlStateMachine::onAlControl(Esc& esc, const SlaveProfile& profile) {
  const std::uint16_t control = esc.alControl();
  const bool ack = (control & kAlErrorFlag) != 0;
  const std::uint16_t status = esc.alStatus();
  const AlState current = state(esc);
  const bool errorPending = (status & kAlErrorFlag) != 0;
  // With an error indicated, requests without acknowledge leave state and error as they are
  // (ETG.1000.6 §6.4.1.4: the master must acknowledge with AL control bit 4).
  if (errorPending && !ack) return;
  std::uint16_t errorCode = 0;
  AlState next = current;
  auto requested = alStateFromRaw(control & kAlStateMask);
  if (!requested) {
    errorCode = code(AlStatusCode::kUnknownRequestedState);
  } else if (*requested == current) {
    next = current;
  } else if (*requested == AlState::kBootstrap) {
    if (current != AlState::kInit) {
      errorCode = code(AlStatusCode::kInvalidRequestedStateChange);
    } else if (!profile.bootstrapMailbox) {
      errorCode = code(AlStatusCode::kBootstrapNotSupported);
    } else {
      errorCode = checkMailbox(esc, *profile.bootstrapMailbox,
                               AlStatusCode::kInvalidMailboxConfigurationBoot);
      if (errorCode == 0) next = AlState::kBootstrap;
    }
  } else if (current == AlState::kBootstrap) {
    if (*requested == AlState::kInit) {
      next = AlState::kInit;
    } else {
      errorCode = code(AlStatusCode::kInvalidRequestedStateChange);
    }
  } else if (rank(*requested) < rank(current)) {
    next = *requested;  // every downward transition is allowed
  } else if (rank(*requested) != rank(current) + 1) {
    errorCode = code(AlStatusCode::kInvalidRequestedStateChange);  // I->S, I->O, P->O
  } else if (*requested == AlState::kPreOp) {
    if (profile.mailbox) {
      errorCode =
          checkMailbox(esc, *profile.mailbox, AlStatusCode::kInvalidMailboxConfigurationPreOp);
    }
    if (errorCode == 0) next = AlState::kPreOp;
  } else if (*requested == AlState::kSafeOp) {
    errorCode = checkProcessData(esc, profile);
    if (errorCode == 0) errorCode = checkSyncConfiguration(esc, profile);
    if (errorCode == 0) {
      next = AlState::kSafeOp;
      dcSynchronous_ = esc.syncActive(0);
    }
  } else {  // SAFEOP -> OP: the master must have delivered valid outputs first
    for (const auto& pd : profile.processData) {
      if (pd.outputs && pd.length > 0 && !esc.pdiOutputsReceived(pd.index)) {
        errorCode = code(AlStatusCode::kNoValidOutputs);
      }
    }
    if (errorCode == 0) next = AlState::kOp;
  }
  if (errorCode != 0) {
    esc.pdiSetAlStatus(
        static_cast<std::uint16_t>(static_cast<std::uint16_t>(current) | kAlErrorFlag), errorCode);
  } else if (profile.explicitDeviceId && (control & reg::al::kDeviceIdentification) != 0 &&
             next != AlState::kBootstrap) {
    // Explicit Device ID requested (AL control bit 5): the ID in the status code register and
    // AL status bit 5 "ID loaded", while no error is indicated and outside BOOT (what the
    // Beckhoff slave stack's SetALStatus does); a request without it clears both.
    esc.pdiSetAlStatus(static_cast<std::uint16_t>(static_cast<std::uint16_t>(next) |
                                                  reg::al::kDeviceIdentification),
                       *profile.explicitDeviceId);
  } else {
    esc.pdiSetAlStatus(static_cast<std::uint16_t>(next), 0);
  }
}

}  // namespace ecsim::slavesim
