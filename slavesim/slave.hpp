// A simulated slave: its ESC plus the firmware behind the PDI (state machine, mailbox server,
// device model). The firmware runs between frames, when the ESC reports events, and on the
// device's own tick.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "protocol/result.hpp"
#include "slavesim/al_state_machine.hpp"
#include "slavesim/esc.hpp"

namespace ecsim::slavesim {

// Protocol server reached through the mailbox (CoE, later FoE/EoE): gets each request and
// answers through Esc::pdiMailboxSend.
class MailboxServer {
 public:
  virtual ~MailboxServer() = default;
  virtual void onRequest(Esc& esc, ConstBytes mailbox, SimTime now) = 0;
  // Called when the firmware is polled; lets the server push queued responses.
  virtual void poll(Esc& /*esc*/, SimTime /*now*/) {}
};

// The application behind the ESC (IO terminal, drive...). It sees only the PDI side.
class Device {
 public:
  virtual ~Device() = default;
  // Current expectations for the ESM checks (mailbox, PDO sizes).
  virtual void updateProfile(SlaveProfile& /*profile*/) {}
  // Called after an AL state change and periodically; exchanges process data with the ESC.
  virtual void step(Esc& /*esc*/, AlState /*state*/, SimTime /*now*/) {}
  // A pulse of the DC sync unit: SYNC0 (signal 0) or SYNC1 (signal 1), at simulation time
  // `now` (the pulse's start; pulses since the last poll are delivered in order). While
  // Esc::syncActive(0) holds, a device synchronised to DC steps its model and latches its
  // inputs here rather than in step() (ETG.1020 DC synchronous mode, 0x1C32:01 = 2).
  virtual void sync(Esc& /*esc*/, unsigned /*signal*/, AlState /*state*/, SimTime /*now*/) {}
  // Called once, when the firmware first runs (before it handles any event): the state the
  // device is in now is its power-up state.
  virtual void powerUp() {}
  // Switched on again after a power cycle: back to the state after power-up, keeping only what
  // the device keeps in non-volatile memory (Slave::powerOn).
  virtual Status coldStart() { return okStatus(); }
};

// The network that runs the slaves' firmware (topology::Segment): told of ESC events (and of
// addressing and IRQ changes, EscObserver) and when a slave gains or loses a device or a
// mailbox server, so that it polls only the slaves with something to do.
class FirmwarePoller : public EscObserver {
 public:
  virtual void firmwareChanged(std::uint32_t id) = 0;

 protected:
  ~FirmwarePoller() = default;
};

class Slave {
 public:
  Slave(std::string name, const EscType& type, std::vector<std::uint8_t> sii, SlaveProfile profile);

  const std::string& name() const { return name_; }
  Esc& esc() { return esc_; }
  const Esc& esc() const { return esc_; }
  SlaveProfile& profile() { return profile_; }
  AlState state() const { return AlStateMachine::state(esc_); }

  void setMailboxServer(std::unique_ptr<MailboxServer> server) {
    mailbox_ = std::move(server);
    firmwareChanged();
  }
  void setDevice(std::unique_ptr<Device> device) {
    device_ = std::move(device);
    firmwareChanged();
  }
  MailboxServer* mailboxServer() { return mailbox_.get(); }
  // Hands the mailbox server over (to wrap it, e.g. for fault injection).
  std::unique_ptr<MailboxServer> takeMailboxServer() {
    firmwareChanged();
    return std::move(mailbox_);
  }
  // Whether poll() has work even without ESC events: a device or a mailbox server.
  bool hasFirmware() const { return device_ != nullptr || mailbox_ != nullptr; }
  // The network polling this slave (nullptr: none); `id` is its index there. The ESC's
  // observer is the poller too.
  void setPoller(FirmwarePoller* poller, std::uint32_t id) {
    poller_ = poller;
    pollerId_ = id;
    esc_.setObserver(poller, id);
  }
  Device* device() { return device_.get(); }

  // Runs the firmware: reacts to ESC events (AL control, mailbox) and steps the device.
  void poll(SimTime now);

  // The ESC's DC latch input `unit` (LATCH0/LATCH1) goes to `level` at simulation time `time`
  // (a sensor or probe wired to the latch pin; Esc::setLatchInput). Edges must come in time
  // order and not before the frames the ESC already saw.
  void setLatchSignal(unsigned unit, bool level, SimTime time) {
    esc_.setLatchInput(unit, level, time);
  }

  AlStateMachine& stateMachine() { return esm_; }
  // SYNC0/SYNC1 pulses delivered to the device so far.
  std::uint64_t syncPulses() const { return syncPulses_; }
  static constexpr unsigned kMaxSyncPulsesPerPoll = 4096;

  // Power. Off: the firmware stops (the topology breaks the links at the neighbours' ports).
  // On: a power-on reset of the ESC (registers and AL state; the EEPROM content is kept) and a
  // cold start of the device (Device::coldStart: a dictionary-based slave's objects back to
  // their power-up values, PDO assignment and mapping included, its device model re-created;
  // what the device keeps in non-volatile memory, such as a multi-turn position or its state
  // file, survives). The firmware runs again only when the ESC loaded its EEPROM configuration
  // (PDI operational), so a slave with an EEPROM checksum error stays in INIT. A cold start
  // that fails (a device model that cannot be re-created) is kept in coldStartStatus().
  void powerOff() { powered_ = false; }
  // Power-up at simulation time `now`: registers reset, the ESC's local clock from 0, the
  // firmware's state machine and the device cold-started (Device::coldStart).
  void powerOn(SimTime now);
  bool powered() const { return powered_; }
  bool firmwareRunning() const { return powered_ && firmwareRunning_; }
  const Status& coldStartStatus() const { return coldStartStatus_; }

 private:
  // SlaveProfile::adoDeviceId into the process memory (when the firmware/PDI runs).
  void showAdoDeviceId();

  std::string name_;
  Esc esc_;
  SlaveProfile profile_;
  AlStateMachine esm_;
  std::unique_ptr<MailboxServer> mailbox_;
  std::unique_ptr<Device> device_;
  std::vector<std::uint8_t> mailboxBuffer_;
  std::uint64_t syncPulses_{0};
  bool powered_{true};
  bool firmwareRunning_{true};
  bool started_{false};  // Device::powerUp called
  Status coldStartStatus_;
  FirmwarePoller* poller_{nullptr};
  std::uint32_t pollerId_{0};
  void firmwareChanged() {
    if (poller_ != nullptr) poller_->firmwareChanged(pollerId_);
  }
};

}  // namespace ecsim::slavesim
