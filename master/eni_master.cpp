// The Master's use of an ENI configuration: station addresses (PhysAddr) and mailbox areas
// after the scan, and the init commands of each transition (ETG.2100): register commands and
// CoE commands before the state is requested, CoE commands of IP once PREOP is reached (a
// mailbox exists only from PREOP on).
#include "master/master.hpp"

#include <cstdio>

#include "master/batch.hpp"

namespace ecsim::master {
namespace {

std::string hex4(unsigned v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04X", v);
  return buf;
}

}  // namespace

Status Master::applyEniSetup() {
  initCmdsDoneFor_.reset();
  transitionFrom_.clear();
  if (!config_ || !config_->eni) return okStatus();
  const EniConfig& eni = *config_->eni;
  DatagramBatch batch;
  for (std::size_t i = 0; i < slaves_.size() && i < eni.slaves.size(); ++i) {
    const EniSlave& want = eni.slaves[i];
    if (slaves_[i].station != want.physAddr) {
      batch.add().write(Command::kApwr, Datagram::autoIncrement(i),
                        reg::kConfiguredStationAddress, want.physAddr);
    }
    if (want.mailbox && slaves_[i].mailbox) {
      MailboxConfig& m = *slaves_[i].mailbox;
      m.outStart = want.mailbox->sendStart;
      m.outSize = want.mailbox->sendLength;
      m.inStart = want.mailbox->recvStart;
      m.inSize = want.mailbox->recvLength;
    }
  }
  if (batch.empty()) return okStatus();
  batch.queueAll(transport_);
  BatchWait wait(batch);
  ECSIM_TRY(run(wait, options_.state.timeout, "station addresses from " + config_->file));
  if (auto s = batch.check(); !s.ok()) {
    return makeError(s.error().code,
                     "station addresses from " + config_->file + ": " + s.error().context);
  }
  for (std::size_t i = 0; i < slaves_.size() && i < eni.slaves.size(); ++i) {
    slaves_[i].station = eni.slaves[i].physAddr;
  }
  return okStatus();
}

Status Master::runInitCommands(AlState target, InitPhase phase) {
  if (!config_ || !config_->eni) return okStatus();
  const EniConfig& eni = *config_->eni;
  const std::string file = eni.file.string();
  const char to = eniStateLetter(target);
  const std::size_t count = std::min(slaves_.size(), eni.slaves.size());
  auto coeCommands = [&](bool fromInit) -> Status {
    for (std::size_t i = 0; i < count; ++i) {
      const char from = transitionFrom_[i];
      if ((from == 'I') != fromInit) continue;
      for (const EniCoeCmd* c : eniCoeCmds(eni.slaves[i], from, to)) {
        const std::string what = "CoE init command 0x" + hex4(c->index) + ":" +
                                 std::to_string(c->subIndex) + " (" + std::string{from, to} +
                                 ") of " + slaves_[i].label() + ", " + file + " line " +
                                 std::to_string(c->line);
        Status s = okStatus();
        if (c->ccs == 1) {
          s = sdoDownload(i, c->index, c->subIndex, ConstBytes(c->data.data(), c->data.size()),
                          c->completeAccess);
        } else if (auto up = sdoUpload(i, c->index, c->subIndex, c->completeAccess); !up.ok()) {
          s = up.takeError();
        }
        if (!s.ok()) return makeError(s.error().code, what + ": " + s.error().context);
      }
    }
    return okStatus();
  };
  if (phase == InitPhase::kAfter) {
    initCmdsDoneFor_.reset();
    if (transitionFrom_.size() < count) return okStatus();
    Status s = coeCommands(true);
    transitionFrom_.clear();
    return s;
  }
  if (initCmdsDoneFor_ == target) return okStatus();
  // A caller that scanned and went on without start() (tools: scan, then bringTo) has not set
  // the ENI's station addresses yet; its init commands may (APWR 0x0010), and the master must
  // know them first.
  for (std::size_t i = 0; i < count; ++i) {
    if (slaves_[i].station != eni.slaves[i].physAddr) {
      ECSIM_TRY(applyEniSetup());
      break;
    }
  }
  initCmdsDoneFor_ = target;
  transitionFrom_.assign(slaves_.size(), 'I');
  for (std::size_t i = 0; i < slaves_.size(); ++i) {
    transitionFrom_[i] = eniStateLetter(slaves_[i].state().value_or(AlState::kInit));
  }
  // Register commands of every slave together, then CoE commands slave by slave.
  DatagramBatch batch;
  std::vector<std::size_t> owners;  // per datagram: the slave
  std::vector<int> lines;           // per datagram: the ENI line of its command
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t added =
        addEniRegisterCmds(batch, eni.slaves[i], transitionFrom_[i], to, &lines);
    owners.insert(owners.end(), added, i);
  }
  if (!batch.empty()) {
    batch.queueAll(transport_);
    BatchWait wait(batch);
    ECSIM_TRY(run(wait, options_.state.timeout, "ENI init commands"));
    for (std::size_t d = 0; d < batch.size(); ++d) {
      if (auto s = batch[d].check(); !s.ok()) {
        return makeError(s.error().code, "register init command of " + slaves_[owners[d]].label() +
                                             " (" + std::string{transitionFrom_[owners[d]], to} +
                                             "), " + file + " line " + std::to_string(lines[d]) +
                                             ": " + s.error().context);
      }
    }
  }
  return coeCommands(false);
}

}  // namespace ecsim::master
