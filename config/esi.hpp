// ESI (EtherCAT Slave Information, ETG.2000) reader: vendor XML files into plain structs.
//
// Reads the three roots met in real files: EtherCATInfo (vendor, groups, devices, modules),
// EtherCATDict (a dictionary only) and EtherCATModule (modules only). Numbers may be written
// `#x1A00`, `0xF3F` or decimal; booleans `1/0/true/false`. Text is kept as the file's bytes
// (names may be Latin-1 when the XML declaration says ISO-8859-1: see EsiFile::encoding and
// latin1ToUtf8()). Every error names the file and the line: "<file>, line <n>: <what>".
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/result.hpp"

namespace ecsim {

enum class EsiEncoding : std::uint8_t { kUtf8, kLatin1 };

// A text with its language (LcId 1033 English, 1031 German, ...).
struct EsiLocalText {
  std::uint32_t lcid{0};  // 0 when the element has no LcId
  std::string text;
};

// Picks the text for `lcid`, else one without LcId, else English, else the first one.
std::string_view pickLocalText(const std::vector<EsiLocalText>& texts, std::uint32_t lcid = 1033);

struct EsiVendor {
  std::uint32_t id{0};
  std::vector<EsiLocalText> names;
  std::string name() const { return std::string(pickLocalText(names)); }
};

struct EsiGroup {
  std::string type;
  std::vector<EsiLocalText> names;
};

struct EsiFmmu {
  std::string text;  // Outputs, Inputs, MBoxState (or a vendor's own word)
  std::optional<std::uint8_t> sm;
  bool opOnly{false};
};

struct EsiSyncManager {
  std::string text;  // MBoxOut, MBoxIn, Outputs, Inputs (or a vendor's own word)
  std::uint16_t startAddress{0};
  std::uint16_t defaultSize{0};  // 0 when absent
  std::optional<std::uint16_t> minSize;
  std::optional<std::uint16_t> maxSize;
  std::uint8_t controlByte{0};
  // Enable attribute: 1/true -> 1, 0/false -> 0; a number is kept as written (SMC writes
  // Enable="9", the SII enable byte with its OpOnly bit).
  std::uint8_t enable{0};
  bool isVirtual{false};
  bool opOnly{false};
  bool fixed{false};
};

struct EsiPdoEntry {
  std::uint16_t index{0};  // 0 = gap (padding bits)
  std::uint8_t subIndex{0};
  std::uint16_t bitLength{0};
  std::string name;
  std::string dataType;  // BOOL, UINT, DINT, ... as written
  bool dependOnSlot{false};
};

struct EsiPdo {
  std::uint16_t index{0};
  std::vector<EsiLocalText> names;
  std::optional<std::uint8_t> sm;  // absent: an optional alternative, not assigned by default
  bool fixed{false};
  bool mandatory{false};
  bool isVirtual{false};
  bool dependOnSlot{false};
  std::vector<std::uint16_t> excludes;
  std::vector<EsiPdoEntry> entries;
  std::string ref;  // 2006-era files: Ref/RefName of a shared <Pdos><Pdo> template
  int line{0};

  std::string name() const { return std::string(pickLocalText(names)); }
  std::uint32_t bitLength() const;
  // A PDO the dictionary can hold as a mapping object: 0x1600-0x1BFF (RxPDOs 0x1600-0x17FF and
  // TxPDOs 0x1A00-0x1BFF in ETG.1000.6, plus 0x1800-0x19FF, which EtherCAT leaves free and
  // vendors use: Orbita2d.xml's TxPdo 0x1800, kept in its real SII image Orbita2d.bin). Others
  // collide with communication objects (Beckhoff_EL1xxx_2011.xml's EL1262 TxPdo 0x1C00 would be
  // 0x1C00, the SM types) and are left out of the dictionary and the SII PDO categories alike,
  // so SII and CoE give a master the same SM sizes.
  constexpr bool inCoeRange() const { return index >= 0x1600 && index <= 0x1BFF; }
};

struct EsiCoe {
  bool sdoInfo{false};
  bool pdoAssign{false};
  bool pdoConfig{false};
  bool pdoUpload{false};
  bool completeAccess{false};
  bool segmentedSdo{false};
  std::uint8_t ds402Channels{0};
};

struct EsiMailbox {
  bool present{false};
  bool dataLinkLayer{false};
  bool aoe{false};
  bool eoe{false};
  bool coe{false};
  bool foe{false};
  bool soe{false};
  bool voe{false};
  std::uint8_t soeChannels{0};
  EsiCoe coeDetails;
  // SII word 0x1C bits (AoE 0x01, EoE 0x02, CoE 0x04, FoE 0x08, SoE 0x10, VoE 0x20).
  std::uint16_t protocolMask() const;
};

struct EsiDcOpMode {
  std::string name;
  std::string description;
  std::uint16_t assignActivate{0};
  std::uint32_t cycleTimeSync0{0};
  std::int32_t cycleTimeSync0Factor{0};
  std::int64_t shiftTimeSync0{0};
  std::uint32_t cycleTimeSync1{0};
  std::int32_t cycleTimeSync1Factor{0};
  std::int64_t shiftTimeSync1{0};
};

struct EsiEepromCategory {
  std::uint16_t type{0};
  std::vector<std::uint8_t> data;
};

struct EsiEeprom {
  std::optional<std::uint32_t> byteSize;
  std::vector<std::uint8_t> configData;  // words 0x00.. as bytes (usually 8 to 14 bytes)
  std::vector<std::uint8_t> bootStrap;   // 8 bytes: words 0x14-0x17
  std::vector<std::uint8_t> data;        // a complete image, when the vendor gives one
  std::vector<EsiEepromCategory> categories;
};

// Access flags of an object or sub-item.
enum class EsiAccess : std::uint8_t { kUnspecified, kReadOnly, kReadWrite, kWriteOnly };
struct EsiFlags {
  EsiAccess access{EsiAccess::kUnspecified};
  std::string readRestrictions;   // e.g. "PreOP", "PreOP_SafeOP_OP" (empty: none)
  std::string writeRestrictions;  // e.g. "PreOP"
  std::string category;           // m, o, c
  std::string pdoMapping;         // R, T, RT (as written, case kept)
  // <Attribute> of an SoE IDN (EtherCATDict files: protocol/soe.hpp SoeAttribute bits).
  std::optional<std::uint32_t> soeAttribute;
  bool rxMappable() const;
  bool txMappable() const;
};

struct EsiSubItemType {  // a DataType's SubItem
  std::uint8_t subIndex{0};
  std::string name;
  std::string type;
  std::uint32_t bitSize{0};
  std::uint32_t bitOffset{0};
  EsiFlags flags;
};

struct EsiArrayInfo {
  std::int64_t lowerBound{0};
  std::uint32_t elements{0};
};

struct EsiDataType {
  std::string name;
  std::string baseType;
  std::uint32_t bitSize{0};
  std::vector<EsiArrayInfo> arrays;  // one per dimension
  std::vector<EsiSubItemType> subItems;
  bool isArray() const { return !arrays.empty(); }
  bool isRecord() const { return !subItems.empty(); }
};

// Default and limits from an Info element. Numbers are kept as written (they may be hex,
// decimal or out of range for the type); DefaultData is hex bytes in wire order.
struct EsiValueInfo {
  std::vector<std::uint8_t> defaultData;
  std::optional<std::string> defaultValue;
  std::optional<std::string> defaultString;
  std::optional<std::string> minValue;
  std::optional<std::string> maxValue;
};

struct EsiSubItemInfo {
  std::string name;
  EsiValueInfo info;
  std::optional<EsiFlags> flags;
};

struct EsiObject {
  std::uint32_t index{0};  // CoE index, or an SoE IDN in an EtherCATDict file
  std::vector<EsiLocalText> names;
  std::string type;
  std::uint32_t bitSize{0};
  EsiValueInfo info;
  std::vector<EsiSubItemInfo> subItems;
  EsiFlags flags;
  bool dependOnSlot{false};  // <Index DependOnSlot="1">: a module's object, moved per slot
  // <Properties><Property><Name>UnitName</Name><Desc>us</Desc> (SoE dictionaries): the unit.
  std::string unitName;
  int line{0};
  std::string name() const { return std::string(pickLocalText(names)); }
};

struct EsiDictionary {
  std::vector<EsiDataType> dataTypes;
  std::vector<EsiObject> objects;
  const EsiObject* findObject(std::uint32_t index) const;
  const EsiDataType* findDataType(std::string_view name) const;
};

// A <Slot> of a modular device (ETG.2001): which modules it takes, and how the objects and
// PDOs of the module in slot instance k (counted from 0 over the device's slots) move:
// index + k * indexIncrement (objects, PDO entries), + k * pdoIncrement (PDOs, mapping objects).
struct EsiSlot {
  std::string name;
  std::uint32_t minInstances{0};
  std::uint32_t maxInstances{0};
  std::vector<std::string> moduleClasses;
  std::vector<std::uint32_t> moduleIdents;
  std::optional<std::uint32_t> defaultModuleIdent;  // <ModuleIdent Default="1">
  std::uint32_t indexIncrement{0};  // Slot@SlotIndexIncrement, else Slots@SlotIndexIncrement
  std::uint32_t pdoIncrement{0};    // Slot@SlotPdoIncrement, else Slots@SlotPdoIncrement
  int line{0};
};

struct EsiModule {
  std::string type;
  std::uint32_t moduleIdent{0};
  std::string moduleClass;
  std::vector<EsiLocalText> names;
  std::vector<EsiPdo> rxPdos;
  std::vector<EsiPdo> txPdos;
  EsiDictionary dictionary;
  int line{0};
  std::string name() const { return std::string(pickLocalText(names)); }
};

struct EsiDevice {
  std::string type;  // <Type> text, trimmed (e.g. "EK1100"): the order/type name
  std::uint32_t productCode{0};
  std::uint32_t revision{0};
  bool hasProductCode{false};  // placeholder devices (EK0000, ...) have none
  std::vector<EsiLocalText> names;
  std::string groupType;
  std::string physics;  // one letter per port, blanks for absent ports: "YY", "K KY"
  bool invisible{false};
  bool useLrdLwr{false};
  std::optional<std::int32_t> ebusCurrent;  // mA
  // How a master reads the device's ID switch (ETG.2000 Info, ETG.1020 explicit device
  // identification): at an address of the ESC memory (IdentificationAdo, e.g. an EK1101's
  // 0x1000, where its ESC in digital I/O mode keeps the switch's inputs), or in 0x0134 on
  // request through AL control bit 5 (IdentificationReg134).
  std::optional<std::uint16_t> identificationAdo;
  bool identificationReg134{false};
  std::optional<std::uint32_t> profileNo;
  std::string imageName;  // <Image16x14> (a name; ImageData16x14 blobs are not kept)
  std::vector<EsiFmmu> fmmus;
  std::vector<EsiSyncManager> syncManagers;
  std::vector<EsiPdo> rxPdos;
  std::vector<EsiPdo> txPdos;
  EsiMailbox mailbox;
  std::vector<EsiDcOpMode> dcOpModes;
  std::optional<EsiEeprom> eeprom;
  EsiDictionary dictionary;
  std::vector<EsiSlot> slots;
  std::vector<EsiModule> modules;
  // Module idents of the modules instantiated into this description (config/esi_modules.hpp),
  // in slot order: the configured and detected module lists 0xF030/0xF050 (ETG.5001).
  std::vector<std::uint32_t> moduleIdents;
  int line{0};

  std::string name(std::uint32_t lcid = 1033) const {
    return std::string(pickLocalText(names, lcid));
  }
};

enum class EsiRoot : std::uint8_t { kEtherCatInfo, kEtherCatDict, kEtherCatModule };

struct EsiFile {
  std::string path;  // as given to the reader, used in messages
  EsiRoot root{EsiRoot::kEtherCatInfo};
  std::string version;  // root Version attribute, may be empty
  EsiEncoding encoding{EsiEncoding::kUtf8};
  EsiVendor vendor;
  std::vector<EsiGroup> groups;
  std::vector<EsiDevice> devices;
  std::vector<EsiModule> modules;  // EtherCATModule root
  EsiDictionary dictionary;        // EtherCATDict root
  // What the reader replaced or left out to go on ("<file>, line <n>: ..."): a malformed value
  // inside one object costs that value (or that object), not the file.
  std::vector<std::string> warnings;

  // Text of this file for display: Latin-1 bytes converted to UTF-8 when the file says so.
  std::string display(std::string_view text) const;
  const EsiGroup* findGroup(std::string_view type) const;
};

// Parses ESI XML held in memory; `fileName` is used in error messages.
Result<EsiFile> parseEsi(std::string_view xml, std::string_view fileName);
// Reads and parses a file (kIo if it cannot be read).
Result<EsiFile> loadEsiFile(const std::filesystem::path& path);

// ESI value syntax, exposed for other readers (ENI, topology files) and tests.
// Integers: "#x1A00", "#X1a00", "0xF3F", "4919", "-2000" (surrounding blanks ignored), and
// "#x0x6041" (both prefixes, as the Orbita2d ESI writes its PDO entry indexes).
Result<std::int64_t> parseEsiInteger(std::string_view text);
// Booleans: "1", "0", "true", "false" (any case).
Result<bool> parseEsiBool(std::string_view text);
// Hex bytes "0800006600010000" (even number of digits, blanks ignored).
Result<std::vector<std::uint8_t>> parseEsiHexBinary(std::string_view text);
// ISO-8859-1 bytes to UTF-8.
std::string latin1ToUtf8(std::string_view latin1);
// Trims ASCII white space (blank, tab, CR, LF) at both ends.
std::string_view trimEsiText(std::string_view text);

}  // namespace ecsim
