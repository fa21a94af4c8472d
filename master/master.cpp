#include "master/master.hpp"

#include <algorithm>
#include <cstring>

#include "master/batch.hpp"
#include "master/esc_config.hpp"

namespace ecsim::master {
namespace {

int rank(AlState s) {
  switch (s) {
    case AlState::kInit:
      return 0;
    case AlState::kPreOp:
      return 1;
    case AlState::kBootstrap:
      return 1;
    case AlState::kSafeOp:
      return 2;
    case AlState::kOp:
      return 3;
  }
  return 0;
}

// Steps several tasks side by side (their datagrams share frames).
class TaskGroup final : public Task {
 public:
  void add(Task& task) { tasks_.push_back(&task); }
  bool step(SimTime now) override {
    bool running = false;
    for (Task* t : tasks_) running = t->step(now) || running;
    return running;
  }
  std::optional<SimTime> wakeAt() const override {
    std::optional<SimTime> earliest;
    for (const Task* t : tasks_) {
      auto w = t->wakeAt();
      if (w && (!earliest || *w < *earliest)) earliest = w;
    }
    return earliest;
  }

 private:
  std::vector<Task*> tasks_;
};

// Runs `inner` while exchanging process data every `period`.
class CyclingTask final : public Task {
 public:
  CyclingTask(Task& inner, CyclicExchange& cyclic, Transport& transport,
              std::vector<std::uint8_t>& image, SimTime period)
      : inner_(inner), cyclic_(cyclic), transport_(transport), image_(image), period_(period) {}
  bool step(SimTime now) override {
    const bool running = inner_.step(now);
    if (!cyclic_.pending()) {
      if (sent_) (void)cyclic_.finish(image_);
      sent_ = false;
      if (running && now >= next_) {
        sent_ = cyclic_.send(transport_, image_, now).ok();
        next_ = now + period_;
      }
    }
    return running;
  }
  std::optional<SimTime> wakeAt() const override {
    auto w = inner_.wakeAt();
    return w ? std::min(*w, next_) : next_;
  }

 private:
  Task& inner_;
  CyclicExchange& cyclic_;
  Transport& transport_;
  std::vector<std::uint8_t>& image_;
  SimTime period_;
  SimTime next_{0};
  bool sent_{false};
};

class CycleWait final : public Task {
 public:
  explicit CycleWait(const CyclicExchange& cyclic) : cyclic_(cyclic) {}
  bool step(SimTime /*now*/) override { return cyclic_.pending(); }

 private:
  const CyclicExchange& cyclic_;
};

}  // namespace

Master::Master(Link& link, Bus& bus, MasterOptions options)
    : options_(options), transport_(link, options.transport), bus_(bus) {}

Status Master::run(Task& task, SimTime timeout, std::string_view what) {
  return runTask(task, transport_, bus_, timeout, what);
}

Status Master::loadConfig(const std::filesystem::path& path) {
  ECSIM_ASSIGN_OR_RETURN(MasterConfig config, loadMasterConfig(path));
  config_ = std::move(config);
  return okStatus();
}

Result<SlaveInfo*> Master::slaveAt(std::size_t position) {
  if (position >= slaves_.size()) {
    return makeError(ErrorCode::kNotFound, "no slave at position " + std::to_string(position) +
                                               " (the bus has " + std::to_string(slaves_.size()) +
                                               ")");
  }
  return &slaves_[position];
}

Status Master::scan() {
  processData_.clear();
  layout_ = {};
  image_.clear();
  dc_ = {};
  cyclic_.setDcReference(std::nullopt);
  health_.reset();
  variables_.clear();
  (void)cyclic_.build(layout_, options_.transport.source);
  ScanTask task(transport_, slaves_, options_.scan);
  task.start(bus_.now());
  const Status ran = run(task, options_.scanTimeout, "scan");
  timeoutAdvice_ = task.timeoutAdvice();
  ECSIM_TRY(ran);
  ECSIM_TRY(task.status());
  applySlaveNames();
  // A redundant ring's BRD counting every slave from the second port: the primary port
  // reaches none (Transport::setRingSlaveCount).
  transport_.setRingSlaveCount(
      static_cast<std::uint16_t>(std::min<std::size_t>(slaves_.size(), UINT16_MAX)));
  return okStatus();
}

void Master::setSlaveNames(std::vector<std::string> names) {
  slaveNames_ = std::move(names);
  applySlaveNames();
}

void Master::applySlaveNames() {
  for (auto& slave : slaves_) {
    const std::size_t i = slave.position;
    slave.configuredName.clear();
    if (i < slaveNames_.size() && !slaveNames_[i].empty()) {
      slave.configuredName = slaveNames_[i];
    } else if (config_ && i < config_->slaves.size()) {
      slave.configuredName = config_->slaves[i].name;
    }
  }
}

Status Master::setupMailboxes() {
  DatagramBatch batch;
  for (const auto& slave : slaves_) addMailboxSetup(batch, slave);
  if (batch.empty()) return okStatus();
  batch.queueAll(transport_);
  BatchWait wait(batch);
  ECSIM_TRY(run(wait, options_.state.timeout, "mailbox setup"));
  if (auto s = batch.check(); !s.ok()) {
    return makeError(s.error().code, "mailbox SyncManagers: " + s.error().context);
  }
  return okStatus();
}

Status Master::readStates() {
  DatagramBatch batch;
  for (const auto& slave : slaves_) {
    batch.add().fprd(slave.station, reg::kAlStatus, reg::kAlStatusCode);
  }
  batch.queueAll(transport_);
  BatchWait wait(batch);
  ECSIM_TRY(run(wait, options_.state.timeout, "AL status"));
  ECSIM_TRY(batch.check());
  for (std::size_t i = 0; i < slaves_.size(); ++i) {
    slaves_[i].alStatus = batch[i].get(reg::kAlStatus);
    slaves_[i].alStatusCode = batch[i].get(reg::kAlStatusCode);
  }
  return okStatus();
}

Status Master::requestState(AlState target) {
  ECSIM_TRY(runInitCommands(target, InitPhase::kBefore));
  // Cyclic datagrams of a state (an ENI Cmd's <State>) go out once every slave is in it.
  AlState lowest = target;
  for (const auto& s : slaves_) {
    const AlState state = s.state().value_or(AlState::kInit);
    if (rank(state) < rank(lowest)) lowest = state;
  }
  ECSIM_TRY(cyclic_.setState(lowest));
  StateChangeTask task(transport_, slaves_, options_.state);
  task.start(target, bus_.now());
  const SimTime timeout = options_.state.timeout + kNsPerSecond;
  Status ran;
  if (cyclic_.built() && cyclic_.frameCount() > 0 && rank(target) >= rank(AlState::kSafeOp)) {
    CyclingTask cycling(task, cyclic_, transport_, image_, options_.cycleTime);
    ran = run(cycling, timeout, "state change");
    CycleWait wait(cyclic_);
    ECSIM_TRY(run(wait, 4 * transport_.options().timeout, "last cycle"));
    if (!cyclic_.pending()) (void)cyclic_.finish(image_);
  } else {
    ran = run(task, timeout, "state change");
  }
  refusals_ = task.refusals();
  ECSIM_TRY(ran);
  ECSIM_TRY(task.status());
  ECSIM_TRY(cyclic_.setState(target));
  return runInitCommands(target, InitPhase::kAfter);
}

Status Master::configureProcessData() {
  applySlaveNames();  // a configuration set after the scan names the slaves too
  ECSIM_TRY(runInitCommands(AlState::kSafeOp, InitPhase::kBefore));  // PDO assignment first
  processData_.assign(slaves_.size(), {});
  std::vector<std::unique_ptr<PdoDiscoveryTask>> discoveries(slaves_.size());
  TaskGroup group;
  for (auto& slave : slaves_) {
    if (!slave.hasCoe()) continue;
    auto& task = discoveries[slave.position];
    task = std::make_unique<PdoDiscoveryTask>(transport_, slave, &emergencies_, options_.mailbox);
    ECSIM_TRY(task->start(bus_.now()));
    group.add(*task);
  }
  ECSIM_TRY(run(group, options_.mailboxTimeout, "PDO discovery"));
  for (auto& slave : slaves_) {
    SlaveProcessData& data = processData_[slave.position];
    if (const auto& task = discoveries[slave.position]) {
      if (!task->status().ok()) {
        return makeError(task->status().error().code,
                         "PDO discovery: " + task->status().error().context);
      }
      data = task->result();
    }
    // CoE without bits (or no CoE): the SII says (as SOEM decides).
    if (data.outputBits() + data.inputBits() == 0) data = processDataFromSii(slave);
  }
  // An ENI's cyclic frames, else the master's own (master/eni_config.hpp).
  ECSIM_ASSIGN_OR_RETURN(layout_, planLayout(config_, slaves_, processData_, options_.layout));
  if (layout_.frameCount > transport_.options().maxFramesInFlight) {
    return makeError(ErrorCode::kTooLarge,
                     "process image needs " + std::to_string(layout_.frameCount) +
                         " frames per cycle, the transport allows " +
                         std::to_string(transport_.options().maxFramesInFlight) + " in flight");
  }
  DatagramBatch batch;
  addProcessDataSetup(batch, layout_);
  batch.queueAll(transport_);
  BatchWait wait(batch);
  ECSIM_TRY(run(wait, options_.state.timeout, "SM/FMMU setup"));
  if (auto s = batch.check(); !s.ok()) {
    return makeError(s.error().code, "SM/FMMU setup: " + s.error().context);
  }
  image_.assign(layout_.size(), 0);
  ECSIM_TRY(cyclic_.build(layout_, options_.transport.source));
  cyclic_.setTiming(options_.cycleTime, options_.cycleTime);
  health_ = std::make_unique<HealthMonitor>(
      transport_, slaves_, layout_, cyclic_, options_.recovery, options_.health, options_.state,
      std::make_unique<MasterSlaveSetup>(processData_, config_, &dc_, &slaves_,
                                         options_.dc.recoverySync0Margin),
      options_.mailbox);
  variables_ = nameVariables(layout_, slaves_);
  if (config_ && config_->eni && !config_->eni->cyclic.empty()) {
    ECSIM_TRY(addEniVariables(variables_, *config_->eni, layout_));  // the ENI's names too
  }
  return okStatus();
}

Status Master::bringTo(AlState target) {
  ECSIM_TRY(readStates());
  if (slaves_.empty()) return okStatus();
  int lowest = rank(AlState::kOp);
  int highest = rank(AlState::kInit);
  for (const auto& s : slaves_) {
    const int r = rank(s.state().value_or(AlState::kInit));
    lowest = std::min(lowest, r);
    highest = std::max(highest, r);
  }
  const int want = rank(target);
  if (want <= lowest) return want == highest ? okStatus() : requestState(target);
  if (lowest < rank(AlState::kPreOp)) {
    ECSIM_TRY(setupMailboxes());
    ECSIM_TRY(requestState(AlState::kPreOp));
  }
  if (want == rank(AlState::kPreOp)) return okStatus();
  if (lowest < rank(AlState::kSafeOp)) {
    ECSIM_TRY(configureProcessData());
    ECSIM_TRY(requestState(AlState::kSafeOp));
  }
  if (want == rank(AlState::kSafeOp)) return okStatus();
  if (!cyclic_.built()) ECSIM_TRY(configureProcessData());
  (void)exchange();  // valid outputs in the slaves before OP is requested
  return requestState(AlState::kOp);
}

Status Master::start() {
  ECSIM_TRY(scan());
  if (config_) ECSIM_TRY(checkIdentities(*config_, slaves_, options_.identity));
  if (slaves_.empty()) return makeError(ErrorCode::kNotFound, "no slaves found");
  ECSIM_TRY(applyEniSetup());
  if (options_.dc.enable) ECSIM_TRY(initDc());
  return bringTo(AlState::kOp);
}

Status Master::stop() {
  if (slaves_.empty()) return okStatus();
  return requestState(AlState::kInit);
}

Status Master::writeData(std::size_t offset, ConstBytes data) {
  if (offset + data.size() > layout_.outputBytes) {
    return makeError(ErrorCode::kInvalidArgument,
                     "writeData: bytes " + std::to_string(offset) + ".." +
                         std::to_string(offset + data.size()) + " are not all outputs (" +
                         std::to_string(layout_.outputBytes) + " output bytes)");
  }
  if (!data.empty()) std::memcpy(image_.data() + offset, data.data(), data.size());
  return okStatus();
}

Status Master::readData(std::size_t offset, Bytes out) const {
  if (offset + out.size() > image_.size()) {
    return makeError(ErrorCode::kInvalidArgument,
                     "readData: bytes " + std::to_string(offset) + ".." +
                         std::to_string(offset + out.size()) + " outside the " +
                         std::to_string(image_.size()) + "-byte process image");
  }
  if (!out.empty()) std::memcpy(out.data(), image_.data() + offset, out.size());
  return okStatus();
}

Status Master::sendCycle(SimTime now) {
  if (!cyclic_.built()) {
    return makeError(ErrorCode::kState, "no process data configured (start() first)");
  }
  return cyclic_.send(transport_, image_, now);
}

bool Master::pollCycle(SimTime now) {
  transport_.poll(now);
  return cyclic_.pending();
}

Status Master::exchange() {
  failedSinceControl_.reset();  // the blocking path: control() looks at this cycle only
  ECSIM_TRY(sendCycle(bus_.now()));
  CycleWait wait(cyclic_);
  ECSIM_TRY(run(wait, 4 * transport_.options().timeout, "cycle"));
  return finishCycle();
}

Status Master::finishCycle() {
  lastCycle_ = cyclic_.finish(image_);
  if (!lastCycle_.ok() && !failedSinceControl_) failedSinceControl_ = lastCycle_;
  if (lastCycle_.framesLost > 0) {
    return makeError(ErrorCode::kTimeout,
                     std::to_string(lastCycle_.framesLost) + " cyclic frame(s) lost");
  }
  if (lastCycle_.firstMismatch) {
    return makeError(ErrorCode::kWorkingCounter, lastCycle_.firstMismatch->describe(slaves_));
  }
  return okStatus();
}

Result<std::vector<std::uint8_t>> Master::sdoUpload(std::size_t position, std::uint16_t index,
                                                    std::uint8_t subindex, bool completeAccess) {
  ECSIM_ASSIGN_OR_RETURN(SlaveInfo * slave, slaveAt(position));
  SdoTask task(transport_, *slave, &emergencies_, options_.mailbox);
  ECSIM_TRY(task.startUpload(index, subindex, completeAccess, bus_.now()));
  ECSIM_TRY(run(task, options_.mailboxTimeout, "SDO upload"));
  ECSIM_TRY(task.status());
  return task.data();
}

Status Master::sdoDownload(std::size_t position, std::uint16_t index, std::uint8_t subindex,
                           ConstBytes data, bool completeAccess) {
  ECSIM_ASSIGN_OR_RETURN(SlaveInfo * slave, slaveAt(position));
  SdoTask task(transport_, *slave, &emergencies_, options_.mailbox);
  ECSIM_TRY(task.startDownload(index, subindex, data, completeAccess, bus_.now()));
  ECSIM_TRY(run(task, options_.mailboxTimeout, "SDO download"));
  return task.status();
}

Status Master::eoeSetIp(std::size_t position, const EoeIpParameters& parameters,
                        std::uint8_t port) {
  ECSIM_ASSIGN_OR_RETURN(SlaveInfo * slave, slaveAt(position));
  EoeIpTask task(transport_, *slave, &emergencies_, options_.mailbox);
  ECSIM_TRY(task.startSet(parameters, port, bus_.now()));
  ECSIM_TRY(run(task, options_.mailboxTimeout, "EoE Set IP Parameter"));
  return task.status();
}

Result<EoeIpParameters> Master::eoeGetIp(std::size_t position, std::uint8_t port) {
  ECSIM_ASSIGN_OR_RETURN(SlaveInfo * slave, slaveAt(position));
  EoeIpTask task(transport_, *slave, &emergencies_, options_.mailbox);
  ECSIM_TRY(task.startGet(port, bus_.now()));
  ECSIM_TRY(run(task, options_.mailboxTimeout, "EoE Get IP Parameter"));
  ECSIM_TRY(task.status());
  return task.parameters();
}

Result<std::vector<std::uint8_t>> Master::soeRead(std::size_t position, std::uint8_t driveNo,
                                                  std::uint8_t elements, std::uint16_t idn) {
  ECSIM_ASSIGN_OR_RETURN(SlaveInfo * slave, slaveAt(position));
  SoeTask task(transport_, *slave, &emergencies_, options_.mailbox);
  ECSIM_TRY(task.startRead(driveNo, elements, idn, bus_.now()));
  ECSIM_TRY(run(task, options_.mailboxTimeout, "SoE read"));
  ECSIM_TRY(task.status());
  return task.data();
}

Status Master::soeWrite(std::size_t position, std::uint8_t driveNo, std::uint16_t idn,
                        ConstBytes value) {
  ECSIM_ASSIGN_OR_RETURN(SlaveInfo * slave, slaveAt(position));
  SoeTask task(transport_, *slave, &emergencies_, options_.mailbox);
  ECSIM_TRY(task.startWrite(driveNo, idn, value, bus_.now()));
  ECSIM_TRY(run(task, options_.mailboxTimeout, "SoE write"));
  return task.status();
}

Result<OdList> Master::readOdList(std::size_t position) {
  ECSIM_ASSIGN_OR_RETURN(SlaveInfo * slave, slaveAt(position));
  SdoInfoTask task(transport_, *slave, &emergencies_, options_.mailbox);
  ECSIM_TRY(task.startOdList(OdListType::kAll, bus_.now()));
  ECSIM_TRY(run(task, options_.mailboxTimeout, "OD list"));
  ECSIM_TRY(task.status());
  return std::get<OdList>(*task.response());
}

Result<ObjectDescription> Master::readObjectDescription(std::size_t position, std::uint16_t index) {
  ECSIM_ASSIGN_OR_RETURN(SlaveInfo * slave, slaveAt(position));
  SdoInfoTask task(transport_, *slave, &emergencies_, options_.mailbox);
  ECSIM_TRY(task.startObjectDescription(index, bus_.now()));
  ECSIM_TRY(run(task, options_.mailboxTimeout, "object description"));
  ECSIM_TRY(task.status());
  const auto* d = std::get_if<ObjectDescription>(&*task.response());
  if (d == nullptr) return makeError(ErrorCode::kMalformed, "not an object description");
  return *d;
}

Result<EntryDescription> Master::readEntryDescription(std::size_t position, std::uint16_t index,
                                                      std::uint8_t subindex) {
  ECSIM_ASSIGN_OR_RETURN(SlaveInfo * slave, slaveAt(position));
  SdoInfoTask task(transport_, *slave, &emergencies_, options_.mailbox);
  // Value info 0x07 asks for no unit/default/min/max (what SOEM asks).
  ECSIM_TRY(task.startEntryDescription(index, subindex, 0x07, bus_.now()));
  ECSIM_TRY(run(task, options_.mailboxTimeout, "entry description"));
  ECSIM_TRY(task.status());
  const auto* d = std::get_if<EntryDescription>(&*task.response());
  if (d == nullptr) return makeError(ErrorCode::kMalformed, "not an entry description");
  return *d;
}

Result<std::vector<std::uint8_t>> Master::readRegisters(std::size_t position, std::uint16_t address,
                                                        std::uint16_t length) {
  ECSIM_ASSIGN_OR_RETURN(SlaveInfo * slave, slaveAt(position));
  DatagramBatch batch;
  batch.add().fprd(slave->station, address, length);
  batch.queueAll(transport_);
  BatchWait wait(batch);
  ECSIM_TRY(run(wait, options_.state.timeout, "register read"));
  ECSIM_TRY(batch.check());
  return std::vector<std::uint8_t>(batch[0].data().begin(), batch[0].data().end());
}

Status Master::writeRegisters(std::size_t position, std::uint16_t address, ConstBytes data) {
  ECSIM_ASSIGN_OR_RETURN(SlaveInfo * slave, slaveAt(position));
  DatagramBatch batch;
  batch.add().fpwr(slave->station, address, data);
  batch.queueAll(transport_);
  BatchWait wait(batch);
  ECSIM_TRY(run(wait, options_.state.timeout, "register write"));
  return batch.check();
}

Status Master::cycle() {
  Status status = exchange();
  control(bus_.now());
  return status;
}

void Master::control(SimTime now) {
  const CycleResult& seen = failedSinceControl_ ? *failedSinceControl_ : lastCycle_;
  if (health_) health_->afterCycle(seen, cyclic_.statistics().cycles, now);
  failedSinceControl_.reset();
}

const std::vector<MasterEvent>& Master::events() const {
  return health_ ? health_->events() : noEvents_;
}

void Master::clearEvents() {
  if (health_) health_->clearEvents();
}

MasterHealth Master::health() const {
  return health_ ? health_->health(transport_.counters()) : MasterHealth{};
}

void Master::setCycleTime(SimTime period) {
  options_.cycleTime = period;
  cyclic_.setTiming(period, period);
}

void Master::resetStatistics() {
  cyclic_.resetStatistics();
}

Result<PdoVariable> Master::variable(std::string_view name) {
  if (variables_.empty()) {
    return makeError(ErrorCode::kState, "no process data configured (start() first)");
  }
  ECSIM_ASSIGN_OR_RETURN(VariableInfo info, findVariable(variables_, name));
  return PdoVariable(std::move(info), image_);
}

}  // namespace ecsim::master
