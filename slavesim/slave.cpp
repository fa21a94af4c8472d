#include "slavesim/slave.hpp"

namespace ecsim::slavesim {

Slave::Slave(std::string name, const EscType& type, std::vector<std::uint8_t> sii,
             SlaveProfile profile)
    : name_(std::move(name)),
      esc_(type, std::move(sii)),
      profile_(std::move(profile)),
      mailboxBuffer_(static_cast<std::size_t>(type.ramKb) * 1024) {}

void Slave::powerOn(SimTime now) {
  esc_.powerOnReset();
  esc_.dcClock().restart(now);
  esm_ = AlStateMachine{};  // the firmware's own state starts over too
  powered_ = true;
  firmwareRunning_ = (esc_.reg16(reg::kDlStatus.address) & reg::dl_status::kPdiOperational) != 0;
  started_ = true;  // the power-up state was taken at the first start (or is taken now)
  coldStartStatus_ = device_ ? device_->coldStart() : okStatus();
  showAdoDeviceId();
}

void Slave::showAdoDeviceId() {
  if (!profile_.adoDeviceId || !firmwareRunning_) return;
  esc_.pdiWrite16(profile_.adoDeviceId->address, profile_.adoDeviceId->value);
}

void Slave::poll(SimTime now) {
  EscEvents events = esc_.takeEvents();
  if (!powered_ || !firmwareRunning_) return;
  if (!started_) {
    started_ = true;
    if (device_) device_->powerUp();
    showAdoDeviceId();
  }
  if (events.alControlWritten) {
    // The firmware reads AL control through the PDI, which frees it for the master's next
    // write (section II 0x0120 note). With device emulation the ESC has already copied it
    // into AL status: no firmware state machine, no checks (a real EK1100 or EL1004 goes from
    // INIT to OP as told: soem-sdinfo-ek1100-el1004.pcapng frames 197/291, 449/479).
    (void)esc_.pdiReadAlControl();
    if (!esc_.deviceEmulation()) {
      if (device_) device_->updateProfile(profile_);
      esm_.onAlControl(esc_, profile_);
    }
  }
  if (events.mailboxReceived && mailbox_) {
    std::size_t n = esc_.pdiMailboxReceive(mailboxBuffer_);
    if (n > 0) mailbox_->onRequest(esc_, ConstBytes(mailboxBuffer_.data(), n), now);
  }
  if (events.mailboxRead) {
    // A toggled repeat request (SM1 activate bit 1 != PDI control bit 1) asks for the last
    // response again (ETG.1000.4 mailbox repeat).
    const std::uint16_t base = reg::smChannel(1);
    bool req =
        (esc_.reg8(base + reg::sm::kActivate.address) & reg::sm::kActivateRepeatRequest) != 0;
    bool ackBit = (esc_.reg8(base + reg::sm::kPdiControl.address) & reg::sm::kPdiRepeatAck) != 0;
    if (req != ackBit) esc_.pdiMailboxRepeat();
  }
  if (mailbox_) mailbox_->poll(esc_, now);
  // SYNC pulses due since the last poll go to the device in time order (bounded per poll so a
  // very long gap cannot stall the simulator; the rest follow at the next poll).
  Esc::SyncPulse pulse;
  for (unsigned n = 0; n < kMaxSyncPulsesPerPoll && esc_.nextSyncPulse(now, pulse); ++n) {
    ++syncPulses_;
    if (device_) device_->sync(esc_, pulse.signal, state(), pulse.time);
  }
  // Process-data watchdog: a slave with firmware leaves OP for SAFEOP with 0x001B (ETG.1000.6
  // Table 11); with device emulation the ESC only counts it (the firmware-less terminal keeps
  // its state; its outputs go to their safe value).
  if (esc_.pdWatchdogExpired(now) && state() == AlState::kOp && !esc_.deviceEmulation()) {
    esm_.raiseError(esc_, AlState::kSafeOp,
                    static_cast<std::uint16_t>(AlStatusCode::kSyncManagerWatchdog));
  }
  esm_.checkSynchronisation(esc_);
  if (device_) device_->step(esc_, state(), now);
  // 1-buffer process-data outputs: the device has taken them; free the buffer for the next.
  for (const auto& pd : profile_.processData) {
    if (pd.outputs && pd.length > 0) esc_.pdiReleaseBuffer(pd.index);
  }
}

}  // namespace ecsim::slavesim
