#include "master/pdo_config.hpp"

#include <algorithm>

namespace ecsim::master {
namespace {

constexpr std::uint16_t kSmTypesIndex = 0x1C00;
constexpr std::uint16_t kSmAssignBase = 0x1C10;
constexpr std::uint8_t kSmTypeOutputs = 3;
constexpr std::uint8_t kSmTypeInputs = 4;
constexpr unsigned kFirstProcessDataSm = 2;  // SM0/SM1 are the mailbox

// Up to four little-endian bytes as an unsigned value (devices answer u8 or u16 for counts).
std::uint32_t le(const std::vector<std::uint8_t>& data) {
  std::uint32_t v = 0;
  for (std::size_t i = 0; i < data.size() && i < 4; ++i)
    v |= static_cast<std::uint32_t>(data[i]) << (8 * i);
  return v;
}

const SiiPdo* findSiiPdo(const SlaveInfo& slave, std::uint16_t index) {
  for (const auto* list : {&slave.siiContents.rxPdos, &slave.siiContents.txPdos}) {
    for (const auto& pdo : *list) {
      if (pdo.index == index) return &pdo;
    }
  }
  return nullptr;
}

}  // namespace

std::uint32_t PdoInfo::bitLength() const {
  std::uint32_t bits = 0;
  for (const auto& e : entries) bits += e.bitLength;
  return bits;
}

std::uint32_t SmPdoAssignment::bitLength() const {
  std::uint32_t bits = 0;
  for (const auto& p : pdos) bits += p.bitLength();
  return bits;
}

std::uint32_t SlaveProcessData::outputBits() const {
  std::uint32_t bits = 0;
  for (const auto& sm : sms) bits += sm.outputs ? sm.bitLength() : 0;
  return bits;
}

std::uint32_t SlaveProcessData::inputBits() const {
  std::uint32_t bits = 0;
  for (const auto& sm : sms) bits += sm.outputs ? 0 : sm.bitLength();
  return bits;
}

std::string_view toString(PdoSource source) {
  switch (source) {
    case PdoSource::kNone:
      return "none";
    case PdoSource::kCoe:
      return "CoE";
    case PdoSource::kSii:
      return "SII";
  }
  return "unknown";
}

SlaveProcessData processDataFromSii(const SlaveInfo& slave) {
  SlaveProcessData data;
  const SiiContents& c = slave.siiContents;
  for (std::size_t n = 0; n < c.syncManagers.size(); ++n) {
    const SiiSyncManagerType type = c.syncManagers[n].type;
    if (type != SiiSyncManagerType::kOutputs && type != SiiSyncManagerType::kInputs) continue;
    SmPdoAssignment sm;
    sm.sm = static_cast<unsigned>(n);
    sm.outputs = type == SiiSyncManagerType::kOutputs;
    // The PDOs assigned to the SM say its direction when they all say the other one (the SMC
    // EX250's SII calls its input SM1 "Outputs"), as SOEM's ecx_map_sii sets SMtype 3/4 from
    // the SII RxPDO/TxPDO categories.
    auto assigned = [n](const std::vector<SiiPdo>& pdos) {
      return std::any_of(pdos.begin(), pdos.end(),
                         [n](const SiiPdo& p) { return p.syncManager == n; });
    };
    if (const bool rx = assigned(c.rxPdos); rx != assigned(c.txPdos)) sm.outputs = rx;
    for (const auto& pdo : sm.outputs ? c.rxPdos : c.txPdos) {
      if (pdo.syncManager != n) continue;
      PdoInfo info;
      info.index = pdo.index;
      info.name = std::string(c.string(pdo.nameIndex));
      for (const auto& e : pdo.entries) {
        info.entries.push_back(
            {e.index, e.subIndex, e.bitLength, e.dataType, std::string(c.string(e.nameIndex))});
      }
      sm.pdos.push_back(std::move(info));
    }
    data.sms.push_back(std::move(sm));
  }
  data.source = data.sms.empty() ? PdoSource::kNone : PdoSource::kSii;
  return data;
}

void addSiiNames(const SlaveInfo& slave, SlaveProcessData& data) {
  const SiiContents& c = slave.siiContents;
  for (auto& sm : data.sms) {
    for (auto& pdo : sm.pdos) {
      const SiiPdo* sii = findSiiPdo(slave, pdo.index);
      if (sii == nullptr) continue;
      if (pdo.name.empty()) pdo.name = std::string(c.string(sii->nameIndex));
      for (auto& entry : pdo.entries) {
        for (const auto& e : sii->entries) {
          if (e.index != entry.index || e.subIndex != entry.subindex) continue;
          if (entry.name.empty()) entry.name = std::string(c.string(e.nameIndex));
          if (entry.dataType == 0) entry.dataType = e.dataType;
          break;
        }
      }
    }
  }
}

PdoDiscoveryTask::PdoDiscoveryTask(Transport& transport, SlaveInfo& slave,
                                   std::vector<ReceivedEmergency>* emergencies,
                                   MailboxOptions options)
    : sdo_(transport, slave, emergencies, options), slave_(slave) {}

void PdoDiscoveryTask::read(std::uint16_t index, std::uint8_t subindex, Handler handler) {
  reads_.push_back({index, subindex, std::move(handler)});
}

Status PdoDiscoveryTask::start(SimTime now) {
  result_ = {};
  reads_.clear();
  status_ = okStatus();
  uploads_ = 0;
  running_ = true;
  read(kSmTypesIndex, 0, [this](const Result<std::vector<std::uint8_t>>& r) {
    if (!r.ok()) return;  // no SM types in the dictionary: the SII decides
    const std::uint32_t count = le(*r);
    for (std::uint32_t sm = kFirstProcessDataSm; sm < count && sm < reg::kMaxSyncManagers; ++sm) {
      read(kSmTypesIndex, static_cast<std::uint8_t>(sm + 1),
           [this, sm](const Result<std::vector<std::uint8_t>>& type) {
             if (!type.ok()) return;
             const std::uint32_t t = le(*type);
             if (t != kSmTypeOutputs && t != kSmTypeInputs) return;
             result_.sms.push_back({sm, t == kSmTypeOutputs, {}});
             readAssignment(result_.sms.size() - 1);
           });
    }
  });
  current_ = nullptr;
  if (!next(now)) return status_;
  return okStatus();
}

void PdoDiscoveryTask::readAssignment(std::size_t smPosition) {
  const auto index = static_cast<std::uint16_t>(kSmAssignBase + result_.sms[smPosition].sm);
  read(index, 0, [this, index, smPosition](const Result<std::vector<std::uint8_t>>& r) {
    if (!r.ok()) return;  // not assignable through CoE: no PDOs from here
    const std::uint32_t count = std::min<std::uint32_t>(le(*r), 0xFE);
    result_.sms[smPosition].pdos.resize(count);
    for (std::uint32_t k = 0; k < count; ++k) {
      read(index, static_cast<std::uint8_t>(k + 1),
           [this, smPosition, k](const Result<std::vector<std::uint8_t>>& pdo) {
             if (!pdo.ok()) {
               status_ =
                   makeError(ErrorCode::kAborted, "PDO assignment of SM" +
                                                      std::to_string(result_.sms[smPosition].sm) +
                                                      ": " + pdo.error().context);
               return;
             }
             const auto pdoIndex = static_cast<std::uint16_t>(le(*pdo));
             // A zero entry assigns nothing (dynamic-PDO devices leave unused subindexes 0):
             // skipped, as other masters do; dropped from the list when discovery ends.
             if (pdoIndex == 0) return;
             result_.sms[smPosition].pdos[k].index = pdoIndex;
             readMapping(smPosition, k);
           });
    }
  });
}

void PdoDiscoveryTask::readMapping(std::size_t smPosition, std::size_t pdoPosition) {
  const std::uint16_t index = result_.sms[smPosition].pdos[pdoPosition].index;
  read(
      index, 0, [this, index, smPosition, pdoPosition](const Result<std::vector<std::uint8_t>>& r) {
        if (!r.ok()) {
          status_ = makeError(ErrorCode::kAborted, "mapping of assigned PDO: " + r.error().context);
          return;
        }
        const std::uint32_t count = std::min<std::uint32_t>(le(*r), 0xFE);
        result_.sms[smPosition].pdos[pdoPosition].entries.resize(count);
        for (std::uint32_t k = 0; k < count; ++k) {
          read(index, static_cast<std::uint8_t>(k + 1),
               [this, smPosition, pdoPosition, k](const Result<std::vector<std::uint8_t>>& e) {
                 if (!e.ok()) {
                   status_ =
                       makeError(ErrorCode::kAborted, "PDO mapping entry: " + e.error().context);
                   return;
                 }
                 const std::uint32_t raw = le(*e);
                 auto& entry = result_.sms[smPosition].pdos[pdoPosition].entries[k];
                 entry.index = static_cast<std::uint16_t>(raw >> 16);
                 entry.subindex = static_cast<std::uint8_t>(raw >> 8);
                 entry.bitLength = static_cast<std::uint8_t>(raw);
               });
        }
      });
}

bool PdoDiscoveryTask::next(SimTime now) {
  if (!status_.ok() || reads_.empty()) {
    running_ = false;
    if (status_.ok()) {
      for (auto& sm : result_.sms) {
        std::erase_if(sm.pdos, [](const auto& pdo) { return pdo.index == 0; });
      }
      result_.source = result_.sms.empty() ? PdoSource::kNone : PdoSource::kCoe;
      addSiiNames(slave_, result_);
    }
    return false;
  }
  Read r = std::move(reads_.front());
  reads_.pop_front();
  current_ = std::move(r.handler);
  ++uploads_;
  if (auto s = sdo_.startUpload(r.index, r.subindex, false, now); !s.ok()) {
    status_ = s;
    running_ = false;
    return false;
  }
  return true;
}

bool PdoDiscoveryTask::step(SimTime now) {
  if (!running_) return false;
  if (current_) {
    if (sdo_.step(now)) return true;
    Handler handler = std::move(current_);
    current_ = nullptr;
    const Status& s = sdo_.status();
    if (!s.ok() && s.error().code != ErrorCode::kAborted) {
      status_ = s;  // timeout, mailbox error: the slave cannot be asked
      running_ = false;
      return false;
    }
    if (s.ok()) {
      handler(sdo_.data());
    } else {
      handler(s.error());
    }
  }
  return next(now);
}

}  // namespace ecsim::master
