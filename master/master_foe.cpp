// BOOT state and FoE of class Master (master.hpp): the bootstrap mailbox from the SII, the
// state change for one slave, and FoE transfers through master/foe_client.hpp.
#include <algorithm>

#include "master/batch.hpp"
#include "master/esc_config.hpp"
#include "master/foe_client.hpp"
#include "master/master.hpp"
#include "master/state_change.hpp"

namespace ecsim::master {
namespace {

// One slave to `target` with StateChangeTask on a copy of it; the AL status read comes back.
template <typename Run>
Status changeState(Transport& transport, SlaveInfo& slave, AlState target,
                   const StateChangeOptions& options, SimTime now, Run&& run) {
  std::vector<SlaveInfo> one{slave};
  StateChangeTask task(transport, one, options);
  task.start(target, now);
  Status ran = run(task);
  slave.alStatus = one.front().alStatus;
  slave.alStatusCode = one.front().alStatusCode;
  ECSIM_TRY(ran);
  return task.status();
}

}  // namespace

Status Master::enterBootstrap(std::size_t position) {
  ECSIM_ASSIGN_OR_RETURN(SlaveInfo * slave, slaveAt(position));
  const SiiMailbox& boot = slave->siiContents.bootstrapMailbox;
  if (!slave->mailbox || boot.receiveSize == 0 || boot.sendSize == 0) {
    return makeError(ErrorCode::kUnsupported,
                     slave->label() + " has no bootstrap mailbox in its SII (words 0x14-0x17)");
  }
  const SimTime timeout = options_.state.timeout + kNsPerSecond;
  auto runIt = [&](Task& task) { return run(task, timeout, "state change"); };
  if (slave->state().value_or(AlState::kInit) != AlState::kBootstrap) {
    ECSIM_TRY(changeState(transport_, *slave, AlState::kInit, options_.state, bus_.now(), runIt));
  }
  // SOEM's firm_update: SM0/SM1 from the SII bootstrap words, control bytes as for the
  // standard mailbox.
  if (!slave->standardMailbox) slave->standardMailbox = slave->mailbox;
  MailboxConfig m = *slave->standardMailbox;
  m.outStart = boot.receiveOffset;
  m.outSize = boot.receiveSize;
  m.inStart = boot.sendOffset;
  m.inSize = boot.sendSize;
  slave->mailbox = m;
  // Both off first, then the bootstrap layout (addMailboxSetup).
  DatagramBatch batch;
  addMailboxSetup(batch, *slave);
  batch.queueAll(transport_);
  BatchWait wait(batch);
  ECSIM_TRY(run(wait, options_.state.timeout, "bootstrap mailbox setup"));
  ECSIM_TRY(batch.check());
  return changeState(transport_, *slave, AlState::kBootstrap, options_.state, bus_.now(), runIt);
}

Status Master::leaveBootstrap(std::size_t position) {
  ECSIM_ASSIGN_OR_RETURN(SlaveInfo * slave, slaveAt(position));
  const SimTime timeout = options_.state.timeout + kNsPerSecond;
  auto runIt = [&](Task& task) { return run(task, timeout, "state change"); };
  Status s = changeState(transport_, *slave, AlState::kInit, options_.state, bus_.now(), runIt);
  if (slave->standardMailbox) {
    slave->mailbox = slave->standardMailbox;
    slave->standardMailbox.reset();
  }
  return s;
}

Status Master::foeWrite(std::size_t position, const std::string& name, ConstBytes data,
                        std::uint32_t password) {
  ECSIM_ASSIGN_OR_RETURN(SlaveInfo * slave, slaveAt(position));
  FoeTask task(transport_, *slave, &emergencies_, options_.mailbox);
  ECSIM_TRY(task.startWrite(name, password, data, bus_.now()));
  // A transfer of many packets: each packet has the mailbox timeout.
  const std::size_t per = std::max<std::size_t>(1, foeDataPerPacket(slave->mailbox->outSize));
  const std::size_t packets = data.size() / per + 2;
  ECSIM_TRY(run(task, options_.mailboxTimeout * static_cast<SimTime>(packets), "FoE write"));
  return task.status();
}

Result<std::vector<std::uint8_t>> Master::foeRead(std::size_t position, const std::string& name,
                                                  std::uint32_t password) {
  ECSIM_ASSIGN_OR_RETURN(SlaveInfo * slave, slaveAt(position));
  FoeTask task(transport_, *slave, &emergencies_, options_.mailbox);
  ECSIM_TRY(task.startRead(name, password, bus_.now()));
  // The size is unknown until the end; each exchange has its own response timeout, this only
  // bounds the whole (64 Ki mailbox timeouts).
  constexpr SimTime kMaxPackets = 1 << 16;
  ECSIM_TRY(run(task, options_.mailboxTimeout * kMaxPackets, "FoE read"));
  ECSIM_TRY(task.status());
  return task.data();
}

}  // namespace ecsim::master
