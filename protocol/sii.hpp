// The SII (Slave Information Interface) EEPROM image: ETG.2010 and the ESC datasheet section I
// §11 (Tables 42/43). The image is a sequence of little-endian 16-bit words:
//
//   0x00-0x07  configuration area: PDI control, PDI configuration, SYNC impulse length,
//              extended PDI configuration, configured station alias, 2 reserved words,
//              checksum (low byte of word 7: CRC-8, x^8+x^2+x+1, init 0xFF, over bytes 0..13)
//   0x08-0x0F  identity: vendor id, product code, revision, serial number (u32 each)
//   0x14-0x17  bootstrap mailbox: receive offset/size, send offset/size
//   0x18-0x1B  standard mailbox:  receive offset/size, send offset/size
//   0x1C       supported mailbox protocols (SiiMailboxProtocol bits)
//   0x3E       EEPROM size: (size in Kbit) - 1       0x3F  version
//   0x40...    categories: u16 type, u16 length in words, data; type 0xFFFF ends the list
//
// "Receive" is seen from the slave: the receive mailbox is written by the master (SM0), the
// send mailbox is read by the master (SM1).
//
// SiiContents is the plain value (what the image says); SiiImage is a checked parse of real
// bytes (it keeps the bytes and where each category lies); encodeSii() writes SiiContents back
// to bytes. Unknown, device-specific (1-9) and vendor (>= 0x0800) categories are kept raw.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/bytes.hpp"
#include "protocol/result.hpp"

namespace ecsim {

namespace sii {
// Word addresses of the fixed header (ETG.2010 Table 2).
inline constexpr std::size_t kWordPdiControl = 0x00;
inline constexpr std::size_t kWordPdiConfiguration = 0x01;
inline constexpr std::size_t kWordSyncImpulseLength = 0x02;
inline constexpr std::size_t kWordExtendedPdiConfiguration = 0x03;
inline constexpr std::size_t kWordStationAlias = 0x04;
inline constexpr std::size_t kWordChecksum = 0x07;
inline constexpr std::size_t kWordVendorId = 0x08;
inline constexpr std::size_t kWordProductCode = 0x0A;
inline constexpr std::size_t kWordRevision = 0x0C;
inline constexpr std::size_t kWordSerial = 0x0E;
inline constexpr std::size_t kWordBootstrapMailbox = 0x14;  // 4 words
inline constexpr std::size_t kWordStandardMailbox = 0x18;   // 4 words
inline constexpr std::size_t kWordMailboxProtocols = 0x1C;
inline constexpr std::size_t kWordSize = 0x3E;
inline constexpr std::size_t kWordVersion = 0x3F;
inline constexpr std::size_t kWordFirstCategory = 0x40;
inline constexpr std::size_t kHeaderWords = 0x40;
inline constexpr std::size_t kHeaderBytes = 2 * kHeaderWords;
inline constexpr std::size_t kChecksumCoveredBytes = 14;  // words 0..6

inline constexpr std::size_t kGeneralBytes = 32;
inline constexpr std::size_t kSyncManagerBytes = 8;
inline constexpr std::size_t kPdoHeaderBytes = 8;
inline constexpr std::size_t kPdoEntryBytes = 8;
inline constexpr std::size_t kDcOpModeBytes = 24;

inline constexpr std::uint16_t kDefaultVersion = 1;
}  // namespace sii

// Category types (ETG.2010 Table 3).
enum class SiiCategoryType : std::uint16_t {
  kNop = 0,
  kStrings = 10,
  kDataTypes = 20,
  kGeneral = 30,
  kFmmu = 40,
  kSyncManager = 41,
  kFmmuExtended = 42,
  kSyncUnit = 43,
  kTxPdo = 50,
  kRxPdo = 51,
  kDc = 60,
  kEnd = 0xFFFF,
};
std::string_view toString(SiiCategoryType type);  // "STRINGS", ..., "unknown"
inline bool isDeviceSpecificCategory(std::uint16_t type) {
  return type >= 1 && type <= 9;
}
inline bool isVendorCategory(std::uint16_t type) {
  return type >= 0x0800 && type < 0xFFFF;
}

// Word 0x1C bits.
struct SiiMailboxProtocol {
  static constexpr std::uint16_t kAoe = 0x0001;
  static constexpr std::uint16_t kEoe = 0x0002;
  static constexpr std::uint16_t kCoe = 0x0004;
  static constexpr std::uint16_t kFoe = 0x0008;
  static constexpr std::uint16_t kSoe = 0x0010;
  static constexpr std::uint16_t kVoe = 0x0020;
};

// General category, CoE details byte (ETG.2010 Table 4).
struct SiiCoeDetails {
  static constexpr std::uint8_t kSdo = 0x01;
  static constexpr std::uint8_t kSdoInfo = 0x02;
  static constexpr std::uint8_t kPdoAssign = 0x04;
  static constexpr std::uint8_t kPdoConfig = 0x08;
  static constexpr std::uint8_t kUploadAtStartup = 0x10;
  static constexpr std::uint8_t kSdoCompleteAccess = 0x20;
};

// General category, flags byte.
struct SiiGeneralFlags {
  static constexpr std::uint8_t kEnableSafeOp = 0x01;
  static constexpr std::uint8_t kEnableNotLrw = 0x02;  // "only LRD/LWR"
  static constexpr std::uint8_t kMailboxDataLinkLayer = 0x04;
  static constexpr std::uint8_t kIdentAlStatus = 0x08;
  static constexpr std::uint8_t kIdentPhysicalMemory = 0x10;
};

// Physical port nibble of the General category (4 bits per port, port 0 in bits 0-3).
enum class SiiPortPhysics : std::uint8_t {
  kNotUsed = 0,
  kMii = 1,
  kReserved = 2,
  kEbus = 3,
  kFastHotConnect = 4,
};

// FMMU category: one byte per FMMU.
enum class SiiFmmuUsage : std::uint8_t {
  kUnused = 0x00,
  kOutputs = 0x01,
  kInputs = 0x02,
  kSyncManagerStatus = 0x03,
  kNotUsed = 0xFF,
};

// SyncManager category: type byte.
enum class SiiSyncManagerType : std::uint8_t {
  kUnused = 0,
  kMailboxOut = 1,  // master -> slave (SM0)
  kMailboxIn = 2,   // slave -> master (SM1)
  kOutputs = 3,
  kInputs = 4,
};

// SyncManager category: enable byte bits.
struct SiiSyncManagerEnable {
  static constexpr std::uint8_t kEnable = 0x01;
  static constexpr std::uint8_t kFixedContent = 0x02;
  static constexpr std::uint8_t kVirtual = 0x04;
  static constexpr std::uint8_t kOpOnly = 0x08;
};

struct SiiConfigArea {
  std::uint16_t pdiControl{0};                // -> 0x0140/0x0141
  std::uint16_t pdiConfiguration{0};          // -> 0x0150/0x0151
  std::uint16_t syncImpulseLength{0};         // -> 0x0982, in 10 ns
  std::uint16_t extendedPdiConfiguration{0};  // -> 0x0152
  std::uint16_t stationAlias{0};              // -> 0x0012
  std::array<std::uint16_t, 2> reserved{};    // words 5 and 6 (some ESCs use them)
  bool operator==(const SiiConfigArea&) const = default;
};

struct SiiIdentity {
  std::uint32_t vendorId{0};
  std::uint32_t productCode{0};
  std::uint32_t revision{0};
  std::uint32_t serial{0};
  bool operator==(const SiiIdentity&) const = default;
};

struct SiiMailbox {
  std::uint16_t receiveOffset{0};  // master -> slave
  std::uint16_t receiveSize{0};
  std::uint16_t sendOffset{0};  // slave -> master
  std::uint16_t sendSize{0};
  bool operator==(const SiiMailbox&) const = default;
};

struct SiiGeneral {
  std::uint8_t groupIndex{0};  // string indexes, 0 = none
  std::uint8_t imageIndex{0};
  std::uint8_t orderIndex{0};
  std::uint8_t nameIndex{0};
  std::uint8_t coeDetails{0};  // SiiCoeDetails bits
  std::uint8_t foeDetails{0};
  std::uint8_t eoeDetails{0};
  std::uint8_t soeChannels{0};
  std::uint8_t ds402Channels{0};
  std::uint8_t sysmanClass{0};
  std::uint8_t flags{0};           // SiiGeneralFlags bits
  std::int16_t currentOnEbus{0};   // mA; negative = the device feeds the E-Bus
  std::uint16_t physicalPorts{0};  // 4 bits per port, SiiPortPhysics
  std::uint16_t physicalMemoryAddress{0};
  // Bytes the layout calls reserved but real devices fill: byte 4 and byte 14 (a duplicate
  // of the group index in ETG.2010, something else in Beckhoff dumps). Kept for round trips.
  std::uint8_t reserved4{0};
  std::uint8_t byte14{0};

  SiiPortPhysics port(std::size_t n) const {
    return static_cast<SiiPortPhysics>((physicalPorts >> (4 * n)) & 0x0F);
  }
  bool operator==(const SiiGeneral&) const = default;
};

struct SiiSyncManager {
  std::uint16_t startAddress{0};
  std::uint16_t length{0};
  std::uint8_t control{0};
  std::uint8_t status{0};
  std::uint8_t enable{0};  // SiiSyncManagerEnable bits
  SiiSyncManagerType type{SiiSyncManagerType::kUnused};
  bool operator==(const SiiSyncManager&) const = default;
};

struct SiiPdoEntry {
  std::uint16_t index{0};
  std::uint8_t subIndex{0};
  std::uint8_t nameIndex{0};
  std::uint8_t dataType{0};  // CoE basic data type index (0x0001 BOOL, 0x0007 UDINT, ...)
  std::uint8_t bitLength{0};
  std::uint16_t flags{0};
  bool operator==(const SiiPdoEntry&) const = default;
};

struct SiiPdo {
  std::uint16_t index{0};
  std::uint8_t syncManager{0};  // >= 8: not assigned to a SyncManager
  std::uint8_t dcSync{0};
  std::uint8_t nameIndex{0};
  std::uint16_t flags{0};
  std::vector<SiiPdoEntry> entries;
  std::uint32_t bitLength() const;
  bool operator==(const SiiPdo&) const = default;
};

struct SiiDcOpMode {
  std::uint32_t cycleTime0{0};
  std::uint32_t shiftTime0{0};
  std::uint32_t shiftTime1{0};
  std::int16_t sync1CycleFactor{0};
  std::uint16_t assignActivate{0};
  std::int16_t sync0CycleFactor{0};
  std::uint8_t nameIndex{0};
  std::uint8_t descriptionIndex{0};
  bool operator==(const SiiDcOpMode&) const = default;
};

// A category kept as bytes (vendor, device-specific, FMMUX, SyncUnit, DataTypes, ...).
struct SiiRawCategory {
  std::uint16_t type{0};
  std::vector<std::uint8_t> data;  // padded to an even length when encoded
  bool operator==(const SiiRawCategory&) const = default;
};

// Everything an SII image says, as plain values.
struct SiiContents {
  SiiConfigArea config;
  SiiIdentity identity;
  SiiMailbox bootstrapMailbox;
  SiiMailbox standardMailbox;
  std::uint16_t mailboxProtocols{0};  // SiiMailboxProtocol bits
  std::uint16_t sizeField{0};         // (EEPROM size in Kbit) - 1
  std::uint16_t version{sii::kDefaultVersion};
  // Header words 0x10-0x13 and 0x1D-0x3D, reserved by ETG.2010 but not always zero in real
  // dumps. Indexed by word address; encodeSii() writes the words that no field above covers.
  std::array<std::uint16_t, sii::kHeaderWords> otherHeaderWords{};

  std::vector<std::string> strings;  // strings[0] is string index 1; bytes, not text
  std::optional<SiiGeneral> general;
  std::vector<SiiFmmuUsage> fmmus;
  std::vector<SiiSyncManager> syncManagers;
  std::vector<SiiPdo> txPdos;  // inputs (slave -> master)
  std::vector<SiiPdo> rxPdos;  // outputs
  std::vector<SiiDcOpMode> dcOpModes;
  // Device-specific (1-9) and vendor (>= 0x0800) ones first, then the others; each group in
  // image order (the order encodeSii() writes them in).
  std::vector<SiiRawCategory> otherCategories;

  // String by its SII index (1-based); empty for 0 or an index past the table.
  std::string_view string(std::size_t index) const;
  std::size_t eepromBytes() const;  // from sizeField
  bool operator==(const SiiContents&) const = default;
};

// CRC-8 of the configuration area (bytes 0..13), the low byte of word 7.
std::uint8_t siiChecksum(ConstBytes firstFourteenBytes);
// Writes the configured station alias (word 4, which the ESC loads into 0x0012) into an image
// with its checksum renewed; an image whose checksum was wrong before keeps a wrong one (a
// dump broken on purpose stays broken). Images too short to hold word 7 are left alone.
void setSiiStationAlias(std::vector<std::uint8_t>& image, std::uint16_t alias);
// EEPROM size field for a size in bytes (size must be a multiple of 128) and back.
std::uint16_t siiSizeFieldForBytes(std::size_t bytes);
std::size_t siiBytesForSizeField(std::uint16_t sizeField);

// Where one category lies in an image.
struct SiiCategory {
  std::uint16_t type{0};
  std::size_t wordOffset{0};  // word address of the type word
  std::size_t wordLength{0};  // data length in words, as the header says
  std::size_t dataByteOffset() const { return 2 * (wordOffset + 2); }
  std::size_t dataBytes() const { return 2 * wordLength; }
  bool known() const;  // one of the types SiiContents decodes
};

// Pull reader over the category list: next() gives the next category, nullopt at the end
// (type 0xFFFF or the end of the data exactly at a category boundary), or an error naming the
// word offset when a header or a category runs past the end of the data.
class SiiCategoryReader {
 public:
  explicit SiiCategoryReader(ConstBytes image) : image_(image) {}
  Result<std::optional<SiiCategory>> next();
  std::size_t wordOffset() const { return word_; }

 private:
  ConstBytes image_;
  std::size_t word_{sii::kWordFirstCategory};
  bool done_{false};
};

class SiiImage {
 public:
  // Strict: any damage in the category area is an error naming its word offset.
  static Result<SiiImage> parse(ConstBytes bytes);
  // Lenient: fails only when the fixed header is missing. Damage stops the category scan;
  // everything decoded before it stays available and damage() says what went wrong.
  static Result<SiiImage> parseLenient(ConstBytes bytes);

  const SiiContents& contents() const { return contents_; }
  const std::vector<SiiCategory>& categories() const { return categories_; }
  const std::optional<Error>& damage() const { return damage_; }
  ConstBytes bytes() const { return bytes_; }
  ConstBytes categoryData(const SiiCategory& category) const;
  std::uint16_t word(std::size_t address) const;  // 0xFFFF past the end, like an erased EEPROM
  bool checksumOk() const;

  const SiiIdentity& identity() const { return contents_.identity; }
  std::string_view string(std::size_t index) const { return contents_.string(index); }

 private:
  static Result<SiiImage> parseImpl(ConstBytes bytes, bool strict);

  std::vector<std::uint8_t> bytes_;
  SiiContents contents_;
  std::vector<SiiCategory> categories_;
  std::optional<Error> damage_;
};

// Category decoders (exposed for tools and tests). Each names the category's word offset in
// its errors; `wordOffset` is only used for that.
Result<std::vector<std::string>> decodeSiiStrings(ConstBytes data, std::size_t wordOffset);
Result<SiiGeneral> decodeSiiGeneral(ConstBytes data, std::size_t wordOffset);
Result<std::vector<SiiSyncManager>> decodeSiiSyncManagers(ConstBytes data, std::size_t wordOffset);
Result<std::vector<SiiPdo>> decodeSiiPdos(ConstBytes data, std::size_t wordOffset);
Result<std::vector<SiiDcOpMode>> decodeSiiDcOpModes(ConstBytes data, std::size_t wordOffset);

struct SiiEncodeOptions {
  // Pad the image with 0xFF up to the EEPROM size of sizeField (as a real EEPROM reads).
  bool padToEepromSize{true};
};

// Writes the header (checksum computed), the categories in ETG order (device-specific and
// vendor raw categories first, as real dumps have them, then STRINGS, GENERAL, FMMU, SM,
// FMMUX/SyncUnit and other raw ones, TXPDO, RXPDO, DC) and END. kTooLarge when the result
// does not fit in the EEPROM size of sizeField, kInvalidArgument for a string longer than 255
// bytes, more than 255 strings or a PDO with more than 255 entries.
Result<std::vector<std::uint8_t>> encodeSii(const SiiContents& contents,
                                            const SiiEncodeOptions& options = {});
// Bytes encodeSii() would produce before padding.
std::size_t siiEncodedSize(const SiiContents& contents);

}  // namespace ecsim
