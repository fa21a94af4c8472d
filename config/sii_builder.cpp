#include "config/sii_builder.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <limits>
#include <string>
#include <utility>

namespace ecsim {
namespace {

// Default configuration area when the ESI has no Eeprom/ConfigData. Modelled on what real
// ET1100-class devices carry (see /work/shared/eeprom):
//  - with a mailbox there is a microcontroller behind the ESC: PDI type 0x05 (SPI slave), no
//    device emulation (the application, i.e. our simulated firmware, drives AL status), and
//    the DC SYNC-out and LATCH-in units powered (0x0141 bits 2 and 3) -> 0x0C05;
//  - without a mailbox the ESC runs alone: PDI 0x04 (digital I/O) with device emulation
//    (0x0141 bit 0, AL status follows AL control) as in el2004/el2828 -> 0x0104, plus the DC
//    units when the device has DC op modes -> 0x0D04.
// PDI configuration: with DC op modes SYNC0/SYNC1 are push-pull active-high outputs (0x0151 =
// 0x66, as the NI 9144 dump has it); sync impulse 1000 x 10 ns = 10 us.
constexpr std::uint16_t kPdiControlWithMailbox = 0x0C05;
constexpr std::uint16_t kPdiControlDigitalIo = 0x0104;
constexpr std::uint16_t kEscConfigDcUnits = 0x0C00;
constexpr std::uint16_t kPdiConfigDcOutputs = 0x6600;
constexpr std::uint16_t kSyncImpulseDefault = 1000;

constexpr std::size_t kDefaultEepromBytes = 256;  // 2 Kbit, the ETG.2010 minimum

// PDO flags (ETG.2010 PDO category).
constexpr std::uint16_t kPdoMandatory = 0x0001;
constexpr std::uint16_t kPdoFixedContent = 0x0010;

std::string upper(std::string_view s) {
  std::string out(s);
  for (auto& c : out) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

// STRINGS table under construction: deduplicated, at most 255 entries of 255 bytes.
class StringTable {
 public:
  std::uint8_t add(std::string_view text) {
    if (text.empty()) return 0;
    text = text.substr(0, 255);
    for (std::size_t i = 0; i < strings_.size(); ++i) {
      if (strings_[i] == text) return static_cast<std::uint8_t>(i + 1);
    }
    if (strings_.size() == 255) return 0;  // table full: the name is left out
    strings_.emplace_back(text);
    return static_cast<std::uint8_t>(strings_.size());
  }
  std::vector<std::string> take() { return std::move(strings_); }

 private:
  std::vector<std::string> strings_;
};

SiiPortPhysics portPhysics(char letter) {
  switch (letter) {
    case 'Y':
      return SiiPortPhysics::kMii;
    case 'K':
      return SiiPortPhysics::kEbus;
    case 'H':
      return SiiPortPhysics::kFastHotConnect;
    default:
      return SiiPortPhysics::kNotUsed;
  }
}

SiiSyncManagerType smType(const EsiSyncManager& sm) {
  const std::string text = upper(sm.text);
  if (text == "MBOXOUT") return SiiSyncManagerType::kMailboxOut;
  if (text == "MBOXIN") return SiiSyncManagerType::kMailboxIn;
  if (text == "OUTPUTS") return SiiSyncManagerType::kOutputs;
  if (text == "INPUTS") return SiiSyncManagerType::kInputs;
  // A vendor's own word (Orbita2d: "OrbitaIn"): the control byte says what the SM is.
  // Bits 1:0 operation mode (00 buffered, 10 mailbox), bits 3:2 direction (00 ECAT reads,
  // 01 ECAT writes).
  if (sm.controlByte == 0) return SiiSyncManagerType::kUnused;
  const bool mailbox = (sm.controlByte & 0x03) == 0x02;
  const bool masterWrites = (sm.controlByte & 0x0C) == 0x04;
  if (mailbox)
    return masterWrites ? SiiSyncManagerType::kMailboxOut : SiiSyncManagerType::kMailboxIn;
  return masterWrites ? SiiSyncManagerType::kOutputs : SiiSyncManagerType::kInputs;
}

SiiFmmuUsage fmmuUsage(const EsiFmmu& fmmu, std::size_t position,
                       const std::vector<SiiSyncManager>& sms) {
  const std::string text = upper(fmmu.text);
  if (text == "OUTPUTS") return SiiFmmuUsage::kOutputs;
  if (text == "INPUTS") return SiiFmmuUsage::kInputs;
  if (text == "MBOXSTATE") return SiiFmmuUsage::kSyncManagerStatus;
  if (fmmu.sm && *fmmu.sm < sms.size()) {
    if (sms[*fmmu.sm].type == SiiSyncManagerType::kOutputs) return SiiFmmuUsage::kOutputs;
    if (sms[*fmmu.sm].type == SiiSyncManagerType::kInputs) return SiiFmmuUsage::kInputs;
  }
  // A vendor's own word: the conventional order is outputs, inputs, mailbox state.
  static constexpr std::array<SiiFmmuUsage, 3> kByPosition = {
      SiiFmmuUsage::kOutputs, SiiFmmuUsage::kInputs, SiiFmmuUsage::kSyncManagerStatus};
  return position < kByPosition.size() ? kByPosition[position] : SiiFmmuUsage::kUnused;
}

std::uint8_t coeDetails(const EsiMailbox& mailbox) {
  if (!mailbox.coe) return 0;
  const EsiCoe& c = mailbox.coeDetails;
  std::uint8_t bits = SiiCoeDetails::kSdo;
  if (c.sdoInfo) bits |= SiiCoeDetails::kSdoInfo;
  if (c.pdoAssign) bits |= SiiCoeDetails::kPdoAssign;
  if (c.pdoConfig) bits |= SiiCoeDetails::kPdoConfig;
  if (c.pdoUpload) bits |= SiiCoeDetails::kUploadAtStartup;
  if (c.completeAccess) bits |= SiiCoeDetails::kSdoCompleteAccess;
  return bits;
}

template <typename T, typename U>
T clampTo(U value) {
  if (value < static_cast<U>(std::numeric_limits<T>::min())) return std::numeric_limits<T>::min();
  if (value > static_cast<U>(std::numeric_limits<T>::max())) return std::numeric_limits<T>::max();
  return static_cast<T>(value);
}

SiiConfigArea configArea(const EsiDevice& device) {
  SiiConfigArea config;
  const std::vector<std::uint8_t>* data = device.eeprom ? &device.eeprom->configData : nullptr;
  if (data != nullptr && !data->empty()) {
    // ConfigData holds words 0.. in wire order; shorter strings (Beckhoff "0001") fill the
    // first words only.
    std::array<std::uint8_t, 14> bytes{};
    std::copy_n(data->begin(), std::min(data->size(), bytes.size()), bytes.begin());
    ConstBytes b(bytes);
    config.pdiControl = readLe16(b, 0);
    config.pdiConfiguration = readLe16(b, 2);
    config.syncImpulseLength = readLe16(b, 4);
    config.extendedPdiConfiguration = readLe16(b, 6);
    config.stationAlias = readLe16(b, 8);
    config.reserved = {readLe16(b, 10), readLe16(b, 12)};
    return config;
  }
  const bool dc = !device.dcOpModes.empty();
  if (device.mailbox.present) {
    config.pdiControl = kPdiControlWithMailbox;
  } else {
    config.pdiControl = dc ? static_cast<std::uint16_t>(kPdiControlDigitalIo | kEscConfigDcUnits)
                           : kPdiControlDigitalIo;
  }
  if (dc) {
    config.pdiConfiguration = kPdiConfigDcOutputs;
    config.syncImpulseLength = kSyncImpulseDefault;
  }
  return config;
}

SiiPdo siiPdo(const EsiPdo& pdo, StringTable& strings, bool names) {
  SiiPdo out;
  out.index = pdo.index;
  out.syncManager = *pdo.sm;
  out.nameIndex = names ? strings.add(pdo.name()) : 0;
  if (pdo.mandatory) out.flags |= kPdoMandatory;
  if (pdo.fixed) out.flags |= kPdoFixedContent;
  for (const auto& e : pdo.entries) {
    SiiPdoEntry entry;
    entry.index = e.index;
    entry.subIndex = e.subIndex;
    entry.nameIndex = names ? strings.add(e.name) : 0;
    entry.dataType = coeDataTypeCode(e.dataType);
    entry.bitLength = clampTo<std::uint8_t>(e.bitLength);
    out.entries.push_back(entry);
  }
  return out;
}

std::size_t standardEepromBytes(std::size_t atLeast) {
  std::size_t bytes = 128;  // 1 Kbit
  while (bytes < atLeast) bytes *= 2;
  return bytes;
}

}  // namespace

std::uint8_t coeDataTypeCode(std::string_view esiTypeName) {
  struct Code {
    std::string_view name;
    std::uint8_t code;
  };
  static constexpr std::array<Code, 24> kCodes = {{
      {"BOOL", 0x01},  {"BIT", 0x01},   {"SINT", 0x02},  {"INT", 0x03},    {"DINT", 0x04},
      {"USINT", 0x05}, {"UINT", 0x06},  {"UDINT", 0x07}, {"REAL", 0x08},   {"STRING", 0x09},
      {"LREAL", 0x11}, {"INT24", 0x10}, {"LINT", 0x15},  {"UINT24", 0x16}, {"ULINT", 0x1B},
      {"BYTE", 0x1E},  {"WORD", 0x1F},  {"DWORD", 0x20}, {"BIT1", 0x30},   {"BIT2", 0x31},
      {"BIT3", 0x32},  {"BIT4", 0x33},  {"BIT5", 0x34},  {"BIT8", 0x37},
  }};
  std::string name = upper(trimEsiText(esiTypeName));
  if (name.rfind("STRING", 0) == 0) name = "STRING";  // STRING(10)
  for (const auto& c : kCodes) {
    if (c.name == name) return c.code;
  }
  if (name == "BIT6") return 0x35;
  if (name == "BIT7") return 0x36;
  // Sized spellings some generators write (Orbita2d.xml: UINT16, UINT8).
  static constexpr std::array<Code, 10> kSized = {{
      {"INT8", 0x02},
      {"INT16", 0x03},
      {"INT32", 0x04},
      {"UINT8", 0x05},
      {"UINT16", 0x06},
      {"UINT32", 0x07},
      {"REAL32", 0x08},
      {"REAL64", 0x11},
      {"INT64", 0x15},
      {"UINT64", 0x1B},
  }};
  for (const auto& c : kSized) {
    if (c.name == name) return c.code;
  }
  return 0;
}

Result<SiiContents> makeSiiContents(const EsiDevice& device, std::uint32_t vendorId,
                                    const SiiBuildOptions& options) {
  if (device.eeprom && device.eeprom->data.size() >= sii::kHeaderBytes) {
    auto image = SiiImage::parse(device.eeprom->data);
    if (!image.ok()) {
      return makeError(image.error().code, "ESI device " + device.type + " (line " +
                                               std::to_string(device.line) +
                                               ") Eeprom/Data: " + image.error().context);
    }
    return image->contents();
  }
  SiiContents c;
  c.config = configArea(device);
  c.identity = {vendorId, device.productCode, device.revision, options.serial};

  for (const auto& sm : device.syncManagers) {
    c.syncManagers.push_back({sm.startAddress, sm.defaultSize, sm.controlByte, 0,
                              static_cast<std::uint8_t>(
                                  sm.enable | (sm.fixed ? SiiSyncManagerEnable::kFixedContent : 0) |
                                  (sm.isVirtual ? SiiSyncManagerEnable::kVirtual : 0) |
                                  (sm.opOnly ? SiiSyncManagerEnable::kOpOnly : 0)),
                              smType(sm)});
  }
  for (const auto& sm : c.syncManagers) {
    if (sm.type == SiiSyncManagerType::kMailboxOut && c.standardMailbox.receiveSize == 0) {
      c.standardMailbox.receiveOffset = sm.startAddress;
      c.standardMailbox.receiveSize = sm.length;
    } else if (sm.type == SiiSyncManagerType::kMailboxIn && c.standardMailbox.sendSize == 0) {
      c.standardMailbox.sendOffset = sm.startAddress;
      c.standardMailbox.sendSize = sm.length;
    }
  }
  if (device.eeprom && device.eeprom->bootStrap.size() >= 8) {
    ConstBytes b(device.eeprom->bootStrap);
    c.bootstrapMailbox = {readLe16(b, 0), readLe16(b, 2), readLe16(b, 4), readLe16(b, 6)};
  }
  c.mailboxProtocols = device.mailbox.protocolMask();

  StringTable strings;
  const std::string name = device.name();
  const std::uint8_t nameIndex = strings.add(options.deviceNameFirst ? name : device.type);
  SiiGeneral g;
  g.groupIndex = strings.add(device.groupType);
  g.orderIndex = strings.add(device.type);
  g.nameIndex = options.deviceNameFirst ? nameIndex : strings.add(name);
  g.imageIndex = strings.add(device.imageName);
  g.coeDetails = coeDetails(device.mailbox);
  g.foeDetails = device.mailbox.foe ? 1 : 0;
  g.eoeDetails = device.mailbox.eoe ? 1 : 0;
  g.soeChannels = device.mailbox.soe ? device.mailbox.soeChannels : 0;
  g.ds402Channels = device.mailbox.coeDetails.ds402Channels;
  if (device.useLrdLwr) g.flags |= SiiGeneralFlags::kEnableNotLrw;
  if (device.mailbox.dataLinkLayer) g.flags |= SiiGeneralFlags::kMailboxDataLinkLayer;
  g.currentOnEbus = clampTo<std::int16_t>(device.ebusCurrent.value_or(0));
  for (std::size_t port = 0; port < std::min<std::size_t>(device.physics.size(), 4); ++port) {
    g.physicalPorts = static_cast<std::uint16_t>(
        g.physicalPorts | (static_cast<unsigned>(portPhysics(device.physics[port])) << (4 * port)));
  }
  g.byte14 = g.groupIndex;  // ETG.2010: a copy of the group index for older masters
  c.general = g;

  for (std::size_t i = 0; i < device.fmmus.size(); ++i) {
    c.fmmus.push_back(fmmuUsage(device.fmmus[i], i, c.syncManagers));
  }
  if (c.fmmus.size() % 2 != 0) c.fmmus.push_back(SiiFmmuUsage::kNotUsed);  // as encoded

  for (const auto& mode : device.dcOpModes) {
    SiiDcOpMode m;
    m.cycleTime0 = mode.cycleTimeSync0;
    m.shiftTime0 = clampTo<std::uint32_t>(mode.shiftTimeSync0 < 0 ? 0 : mode.shiftTimeSync0);
    m.shiftTime1 = clampTo<std::uint32_t>(mode.shiftTimeSync1 < 0 ? 0 : mode.shiftTimeSync1);
    m.sync0CycleFactor = clampTo<std::int16_t>(mode.cycleTimeSync0Factor);
    m.sync1CycleFactor = clampTo<std::int16_t>(mode.cycleTimeSync1Factor);
    m.assignActivate = mode.assignActivate;
    m.nameIndex = strings.add(mode.name);
    m.descriptionIndex = strings.add(mode.description);
    c.dcOpModes.push_back(m);
  }
  if (options.pdoCategories) {
    for (const auto& pdo : device.txPdos) {
      if (pdo.sm && pdo.inCoeRange()) {
        c.txPdos.push_back(siiPdo(pdo, strings, options.pdoNameStrings));
      }
    }
    for (const auto& pdo : device.rxPdos) {
      if (pdo.sm && pdo.inCoeRange()) {
        c.rxPdos.push_back(siiPdo(pdo, strings, options.pdoNameStrings));
      }
    }
  }
  c.strings = strings.take();
  if (device.eeprom) {
    for (const auto& raw : device.eeprom->categories)
      c.otherCategories.push_back({raw.type, raw.data});
  }

  const std::size_t wanted = device.eeprom && device.eeprom->byteSize
                                 ? std::max<std::size_t>(*device.eeprom->byteSize, 128)
                                 : kDefaultEepromBytes;
  const std::size_t bytes = standardEepromBytes(std::max(wanted, siiEncodedSize(c)));
  c.sizeField = siiSizeFieldForBytes(bytes);
  return c;
}

Result<std::vector<std::uint8_t>> buildSiiImage(const EsiDevice& device, std::uint32_t vendorId,
                                                const SiiBuildOptions& options) {
  ECSIM_ASSIGN_OR_RETURN(SiiContents contents, makeSiiContents(device, vendorId, options));
  return encodeSii(contents, SiiEncodeOptions{options.padToEepromSize});
}

}  // namespace ecsim
