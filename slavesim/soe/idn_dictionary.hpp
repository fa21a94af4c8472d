// The IDNs of one SoE drive (IEC 61800-7-204 data blocks: name, attribute, unit, minimum,
// maximum, operation data, default), built from an ESI EtherCATDict file whose <Object>
// <Index> are IDNs (Beckhoff's AX5000 dictionaries, e.g.
// ../shared/esi/Beckhoff_AX5021-xxxx-0001_Dict.xml):
//
//   <Name>                 the name element
//   <Flags><Attribute>     the attribute (protocol/soe.hpp SoeAttribute): element length,
//                          list, procedure command, data type, write protection per phase
//   <BitSize>              a list's maximum: BitSize / 8 bytes, less the 4-byte list header
//   <Info><DefaultValue>   operation data at power-up and the default element (fixed length)
//   <Info><Min/MaxValue>   the minimum and maximum elements (fixed length)
//   UnitName property      the unit element
//   <Flags><PdoMapping>    T: configurable in the AT (S-0-0187), R: in the MDT (S-0-0188)
//
// The lists a drive derives from its own dictionary are filled here: S-0-0017 (all IDNs),
// S-0-0025 (procedure commands), S-0-0187 / S-0-0188 (configurable AT / MDT data), and the
// AT / MDT configuration lists S-0-0016 / S-0-0024 start with the configurable IDNs that fit
// them (ecsim's choice: the dictionary gives no power-up telegram; a master writes its own in
// PREOP). IDNs the drive must have and the file lacks are added with the standard names.
// What cannot be taken as written (an object without attribute, a value that is no number or
// out of its element's range) is a warning naming the file and line, and the object or value
// is left out.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "config/esi.hpp"
#include "protocol/soe.hpp"

namespace ecsim::slavesim::soe {

namespace idn {
constexpr std::uint16_t kAtConfiguration = 16;        // S-0-0016
constexpr std::uint16_t kAllIdns = 17;                // S-0-0017
constexpr std::uint16_t kMdtConfiguration = 24;       // S-0-0024
constexpr std::uint16_t kProcedureCommands = 25;      // S-0-0025
constexpr std::uint16_t kClass1Diagnostic = 11;       // S-0-0011
constexpr std::uint16_t kResetClass1Diagnostic = 99;  // S-0-0099
constexpr std::uint16_t kMasterControlWord = 134;     // S-0-0134, always in the MDT
constexpr std::uint16_t kDriveStatusWord = 135;       // S-0-0135, always in the AT
constexpr std::uint16_t kConfigurableAt = 187;        // S-0-0187
constexpr std::uint16_t kConfigurableMdt = 188;       // S-0-0188
}  // namespace idn

struct IdnEntry {
  std::uint16_t idn{0};
  std::string name;
  SoeAttribute attribute;
  std::string unit;
  // Fixed length: attribute.elementSize() bytes. List: the data after the list header.
  std::vector<std::uint8_t> value;
  std::uint16_t maxListLength{0};  // bytes, lists only
  std::optional<std::vector<std::uint8_t>> minimum;
  std::optional<std::vector<std::uint8_t>> maximum;
  std::optional<std::vector<std::uint8_t>> defaultValue;
  bool inAt{false};   // <PdoMapping> T
  bool inMdt{false};  // <PdoMapping> R
  // Procedure commands: the acknowledgement (soe_command::kState*) and when a command in
  // progress finishes.
  std::uint16_t commandState{soe_command::kStateCancelled};
  std::int64_t commandDoneAt{0};

  // The value element as sent: a list with its header.
  std::vector<std::uint8_t> valueElement() const;
};

class IdnDictionary {
 public:
  IdnEntry* find(std::uint16_t idn);
  const IdnEntry* find(std::uint16_t idn) const;
  // Adds or replaces.
  void add(IdnEntry entry);
  // Every IDN, in ascending order (S before P).
  std::vector<std::uint16_t> idns() const;
  std::size_t size() const { return entries_.size(); }
  // The IDNs of a list entry (2-byte elements); empty if none or not a list.
  std::vector<std::uint16_t> idnList(std::uint16_t idn) const;
  void setIdnList(std::uint16_t idn, const std::vector<std::uint16_t>& idns);

 private:
  std::map<std::uint16_t, IdnEntry> entries_;
};

// Builds a drive's IDNs from an EtherCATDict dictionary (`file` names it in warnings), then
// derives the standard lists. `warnings` may be null.
IdnDictionary buildIdnDictionary(const EsiDictionary& dictionary, std::string_view file,
                                 std::vector<std::string>* warnings);

}  // namespace ecsim::slavesim::soe
