#include "protocol/sii.hpp"

#include <algorithm>
#include <string>
#include <utility>

namespace ecsim {
namespace {

std::string hex(std::size_t value, int width = 4) {
  static constexpr char kDigits[] = "0123456789ABCDEF";
  std::string s = "0x";
  for (int shift = 4 * (width - 1); shift >= 0; shift -= 4) {
    s += kDigits[(value >> shift) & 0xF];
  }
  return s;
}

std::string where(std::size_t wordOffset) {
  return "SII word " + hex(wordOffset);
}

std::string categoryName(std::uint16_t type) {
  std::string name(toString(static_cast<SiiCategoryType>(type)));
  return name + " (" + hex(type) + ")";
}

// Raw categories the encoder writes before STRINGS (where real dumps have them).
bool leadingRawCategory(std::uint16_t type) {
  return isDeviceSpecificCategory(type) || isVendorCategory(type);
}

bool isOtherHeaderWord(std::size_t address) {
  return (address >= 0x10 && address <= 0x13) || (address >= 0x1D && address <= 0x3D);
}

SiiMailbox readMailbox(ConstBytes b, std::size_t word) {
  return {readLe16(b, 2 * word), readLe16(b, 2 * word + 2), readLe16(b, 2 * word + 4),
          readLe16(b, 2 * word + 6)};
}

void writeMailbox(Bytes b, std::size_t word, const SiiMailbox& m) {
  writeLe16(b, 2 * word, m.receiveOffset);
  writeLe16(b, 2 * word + 2, m.receiveSize);
  writeLe16(b, 2 * word + 4, m.sendOffset);
  writeLe16(b, 2 * word + 6, m.sendSize);
}

SiiContents decodeHeader(ConstBytes b) {
  SiiContents c;
  c.config.pdiControl = readLe16(b, 2 * sii::kWordPdiControl);
  c.config.pdiConfiguration = readLe16(b, 2 * sii::kWordPdiConfiguration);
  c.config.syncImpulseLength = readLe16(b, 2 * sii::kWordSyncImpulseLength);
  c.config.extendedPdiConfiguration = readLe16(b, 2 * sii::kWordExtendedPdiConfiguration);
  c.config.stationAlias = readLe16(b, 2 * sii::kWordStationAlias);
  c.config.reserved = {readLe16(b, 2 * 5), readLe16(b, 2 * 6)};
  c.identity.vendorId = readLe32(b, 2 * sii::kWordVendorId);
  c.identity.productCode = readLe32(b, 2 * sii::kWordProductCode);
  c.identity.revision = readLe32(b, 2 * sii::kWordRevision);
  c.identity.serial = readLe32(b, 2 * sii::kWordSerial);
  c.bootstrapMailbox = readMailbox(b, sii::kWordBootstrapMailbox);
  c.standardMailbox = readMailbox(b, sii::kWordStandardMailbox);
  c.mailboxProtocols = readLe16(b, 2 * sii::kWordMailboxProtocols);
  c.sizeField = readLe16(b, 2 * sii::kWordSize);
  c.version = readLe16(b, 2 * sii::kWordVersion);
  for (std::size_t w = 0; w < sii::kHeaderWords; ++w) {
    if (isOtherHeaderWord(w)) c.otherHeaderWords[w] = readLe16(b, 2 * w);
  }
  return c;
}

void encodeHeader(const SiiContents& c, Bytes b) {
  for (std::size_t w = 0; w < sii::kHeaderWords; ++w) {
    writeLe16(b, 2 * w, isOtherHeaderWord(w) ? c.otherHeaderWords[w] : 0);
  }
  writeLe16(b, 2 * sii::kWordPdiControl, c.config.pdiControl);
  writeLe16(b, 2 * sii::kWordPdiConfiguration, c.config.pdiConfiguration);
  writeLe16(b, 2 * sii::kWordSyncImpulseLength, c.config.syncImpulseLength);
  writeLe16(b, 2 * sii::kWordExtendedPdiConfiguration, c.config.extendedPdiConfiguration);
  writeLe16(b, 2 * sii::kWordStationAlias, c.config.stationAlias);
  writeLe16(b, 2 * 5, c.config.reserved[0]);
  writeLe16(b, 2 * 6, c.config.reserved[1]);
  writeLe16(b, 2 * sii::kWordChecksum, siiChecksum(b.first(sii::kChecksumCoveredBytes)));
  writeLe32(b, 2 * sii::kWordVendorId, c.identity.vendorId);
  writeLe32(b, 2 * sii::kWordProductCode, c.identity.productCode);
  writeLe32(b, 2 * sii::kWordRevision, c.identity.revision);
  writeLe32(b, 2 * sii::kWordSerial, c.identity.serial);
  writeMailbox(b, sii::kWordBootstrapMailbox, c.bootstrapMailbox);
  writeMailbox(b, sii::kWordStandardMailbox, c.standardMailbox);
  writeLe16(b, 2 * sii::kWordMailboxProtocols, c.mailboxProtocols);
  writeLe16(b, 2 * sii::kWordSize, c.sizeField);
  writeLe16(b, 2 * sii::kWordVersion, c.version);
}

// Decodes one known category into `c`.
Status decodeCategory(const SiiCategory& cat, ConstBytes data, SiiContents& c) {
  switch (static_cast<SiiCategoryType>(cat.type)) {
    case SiiCategoryType::kStrings: {
      ECSIM_ASSIGN_OR_RETURN(auto strings, decodeSiiStrings(data, cat.wordOffset));
      c.strings = std::move(strings);
      return okStatus();
    }
    case SiiCategoryType::kGeneral: {
      ECSIM_ASSIGN_OR_RETURN(auto general, decodeSiiGeneral(data, cat.wordOffset));
      c.general = general;
      return okStatus();
    }
    case SiiCategoryType::kFmmu:
      for (std::uint8_t byte : data) c.fmmus.push_back(static_cast<SiiFmmuUsage>(byte));
      return okStatus();
    case SiiCategoryType::kSyncManager: {
      ECSIM_ASSIGN_OR_RETURN(auto sms, decodeSiiSyncManagers(data, cat.wordOffset));
      c.syncManagers.insert(c.syncManagers.end(), sms.begin(), sms.end());
      return okStatus();
    }
    case SiiCategoryType::kTxPdo:
    case SiiCategoryType::kRxPdo: {
      ECSIM_ASSIGN_OR_RETURN(auto pdos, decodeSiiPdos(data, cat.wordOffset));
      auto& list =
          cat.type == static_cast<std::uint16_t>(SiiCategoryType::kTxPdo) ? c.txPdos : c.rxPdos;
      list.insert(list.end(), pdos.begin(), pdos.end());
      return okStatus();
    }
    case SiiCategoryType::kDc: {
      ECSIM_ASSIGN_OR_RETURN(auto modes, decodeSiiDcOpModes(data, cat.wordOffset));
      c.dcOpModes.insert(c.dcOpModes.end(), modes.begin(), modes.end());
      return okStatus();
    }
    default:
      c.otherCategories.push_back({cat.type, std::vector<std::uint8_t>(data.begin(), data.end())});
      return okStatus();
  }
}

}  // namespace

std::string_view toString(SiiCategoryType type) {
  switch (type) {
    case SiiCategoryType::kNop:
      return "NOP";
    case SiiCategoryType::kStrings:
      return "STRINGS";
    case SiiCategoryType::kDataTypes:
      return "DATATYPES";
    case SiiCategoryType::kGeneral:
      return "GENERAL";
    case SiiCategoryType::kFmmu:
      return "FMMU";
    case SiiCategoryType::kSyncManager:
      return "SYNCM";
    case SiiCategoryType::kFmmuExtended:
      return "FMMUX";
    case SiiCategoryType::kSyncUnit:
      return "SYNCUNIT";
    case SiiCategoryType::kTxPdo:
      return "TXPDO";
    case SiiCategoryType::kRxPdo:
      return "RXPDO";
    case SiiCategoryType::kDc:
      return "DC";
    case SiiCategoryType::kEnd:
      return "END";
  }
  auto raw = static_cast<std::uint16_t>(type);
  if (isDeviceSpecificCategory(raw)) return "device-specific";
  if (isVendorCategory(raw)) return "vendor-specific";
  return "unknown";
}

std::uint32_t SiiPdo::bitLength() const {
  std::uint32_t bits = 0;
  for (const auto& e : entries) bits += e.bitLength;
  return bits;
}

std::string_view SiiContents::string(std::size_t index) const {
  if (index == 0 || index > strings.size()) return {};
  return strings[index - 1];
}

std::size_t SiiContents::eepromBytes() const {
  return siiBytesForSizeField(sizeField);
}

std::uint8_t siiChecksum(ConstBytes firstFourteenBytes) {
  std::uint8_t crc = 0xFF;
  for (std::size_t i = 0; i < sii::kChecksumCoveredBytes && i < firstFourteenBytes.size(); ++i) {
    crc ^= firstFourteenBytes[i];
    for (int bit = 0; bit < 8; ++bit) {
      crc = static_cast<std::uint8_t>((crc & 0x80) ? ((crc << 1) ^ 0x07) : (crc << 1));
    }
  }
  return crc;
}

void setSiiStationAlias(std::vector<std::uint8_t>& image, std::uint16_t alias) {
  const std::size_t checksumAt = sii::kWordChecksum * 2;
  if (image.size() < checksumAt + 2) return;
  const bool checksumRight = siiChecksum(image) == image[checksumAt];
  writeLe16(image, sii::kWordStationAlias * 2, alias);
  if (checksumRight) image[checksumAt] = siiChecksum(image);
}

std::uint16_t siiSizeFieldForBytes(std::size_t bytes) {
  std::size_t kbit = bytes * 8 / 1024;
  return static_cast<std::uint16_t>(kbit == 0 ? 0 : kbit - 1);
}

std::size_t siiBytesForSizeField(std::uint16_t sizeField) {
  return (static_cast<std::size_t>(sizeField) + 1) * 1024 / 8;
}

bool SiiCategory::known() const {
  switch (static_cast<SiiCategoryType>(type)) {
    case SiiCategoryType::kStrings:
    case SiiCategoryType::kGeneral:
    case SiiCategoryType::kFmmu:
    case SiiCategoryType::kSyncManager:
    case SiiCategoryType::kTxPdo:
    case SiiCategoryType::kRxPdo:
    case SiiCategoryType::kDc:
      return true;
    default:
      return false;
  }
}

Result<std::optional<SiiCategory>> SiiCategoryReader::next() {
  if (done_) return std::optional<SiiCategory>{};
  const std::size_t words = image_.size() / 2;
  if (word_ >= words) {  // the data ends at a category boundary: treat as END
    done_ = true;
    return std::optional<SiiCategory>{};
  }
  const std::uint16_t type = readLe16(image_, 2 * word_);
  if (type == static_cast<std::uint16_t>(SiiCategoryType::kEnd)) {
    done_ = true;
    return std::optional<SiiCategory>{};
  }
  if (word_ + 1 >= words) {
    done_ = true;
    return makeError(ErrorCode::kTruncated, where(word_) + ": category " + categoryName(type) +
                                                " header cut off by the end of the image");
  }
  SiiCategory cat{type, word_, readLe16(image_, 2 * word_ + 2)};
  if (word_ + 2 + cat.wordLength > words) {
    done_ = true;
    return makeError(ErrorCode::kTruncated, where(word_) + ": category " + categoryName(type) +
                                                " length " + std::to_string(cat.wordLength) +
                                                " words runs past the end of the image (" +
                                                std::to_string(words) + " words)");
  }
  word_ += 2 + cat.wordLength;
  return std::optional<SiiCategory>{cat};
}

Result<SiiImage> SiiImage::parse(ConstBytes bytes) {
  return parseImpl(bytes, true);
}

Result<SiiImage> SiiImage::parseLenient(ConstBytes bytes) {
  return parseImpl(bytes, false);
}

Result<SiiImage> SiiImage::parseImpl(ConstBytes bytes, bool strict) {
  if (bytes.size() < sii::kHeaderBytes) {
    return makeError(ErrorCode::kTruncated, "SII image of " + std::to_string(bytes.size()) +
                                                " bytes is shorter than the 128-byte header");
  }
  SiiImage image;
  image.bytes_.assign(bytes.begin(), bytes.end());
  image.contents_ = decodeHeader(bytes);
  SiiCategoryReader reader(bytes);
  while (true) {
    auto next = reader.next();
    if (!next.ok()) {
      if (strict) return next.takeError();
      image.damage_ = next.takeError();
      break;
    }
    if (!next->has_value()) break;
    const SiiCategory cat = **next;
    image.categories_.push_back(cat);
    auto decoded = decodeCategory(cat, image.categoryData(cat), image.contents_);
    if (!decoded.ok()) {
      if (strict) return decoded.takeError();
      image.damage_ = decoded.takeError();
      break;
    }
  }
  // Raw categories in the order encodeSii() writes them (device-specific and vendor ones
  // first, the rest after SYNCM), so that parse(encode(contents)) == contents.
  auto& raw = image.contents_.otherCategories;
  std::stable_partition(raw.begin(), raw.end(),
                        [](const SiiRawCategory& c) { return leadingRawCategory(c.type); });
  return image;
}

ConstBytes SiiImage::categoryData(const SiiCategory& category) const {
  return ConstBytes(bytes_).subspan(category.dataByteOffset(), category.dataBytes());
}

std::uint16_t SiiImage::word(std::size_t address) const {
  if (2 * address + 2 > bytes_.size()) return 0xFFFF;
  return readLe16(bytes_, 2 * address);
}

bool SiiImage::checksumOk() const {
  return siiChecksum(ConstBytes(bytes_).first(sii::kChecksumCoveredBytes)) ==
         (word(sii::kWordChecksum) & 0xFF);
}

Result<std::vector<std::string>> decodeSiiStrings(ConstBytes data, std::size_t wordOffset) {
  std::vector<std::string> strings;
  if (data.empty()) return strings;
  const std::size_t count = data[0];
  std::size_t at = 1;
  for (std::size_t i = 0; i < count; ++i) {
    if (at >= data.size() || at + 1 + data[at] > data.size()) {
      return makeError(ErrorCode::kTruncated,
                       where(wordOffset) + ": STRINGS: string " + std::to_string(i + 1) + " of " +
                           std::to_string(count) + " runs past the end of the category");
    }
    const std::size_t length = data[at];
    const auto first = data.begin() + static_cast<std::ptrdiff_t>(at + 1);
    strings.emplace_back(first, first + static_cast<std::ptrdiff_t>(length));
    at += 1 + length;
  }
  return strings;
}

Result<SiiGeneral> decodeSiiGeneral(ConstBytes data, std::size_t wordOffset) {
  // Older images may carry a shorter General category; absent bytes read as zero.
  if (data.size() < 4) {
    return makeError(ErrorCode::kMalformed, where(wordOffset) + ": GENERAL category of " +
                                                std::to_string(data.size()) +
                                                " bytes is too short");
  }
  std::array<std::uint8_t, sii::kGeneralBytes> b{};
  std::copy_n(data.begin(), std::min(data.size(), b.size()), b.begin());
  ConstBytes g(b);
  SiiGeneral out;
  out.groupIndex = g[0];
  out.imageIndex = g[1];
  out.orderIndex = g[2];
  out.nameIndex = g[3];
  out.reserved4 = g[4];
  out.coeDetails = g[5];
  out.foeDetails = g[6];
  out.eoeDetails = g[7];
  out.soeChannels = g[8];
  out.ds402Channels = g[9];
  out.sysmanClass = g[10];
  out.flags = g[11];
  out.currentOnEbus = static_cast<std::int16_t>(readLe16(g, 12));
  out.byte14 = g[14];
  out.physicalPorts = readLe16(g, 16);
  out.physicalMemoryAddress = readLe16(g, 18);
  return out;
}

Result<std::vector<SiiSyncManager>> decodeSiiSyncManagers(ConstBytes data, std::size_t wordOffset) {
  if (data.size() % sii::kSyncManagerBytes != 0) {
    return makeError(ErrorCode::kMalformed, where(wordOffset) + ": SYNCM category of " +
                                                std::to_string(data.size()) +
                                                " bytes is not a multiple of 8");
  }
  std::vector<SiiSyncManager> sms;
  for (std::size_t at = 0; at < data.size(); at += sii::kSyncManagerBytes) {
    sms.push_back({readLe16(data, at), readLe16(data, at + 2), data[at + 4], data[at + 5],
                   data[at + 6], static_cast<SiiSyncManagerType>(data[at + 7])});
  }
  return sms;
}

Result<std::vector<SiiPdo>> decodeSiiPdos(ConstBytes data, std::size_t wordOffset) {
  std::vector<SiiPdo> pdos;
  std::size_t at = 0;
  while (at < data.size()) {
    if (at + sii::kPdoHeaderBytes > data.size()) {
      return makeError(ErrorCode::kTruncated, where(wordOffset) + ": PDO header at data byte " +
                                                  std::to_string(at) +
                                                  " runs past the end of the category");
    }
    SiiPdo pdo;
    pdo.index = readLe16(data, at);
    const std::size_t entries = data[at + 2];
    pdo.syncManager = data[at + 3];
    pdo.dcSync = data[at + 4];
    pdo.nameIndex = data[at + 5];
    pdo.flags = readLe16(data, at + 6);
    at += sii::kPdoHeaderBytes;
    if (at + entries * sii::kPdoEntryBytes > data.size()) {
      return makeError(ErrorCode::kTruncated, where(wordOffset) + ": PDO " + hex(pdo.index) +
                                                  " with " + std::to_string(entries) +
                                                  " entries runs past the end of the category");
    }
    for (std::size_t i = 0; i < entries; ++i, at += sii::kPdoEntryBytes) {
      pdo.entries.push_back({readLe16(data, at), data[at + 2], data[at + 3], data[at + 4],
                             data[at + 5], readLe16(data, at + 6)});
    }
    pdos.push_back(std::move(pdo));
  }
  return pdos;
}

Result<std::vector<SiiDcOpMode>> decodeSiiDcOpModes(ConstBytes data, std::size_t wordOffset) {
  if (data.size() % sii::kDcOpModeBytes != 0) {
    return makeError(ErrorCode::kMalformed, where(wordOffset) + ": DC category of " +
                                                std::to_string(data.size()) +
                                                " bytes is not a multiple of 24");
  }
  std::vector<SiiDcOpMode> modes;
  for (std::size_t at = 0; at < data.size(); at += sii::kDcOpModeBytes) {
    SiiDcOpMode m;
    m.cycleTime0 = readLe32(data, at);
    m.shiftTime0 = readLe32(data, at + 4);
    m.shiftTime1 = readLe32(data, at + 8);
    m.sync1CycleFactor = static_cast<std::int16_t>(readLe16(data, at + 12));
    m.assignActivate = readLe16(data, at + 14);
    m.sync0CycleFactor = static_cast<std::int16_t>(readLe16(data, at + 16));
    m.nameIndex = data[at + 18];
    m.descriptionIndex = data[at + 19];
    modes.push_back(m);
  }
  return modes;
}

namespace {

// Appends bytes, little-endian, to a growing image.
class Writer {
 public:
  explicit Writer(std::vector<std::uint8_t>& out) : out_(out) {}
  void u8(std::uint8_t v) { out_.push_back(v); }
  void u16(std::uint16_t v) {
    out_.push_back(static_cast<std::uint8_t>(v));
    out_.push_back(static_cast<std::uint8_t>(v >> 8));
  }
  void u32(std::uint32_t v) {
    u16(static_cast<std::uint16_t>(v));
    u16(static_cast<std::uint16_t>(v >> 16));
  }
  std::size_t size() const { return out_.size(); }
  // Starts a category; finish() pads its data to whole words and fills in the length.
  void begin(std::uint16_t type) {
    u16(type);
    lengthAt_ = out_.size();
    u16(0);
  }
  void finish(std::uint8_t pad = 0) {
    if ((out_.size() - lengthAt_) % 2 != 0) u8(pad);
    const std::size_t words = (out_.size() - lengthAt_ - 2) / 2;
    writeLe16(out_, lengthAt_, static_cast<std::uint16_t>(words));
  }

 private:
  std::vector<std::uint8_t>& out_;
  std::size_t lengthAt_{0};
};

Status checkEncodable(const SiiContents& c) {
  if (c.strings.size() > 255) {
    return makeError(ErrorCode::kInvalidArgument,
                     "SII STRINGS: " + std::to_string(c.strings.size()) + " strings (max 255)");
  }
  for (std::size_t i = 0; i < c.strings.size(); ++i) {
    if (c.strings[i].size() > 255) {
      return makeError(ErrorCode::kInvalidArgument,
                       "SII STRINGS: string " + std::to_string(i + 1) + " has " +
                           std::to_string(c.strings[i].size()) + " bytes (max 255)");
    }
  }
  for (const auto* list : {&c.txPdos, &c.rxPdos}) {
    for (const auto& pdo : *list) {
      if (pdo.entries.size() > 255) {
        return makeError(ErrorCode::kInvalidArgument,
                         "SII PDO " + hex(pdo.index) + ": more than 255 entries");
      }
    }
  }
  for (const auto& raw : c.otherCategories) {
    if (raw.data.size() > 2 * 0xFFFF) {
      return makeError(ErrorCode::kInvalidArgument,
                       "SII category " + hex(raw.type) + ": too long for its length word");
    }
  }
  return okStatus();
}

void writeRaw(Writer& w, const SiiRawCategory& raw) {
  w.begin(raw.type);
  for (std::uint8_t b : raw.data) w.u8(b);
  w.finish();
}

void writePdos(Writer& w, SiiCategoryType type, const std::vector<SiiPdo>& pdos) {
  if (pdos.empty()) return;
  w.begin(static_cast<std::uint16_t>(type));
  for (const auto& pdo : pdos) {
    w.u16(pdo.index);
    w.u8(static_cast<std::uint8_t>(pdo.entries.size()));
    w.u8(pdo.syncManager);
    w.u8(pdo.dcSync);
    w.u8(pdo.nameIndex);
    w.u16(pdo.flags);
    for (const auto& e : pdo.entries) {
      w.u16(e.index);
      w.u8(e.subIndex);
      w.u8(e.nameIndex);
      w.u8(e.dataType);
      w.u8(e.bitLength);
      w.u16(e.flags);
    }
  }
  w.finish();
}

void writeCategories(const SiiContents& c, Writer& w) {
  for (const auto& raw : c.otherCategories) {
    if (leadingRawCategory(raw.type)) writeRaw(w, raw);
  }
  if (!c.strings.empty()) {
    w.begin(static_cast<std::uint16_t>(SiiCategoryType::kStrings));
    w.u8(static_cast<std::uint8_t>(c.strings.size()));
    for (const auto& s : c.strings) {
      w.u8(static_cast<std::uint8_t>(s.size()));
      for (char ch : s) w.u8(static_cast<std::uint8_t>(ch));
    }
    w.finish();
  }
  if (c.general) {
    const SiiGeneral& g = *c.general;
    w.begin(static_cast<std::uint16_t>(SiiCategoryType::kGeneral));
    for (std::uint8_t b :
         {g.groupIndex, g.imageIndex, g.orderIndex, g.nameIndex, g.reserved4, g.coeDetails,
          g.foeDetails, g.eoeDetails, g.soeChannels, g.ds402Channels, g.sysmanClass, g.flags}) {
      w.u8(b);
    }
    w.u16(static_cast<std::uint16_t>(g.currentOnEbus));
    w.u8(g.byte14);
    w.u8(0);
    w.u16(g.physicalPorts);
    w.u16(g.physicalMemoryAddress);
    for (int i = 0; i < 12; ++i) w.u8(0);
    w.finish();
  }
  if (!c.fmmus.empty()) {
    w.begin(static_cast<std::uint16_t>(SiiCategoryType::kFmmu));
    for (auto f : c.fmmus) w.u8(static_cast<std::uint8_t>(f));
    w.finish(static_cast<std::uint8_t>(SiiFmmuUsage::kNotUsed));
  }
  if (!c.syncManagers.empty()) {
    w.begin(static_cast<std::uint16_t>(SiiCategoryType::kSyncManager));
    for (const auto& sm : c.syncManagers) {
      w.u16(sm.startAddress);
      w.u16(sm.length);
      w.u8(sm.control);
      w.u8(sm.status);
      w.u8(sm.enable);
      w.u8(static_cast<std::uint8_t>(sm.type));
    }
    w.finish();
  }
  for (const auto& raw : c.otherCategories) {
    if (!leadingRawCategory(raw.type)) writeRaw(w, raw);
  }
  writePdos(w, SiiCategoryType::kTxPdo, c.txPdos);
  writePdos(w, SiiCategoryType::kRxPdo, c.rxPdos);
  if (!c.dcOpModes.empty()) {
    w.begin(static_cast<std::uint16_t>(SiiCategoryType::kDc));
    for (const auto& m : c.dcOpModes) {
      w.u32(m.cycleTime0);
      w.u32(m.shiftTime0);
      w.u32(m.shiftTime1);
      w.u16(static_cast<std::uint16_t>(m.sync1CycleFactor));
      w.u16(m.assignActivate);
      w.u16(static_cast<std::uint16_t>(m.sync0CycleFactor));
      w.u8(m.nameIndex);
      w.u8(m.descriptionIndex);
      w.u32(0);
    }
    w.finish();
  }
  w.u16(static_cast<std::uint16_t>(SiiCategoryType::kEnd));
  w.u16(0xFFFF);  // an erased EEPROM reads 0xFFFF after END; keeps the image word-aligned x2
}

}  // namespace

std::size_t siiEncodedSize(const SiiContents& contents) {
  std::vector<std::uint8_t> out(sii::kHeaderBytes, 0);
  Writer w(out);
  writeCategories(contents, w);
  return out.size();
}

Result<std::vector<std::uint8_t>> encodeSii(const SiiContents& contents,
                                            const SiiEncodeOptions& options) {
  ECSIM_TRY(checkEncodable(contents));
  std::vector<std::uint8_t> out(sii::kHeaderBytes, 0);
  encodeHeader(contents, out);
  Writer w(out);
  writeCategories(contents, w);
  const std::size_t eeprom = contents.eepromBytes();
  if (out.size() > eeprom) {
    return makeError(ErrorCode::kTooLarge,
                     "SII image of " + std::to_string(out.size()) + " bytes does not fit the " +
                         std::to_string(eeprom * 8 / 1024) + " Kbit EEPROM of size field " +
                         std::to_string(contents.sizeField));
  }
  if (options.padToEepromSize) out.resize(eeprom, 0xFF);
  return out;
}

}  // namespace ecsim
