// Modular devices (ETG.2001 modular device profile, ETG.5001 MDP): a head station whose <Slots>
// take modules (<Module>, in its own file, another ESI file or an EtherCATModule file). A
// configuration tool (TwinCAT) puts modules into the slots; the device then has the head's
// PDOs and objects plus each module's, moved per slot:
//   slot instance k (counted from 0 over the device's slots, in order),
//   PDO index with DependOnSlot          + k * SlotPdoIncrement,
//   mapping objects 0x1600-0x1BFF        + k * SlotPdoIncrement (they are the PDOs),
//   other objects and PDO entry indexes  + k * SlotIndexIncrement (DependOnSlot only),
// e.g. Weidmueller_UR20_FBC.xml <Slots SlotIndexIncrement="16" SlotPdoIncrement="1">: the
// UR20-4DI-P (Weidmueller_UR20_IO.xml, TxPdo #x1A00, entries #x6000) in slot 2 has TxPdo
// 0x1A02 mapping 0x6020:01... The module idents in slot order become 0xF030/0xF050.
// Without a choice, each slot with a default module (<ModuleIdent Default="1">) gets
// max(MinInstances, 1) of it; slots without a default stay empty.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "config/esi.hpp"
#include "protocol/result.hpp"

namespace ecsim {

// Where modules are looked up: the device's own <Modules>, then each file's, in order.
class EsiModuleCatalog {
 public:
  void add(const EsiFile& file);
  void add(const std::vector<EsiModule>& modules);
  const EsiModule* findByIdent(std::uint32_t ident) const;
  const EsiModule* findByType(std::string_view type) const;
  // All module type names (for "did you mean").
  std::vector<std::string_view> typeNames() const;
  bool empty() const { return modules_.empty(); }

 private:
  std::vector<const EsiModule*> modules_;
};

// The slots' default modules (see above); empty when no slot names one.
Result<std::vector<const EsiModule*>> defaultModules(const EsiDevice& device,
                                                     const EsiModuleCatalog& catalog);

// `device` with `modules` in its slot instances 0, 1, ... (checked against the slots' module
// classes/idents and instance counts): PDOs, dictionary objects and data types added, the
// process-data SMs' default sizes from the assigned PDOs, moduleIdents filled in. Notes on
// what was adjusted (an object a module brings that the device already has) go to `notes`.
Result<EsiDevice> instantiateModules(const EsiDevice& device,
                                     const std::vector<const EsiModule*>& modules,
                                     std::vector<std::string>* notes = nullptr);

}  // namespace ecsim
