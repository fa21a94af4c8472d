// ecsim's EtherCAT master: the application API over the step-driven core.
//
//   Master master(link, bus);
//   master.loadConfig("bus.xml");       // optional: the slaves expected, with identity
//   master.start();                     // scan, identity check, mailboxes, PDO mapping from
//                                       // CoE or SII, process image, SM/FMMU, INIT->PREOP->
//                                       // SAFEOP->OP for all slaves together
//   for (;;) {
//     master.writeData(offset, outputs);  // process image offsets (layout(): outputs first)
//     master.exchange();                  // one cycle: LRW frames out and back, WKC checked
//     master.readData(offset, inputs);
//   }
//   master.stop();                      // all slaves back to INIT
//
// Every call blocks through the Bus (real time on an interface, virtual time in tests) but
// the work is done by non-blocking state machines (master/scan.hpp, state_change.hpp,
// coe_client.hpp, ...) that a real-time driver can step itself. Errors name the slave (position,
// station address, name) and, for refusals, the AL status code and its text.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "link/link.hpp"
#include "master/bus.hpp"
#include "master/coe_client.hpp"
#include "master/cyclic.hpp"
#include "master/dc.hpp"
#include "master/eni_config.hpp"
#include "master/eoe_client.hpp"
#include "master/health.hpp"
#include "master/pdo_config.hpp"
#include "master/process_image.hpp"
#include "master/scan.hpp"
#include "master/slave_info.hpp"
#include "master/soe_client.hpp"
#include "master/state_change.hpp"
#include "master/transport.hpp"
#include "master/variables.hpp"

namespace ecsim::master {

struct MasterOptions {
  TransportOptions transport;
  ScanOptions scan;
  StateChangeOptions state;
  MailboxOptions mailbox;
  LayoutOptions layout;
  // While waiting for SAFEOP -> OP (and afterwards in start()), process data is exchanged
  // this often so the slaves see valid outputs and their watchdogs stay calm.
  SimTime cycleTime{kNsPerMs};
  SimTime scanTimeout{30 * kNsPerSecond};
  SimTime mailboxTimeout{10 * kNsPerSecond};  // one SDO transfer or PDO discovery
  // Distributed clocks (master/dc.hpp): with dc.enable, start() sets them up after the scan
  // and the cyclic frame carries the reference clock's time.
  DcOptions dc;
  // Cyclic health (master/health.hpp) in cycle(): with recovery a slave that disappears is
  // reported, the others keep running, and it is brought back to OP when it returns; without,
  // nothing is read or reconfigured and every missing working counter is a WKC error.
  bool recovery{true};
  HealthOptions health;
  // What start() compares against a loaded configuration (serial numbers: off by default).
  IdentityCheck identity;
};

class Master {
 public:
  // link and bus must outlive the master.
  Master(Link& link, Bus& bus, MasterOptions options = {});

  // ---- the application API ------------------------------------------------------------------
  Status loadConfig(const std::filesystem::path& path);
  void setConfig(MasterConfig config) { config_ = std::move(config); }
  const std::optional<MasterConfig>& config() const { return config_; }
  // The slaves' names by bus position (a topology's or ENI's, topology/slave_names.hpp), for
  // variables, events and messages (SlaveInfo::configuredName). They win over the names of a
  // configuration; an empty or missing entry leaves that slave to the configuration or its SII.
  void setSlaveNames(std::vector<std::string> names);
  const std::vector<std::string>& slaveNames() const { return slaveNames_; }

  Status start();
  // Copies into the outputs of the process image (offset < layout().outputBytes).
  Status writeData(std::size_t offset, ConstBytes data);
  // Copies from the process image (outputs or inputs).
  Status readData(std::size_t offset, Bytes out) const;
  // One cycle: send the frames, wait for them (at most the transport timeout), copy inputs,
  // check WKCs. kWorkingCounter naming the slaves concerned, kTimeout for a lost frame.
  Status exchange();
  Status stop();

  // ---- cyclic health, recovery, names (master/health.hpp, recovery.hpp, variables.hpp) ------
  // One cycle with health and recovery: exchange(), then the HealthMonitor looks at the
  // result, queues its AL status reads (every HealthOptions::statusInterval cycles, and at once
  // after an error) and steps any slave's recovery by one step; those datagrams travel beside
  // the next cycles' frames. Returns exchange()'s status (after a slave is reported lost its
  // working counters are no longer expected, so the cycles are ok again).
  //
  //   while (running) { master.cycle(); for (auto& e : master.events()) log(e.text); ... }
  Status cycle();
  // cycle() in steps, for a driver that runs them on different threads (master/rt_driver.hpp):
  //
  //   sendCycle(now)     the cached frames out with the outputs of the process image; datagrams
  //                      queued meanwhile (status reads, recovery, acyclic tasks) go out with
  //                      them, at the first pollCycle()
  //   pollCycle(now)     receives what has arrived, handles timeouts, sends what is queued;
  //                      true while a frame of this cycle is in flight (call it again after
  //                      the Bus waited)
  //   finishCycle()      inputs into the image, WKCs checked: exchange()'s status
  //   control(now)       the HealthMonitor after the cycle: status reads, one recovery step
  //
  // cycle() is exactly these four in a row, with the Bus waiting between the polls. None of
  // them blocks or allocates while nothing goes wrong, and none is thread-safe: a caller on
  // several threads runs each step under one lock that also guards the process image (the
  // driver's master lock) and waits for frames outside it. When control() runs less often than
  // the cycles, it looks at the first failed cycle since it last ran, else the last one.
  Status sendCycle(SimTime now);
  bool pollCycle(SimTime now);
  Status finishCycle();
  void control(SimTime now);
  // Lost / returned / reset / error / recovered / recovery failed, oldest first, each naming
  // the slave and the cycle ("slave 3 (0x1004 'DO1') lost at cycle 1002").
  const std::vector<MasterEvent>& events() const;
  void clearEvents();
  // Per slave: condition, AL status as last read, lost/recovered counts; cyclic counters.
  MasterHealth health() const;
  // The period jitter is measured against and after which an answer counts as late (default
  // MasterOptions::cycleTime); resetStatistics() empties counters and histograms.
  void setCycleTime(SimTime period);
  void resetStatistics();
  // A process-data variable by name ("Drive1.Statusword", "DI1.Input 3", or the aliases
  // master/variables.hpp lists), bound to the process image: get<std::int32_t>(), set(...).
  Result<PdoVariable> variable(std::string_view name);
  const std::vector<VariableInfo>& variables() const { return variables_; }

  // ---- distributed clocks (master/dc.hpp) --------------------------------------------------
  // Delays, offsets, static drift compensation, SYNC0 for the slaves whose ENI entry has <DC>
  // or whose SII lists a DC op mode with SYNC0; the cyclic frame then carries an FRMW of the
  // reference clock. Needs a scan.
  Status initDc();
  const DcSetup& dcSetup() const { return dc_; }
  // Largest |0x092C| (ns) over the DC slaves other than the reference, read now.
  Result<SimTime> dcSyncError();

  // ---- steps and services (tools, tests) ----------------------------------------------------
  Status scan();
  Status setupMailboxes();
  // One state for all slaves (no path through intermediate states); with process data
  // configured and a target of SAFEOP or OP, cycles go on while waiting.
  Status requestState(AlState target);
  // Walks INIT -> PREOP -> SAFEOP -> OP (configuring on the way) up to `target`, or goes
  // straight down.
  Status bringTo(AlState target);
  // Reads every slave's AL status and code.
  Status readStates();
  // PDO discovery (CoE, else SII), process image, SM/FMMU writes; slaves must be in PREOP.
  Status configureProcessData();

  Result<std::vector<std::uint8_t>> sdoUpload(std::size_t position, std::uint16_t index,
                                              std::uint8_t subindex, bool completeAccess = false);
  Status sdoDownload(std::size_t position, std::uint16_t index, std::uint8_t subindex,
                     ConstBytes data, bool completeAccess = false);
  // SoE (master/soe_client.hpp): the elements of one IDN of drive `driveNo`, in element order;
  // a write sets the value element.
  Result<std::vector<std::uint8_t>> soeRead(std::size_t position, std::uint8_t driveNo,
                                            std::uint8_t elements, std::uint16_t idn);
  Status soeWrite(std::size_t position, std::uint8_t driveNo, std::uint16_t idn, ConstBytes value);
  Result<OdList> readOdList(std::size_t position);
  // EoE (ETG.1000.6 §5.7): sets the fields `parameters` includes / reads the slave's IP
  // parameters (master/eoe_client.hpp).
  Status eoeSetIp(std::size_t position, const EoeIpParameters& parameters, std::uint8_t port = 0);
  Result<EoeIpParameters> eoeGetIp(std::size_t position, std::uint8_t port = 0);
  Result<ObjectDescription> readObjectDescription(std::size_t position, std::uint16_t index);
  Result<EntryDescription> readEntryDescription(std::size_t position, std::uint16_t index,
                                                std::uint8_t subindex);
  // BOOT (master_foe.cpp): the slave to INIT, SM0/SM1 programmed with the bootstrap mailbox
  // of its SII (words 0x14-0x17), BOOT requested; its mailbox is the bootstrap one until
  // leaveBootstrap() (INIT, the standard mailbox back). kUnsupported without a bootstrap
  // mailbox in the SII; kAborted with the AL status code when the slave refuses.
  Status enterBootstrap(std::size_t position);
  Status leaveBootstrap(std::size_t position);
  // FoE (master/foe_client.hpp) through the slave's mailbox as it is now (PREOP and up, or BOOT).
  Status foeWrite(std::size_t position, const std::string& name, ConstBytes data,
                  std::uint32_t password = 0);
  Result<std::vector<std::uint8_t>> foeRead(std::size_t position, const std::string& name,
                                            std::uint32_t password = 0);
  Result<std::vector<std::uint8_t>> readRegisters(std::size_t position, std::uint16_t address,
                                                  std::uint16_t length);
  Status writeRegisters(std::size_t position, std::uint16_t address, ConstBytes data);

  const std::vector<SlaveInfo>& slaves() const { return slaves_; }
  // What the last scan's count said about the frame timeout (ScanOptions::adaptTimeout).
  const std::optional<TimeoutAdvice>& timeoutAdvice() const { return timeoutAdvice_; }
  const std::vector<SlaveProcessData>& processData() const { return processData_; }
  const ProcessImageLayout& layout() const { return layout_; }
  ConstBytes image() const { return image_; }
  const CyclicStatistics& statistics() const { return cyclic_.statistics(); }
  const CycleResult& lastCycle() const { return lastCycle_; }
  const std::vector<StateRefusal>& lastRefusals() const { return refusals_; }
  const std::vector<ReceivedEmergency>& emergencies() const { return emergencies_; }
  // Cable redundancy: `link` is the master's second port, wired to the far end of the line
  // (Transport::setRedundantLink; events kRingBroken/kRingWhole). Before start(); it must
  // outlive the master.
  void setRedundantLink(Link* link) { transport_.setRedundantLink(link); }
  Transport& transport() { return transport_; }
  const Transport& transport() const { return transport_; }
  Bus& bus() { return bus_; }
  const MasterOptions& options() const { return options_; }

 private:
  Status run(Task& task, SimTime timeout, std::string_view what);
  Result<SlaveInfo*> slaveAt(std::size_t position);
  // ENI configuration (master/eni_master.cpp): station addresses and mailbox areas after the
  // scan; init commands of each slave's transition to `target`: register and CoE commands
  // before the request (phase kBefore), CoE commands of IP once PREOP is reached (kAfter).
  enum class InitPhase { kBefore, kAfter };
  Status applyEniSetup();
  Status runInitCommands(AlState target, InitPhase phase);
  // Sets each scanned slave's configuredName from slaveNames_, else the configuration.
  void applySlaveNames();

  MasterOptions options_;
  Transport transport_;
  Bus& bus_;
  std::optional<MasterConfig> config_;
  std::vector<std::string> slaveNames_;
  std::vector<SlaveInfo> slaves_;
  std::vector<SlaveProcessData> processData_;
  ProcessImageLayout layout_;
  std::vector<std::uint8_t> image_;
  CyclicExchange cyclic_;
  CycleResult lastCycle_;
  std::optional<CycleResult> failedSinceControl_;  // the first failed cycle control() has not seen
  std::vector<StateRefusal> refusals_;
  std::vector<ReceivedEmergency> emergencies_;
  std::unique_ptr<HealthMonitor> health_;  // made with the process image
  std::vector<VariableInfo> variables_;
  std::vector<MasterEvent> noEvents_;
  DcSetup dc_;
  std::optional<TimeoutAdvice> timeoutAdvice_;
  std::optional<AlState> initCmdsDoneFor_;  // the before-phase already ran for this target
  std::vector<char> transitionFrom_;        // per slave: the state letter it left
};

}  // namespace ecsim::master
