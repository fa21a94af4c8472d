// Which PDOs a slave exchanges through which SyncManager, found without a configuration file:
//
//   from CoE (the slave's dictionary; the order SOEM reads it, notes/soem-interop.md §3.5):
//     0x1C00:00 number of SMs, 0x1C00:n+1 type of SM n (3 outputs, 4 inputs);
//     0x1C10+n:00 / :k the PDOs assigned to SM n; PDO:00 / :k its mapping (u32 = index << 16 |
//     subindex << 8 | bit length)
//   from the SII (ETG.2010 TXPDO/RXPDO categories): the PDOs whose SM field names a
//     process-data SM of the SM category - for slaves without CoE, or when CoE gives no bits
//
// Names come from the SII strings of the PDO and entry with the same index where the SII has
// them (the dictionary's own names would need SDO information).
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <string>
#include <vector>

#include "master/coe_client.hpp"
#include "master/slave_info.hpp"

namespace ecsim::master {

struct PdoEntryInfo {
  std::uint16_t index{0};  // 0: a gap of bitLength bits
  std::uint8_t subindex{0};
  std::uint8_t bitLength{0};
  std::uint16_t dataType{0};  // from the SII where known, else 0
  std::string name;
  bool operator==(const PdoEntryInfo&) const = default;
};

struct PdoInfo {
  std::uint16_t index{0};
  std::string name;
  std::vector<PdoEntryInfo> entries;
  std::uint32_t bitLength() const;
  bool operator==(const PdoInfo&) const = default;
};

struct SmPdoAssignment {
  unsigned sm{0};
  bool outputs{true};
  std::vector<PdoInfo> pdos;
  std::uint32_t bitLength() const;
  bool operator==(const SmPdoAssignment&) const = default;
};

enum class PdoSource : std::uint8_t { kNone, kCoe, kSii };
std::string_view toString(PdoSource source);

struct SlaveProcessData {
  PdoSource source{PdoSource::kNone};
  std::vector<SmPdoAssignment> sms;  // process-data SMs in SM order (0 bits included)
  std::uint32_t outputBits() const;
  std::uint32_t inputBits() const;
};

// The SII's view: every outputs/inputs SM of the SM category with the PDOs assigned to it.
SlaveProcessData processDataFromSii(const SlaveInfo& slave);
// Names (PDO and entries) and data types from the SII for PDOs found through CoE.
void addSiiNames(const SlaveInfo& slave, SlaveProcessData& data);

// Reads the PDO assignment and mapping of one CoE slave. status() is ok also when the
// dictionary has no 0x1C00 (the result is then empty: use the SII); an SDO failure other than
// an abort (timeout, mailbox error) is an error.
class PdoDiscoveryTask final : public Task {
 public:
  PdoDiscoveryTask(Transport& transport, SlaveInfo& slave,
                   std::vector<ReceivedEmergency>* emergencies, MailboxOptions options = {});

  Status start(SimTime now);
  bool step(SimTime now) override;
  std::optional<SimTime> wakeAt() const override { return sdo_.wakeAt(); }
  const Status& status() const { return status_; }
  const SlaveProcessData& result() const { return result_; }
  std::uint64_t uploads() const { return uploads_; }

 private:
  using Handler = std::function<void(const Result<std::vector<std::uint8_t>>&)>;
  struct Read {
    std::uint16_t index;
    std::uint8_t subindex;
    Handler handler;
  };
  void read(std::uint16_t index, std::uint8_t subindex, Handler handler);
  bool next(SimTime now);
  void readAssignment(std::size_t smPosition);
  void readMapping(std::size_t smPosition, std::size_t pdoPosition);

  SdoTask sdo_;
  SlaveInfo& slave_;
  Status status_;
  bool running_{false};
  std::deque<Read> reads_;
  Handler current_;
  SlaveProcessData result_;
  std::uint64_t uploads_{0};
};

}  // namespace ecsim::master
