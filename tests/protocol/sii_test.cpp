#include "protocol/sii.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <ostream>
#include <string>
#include <vector>
#include "tests/support/ci_mode.hpp"

namespace ecsim {
namespace {

namespace fs = std::filesystem;

// Locates /work/shared/eeprom; empty when the data is absent (the caller skips, or fails
// under CI=true).
fs::path eepromDir() {
  fs::path dir = fs::path(ECSIM_SHARED_DIR) / "eeprom";
  return fs::is_directory(dir) ? dir : fs::path{};
}

#define REQUIRE_EEPROM_DIR(dir)                                               \
  const fs::path dir = eepromDir();                                           \
  if (dir.empty()) {                                                          \
    if (::ecsim::testing::ciMode())                                           \
      FAIL() << "CI=true but " ECSIM_SHARED_DIR "/eeprom is missing";         \
    GTEST_SKIP() << "reference data " ECSIM_SHARED_DIR "/eeprom not present"; \
  }

std::vector<std::uint8_t> readFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// --- checksum -------------------------------------------------------------------------------

// Golden bytes: the first 16 bytes of /work/shared/eeprom/ek1100.hex (a dump of a real
// EK1100): words 0-6 = 00 0d 00 00 ... and word 7 = 0x0046, i.e. checksum 0x46.
TEST(SiiChecksum, MatchesRealEk1100Dump) {
  const std::vector<std::uint8_t> head = {0x00, 0x0d, 0x00, 0x00, 0x00, 0x00, 0x00,
                                          0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00};
  EXPECT_EQ(siiChecksum(head), 0x46);
}

// Golden bytes: first 14 bytes of /work/shared/eeprom/STMBL_ECAT_eeprom.bin, word 7 = 0x00a9.
TEST(SiiChecksum, MatchesRealStmblImage) {
  const std::vector<std::uint8_t> head = {0x05, 0x06, 0x00, 0x44, 0x64, 0x00, 0x00,
                                          0x00, 0x00, 0x00, 0x1a, 0x00, 0x00, 0x00};
  EXPECT_EQ(siiChecksum(head), 0xA9);
}

TEST(SiiChecksum, InitialValueIsFfNotZero) {
  // With init 0x00 an all-zero area would give 0x00; with init 0xFF it does not.
  const std::vector<std::uint8_t> zeros(14, 0);
  EXPECT_NE(siiChecksum(zeros), 0x00);
}

// The configured station alias is word 4, inside the checksummed area: a new alias needs a new
// checksum, or the ESC refuses the whole header (0x0502 bit 11). Starting from the real
// EK1100 header above (checksum 0x46), alias 0x0102 gives the checksum of those bytes.
TEST(SiiStationAlias, RenewsTheChecksum) {
  std::vector<std::uint8_t> image = {0x00, 0x0d, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
                                     0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x46, 0x00};
  ASSERT_EQ(siiChecksum(image), 0x46);
  setSiiStationAlias(image, 0x0102);
  EXPECT_EQ(readLe16(image, 8), 0x0102);
  EXPECT_EQ(image[14], siiChecksum(image));
  EXPECT_NE(image[14], 0x46);
}

TEST(SiiStationAlias, AWrongChecksumStaysWrong) {
  std::vector<std::uint8_t> image(16, 0);
  image[14] = static_cast<std::uint8_t>(siiChecksum(image) ^ 0xFF);  // broken on purpose
  setSiiStationAlias(image, 7);
  EXPECT_EQ(readLe16(image, 8), 7);
  EXPECT_NE(image[14], siiChecksum(image));
}

TEST(SiiSize, FieldIsKbitMinusOne) {
  EXPECT_EQ(siiSizeFieldForBytes(256), 1);    // 2 Kbit (SOES_lan9252demo_slave.bin)
  EXPECT_EQ(siiSizeFieldForBytes(2048), 15);  // 16 Kbit (ek1100.hex)
  EXPECT_EQ(siiSizeFieldForBytes(4096), 31);  // 32 Kbit (hbm_clipx_eeprom_dump.bin)
  EXPECT_EQ(siiBytesForSizeField(15), 2048u);
  EXPECT_EQ(siiBytesForSizeField(0), 128u);
}

// --- synthetic round trip -------------------------------------------------------------------

SiiContents sampleContents() {
  SiiContents c;
  c.config.pdiControl = 0x0C05;
  c.config.stationAlias = 0x1234;
  c.identity = {0x1337, 0x4D2, 0x00020001, 42};
  c.bootstrapMailbox = {0x1000, 0x80, 0x1080, 0x80};
  c.standardMailbox = {0x1000, 0x80, 0x1080, 0x80};
  c.mailboxProtocols = SiiMailboxProtocol::kCoe | SiiMailboxProtocol::kFoe;
  c.sizeField = 3;  // 4 Kbit
  c.strings = {"dev", "group", "Name with \xb5 byte"};
  SiiGeneral g;
  g.groupIndex = 2;
  g.orderIndex = 1;
  g.nameIndex = 3;
  g.coeDetails = SiiCoeDetails::kSdo | SiiCoeDetails::kSdoInfo;
  g.currentOnEbus = -2000;
  g.physicalPorts = 0x0011;
  c.general = g;
  c.fmmus = {SiiFmmuUsage::kOutputs, SiiFmmuUsage::kInputs};
  c.syncManagers = {{0x1000, 0x80, 0x26, 0, 1, SiiSyncManagerType::kMailboxOut},
                    {0x1080, 0x80, 0x22, 0, 1, SiiSyncManagerType::kMailboxIn}};
  SiiPdo tx{0x1A00, 3, 0, 0, 0, {{0x6000, 1, 0, 1, 1, 0}, {0, 0, 0, 0, 7, 0}}};
  c.txPdos = {tx};
  c.dcOpModes = {{0, 0, 0, 0, 0x0300, 1, 0, 0}};
  c.otherCategories = {{0x0800, {1, 2, 3, 4}}};
  return c;
}

TEST(SiiEncode, RoundTripsThroughParse) {
  const SiiContents c = sampleContents();
  auto bytes = encodeSii(c);
  ASSERT_TRUE(bytes.ok()) << bytes.error().message();
  EXPECT_EQ(bytes->size(), 512u);
  auto image = SiiImage::parse(*bytes);
  ASSERT_TRUE(image.ok()) << image.error().message();
  EXPECT_TRUE(image->checksumOk());
  EXPECT_EQ(image->contents(), c);
  EXPECT_EQ(image->string(3), "Name with \xb5 byte");
  EXPECT_EQ(image->string(0), "");
  EXPECT_EQ(image->string(4), "");
}

TEST(SiiEncode, HeaderGoldenWords) {
  auto bytes = encodeSii(sampleContents());
  ASSERT_TRUE(bytes.ok());
  ConstBytes b(*bytes);
  EXPECT_EQ(readLe16(b, 0), 0x0C05);
  EXPECT_EQ(readLe16(b, 2 * 4), 0x1234);
  EXPECT_EQ(readLe32(b, 2 * 0x08), 0x1337u);
  EXPECT_EQ(readLe32(b, 2 * 0x0A), 0x4D2u);
  EXPECT_EQ(readLe16(b, 2 * 0x1C), 0x000C);
  EXPECT_EQ(readLe16(b, 2 * 0x3E), 3);
  EXPECT_EQ(readLe16(b, 2 * 0x3F), 1);
  EXPECT_EQ(b[14], siiChecksum(b.first(14)));
  // The vendor category comes first, as in real dumps (akd.hex).
  EXPECT_EQ(readLe16(b, 0x80), 0x0800);
  EXPECT_EQ(readLe16(b, 0x82), 2);
  // Erased EEPROM past END.
  EXPECT_EQ(b.back(), 0xFF);
}

TEST(SiiEncode, OddFmmuCountIsPaddedWithNotUsed) {
  SiiContents c;
  c.sizeField = 1;
  c.fmmus = {SiiFmmuUsage::kOutputs, SiiFmmuUsage::kInputs, SiiFmmuUsage::kSyncManagerStatus};
  auto bytes = encodeSii(c);
  ASSERT_TRUE(bytes.ok());
  auto image = SiiImage::parse(*bytes);
  ASSERT_TRUE(image.ok());
  ASSERT_EQ(image->contents().fmmus.size(), 4u);
  EXPECT_EQ(image->contents().fmmus[3], SiiFmmuUsage::kNotUsed);
}

TEST(SiiEncode, RefusesImageLargerThanEeprom) {
  SiiContents c = sampleContents();
  c.sizeField = 0;  // 1 Kbit = 128 bytes: only the header fits
  auto bytes = encodeSii(c);
  ASSERT_FALSE(bytes.ok());
  EXPECT_EQ(bytes.error().code, ErrorCode::kTooLarge);
}

TEST(SiiEncode, RefusesOverlongString) {
  SiiContents c;
  c.sizeField = 15;
  c.strings = {std::string(256, 'x')};
  auto bytes = encodeSii(c);
  ASSERT_FALSE(bytes.ok());
  EXPECT_EQ(bytes.error().code, ErrorCode::kInvalidArgument);
}

// --- parse errors ---------------------------------------------------------------------------

TEST(SiiParse, RejectsShortHeader) {
  std::vector<std::uint8_t> bytes(100, 0);
  auto image = SiiImage::parse(bytes);
  ASSERT_FALSE(image.ok());
  EXPECT_EQ(image.error().code, ErrorCode::kTruncated);
}

TEST(SiiParse, CategoryPastEndNamesWordOffset) {
  std::vector<std::uint8_t> bytes(sii::kHeaderBytes + 8, 0);
  writeLe16(bytes, 0x80, 10);   // STRINGS
  writeLe16(bytes, 0x82, 100);  // 100 words, only 2 present
  auto image = SiiImage::parse(bytes);
  ASSERT_FALSE(image.ok());
  EXPECT_EQ(image.error().code, ErrorCode::kTruncated);
  EXPECT_NE(image.error().context.find("SII word 0x0040"), std::string::npos)
      << image.error().context;
  auto lenient = SiiImage::parseLenient(bytes);
  ASSERT_TRUE(lenient.ok());
  ASSERT_TRUE(lenient->damage().has_value());
  EXPECT_TRUE(lenient->categories().empty());
}

TEST(SiiParse, EndOfDataAtCategoryBoundaryEndsList) {
  auto bytes = encodeSii(sampleContents(), {.padToEepromSize = false});
  ASSERT_TRUE(bytes.ok());
  bytes->resize(bytes->size() - 4);  // drop END and the erased word
  auto image = SiiImage::parse(*bytes);
  ASSERT_TRUE(image.ok()) << image.error().message();
  EXPECT_EQ(image->contents().dcOpModes.size(), 1u);
}

TEST(SiiParse, StringRunningPastCategoryIsAnError) {
  std::vector<std::uint8_t> data = {2, 3, 'a', 'b', 'c', 9, 'x'};
  auto strings = decodeSiiStrings(data, 0x40);
  ASSERT_FALSE(strings.ok());
  EXPECT_NE(strings.error().context.find("string 2 of 2"), std::string::npos);
}

TEST(SiiParse, PdoEntriesPastCategoryIsAnError) {
  std::vector<std::uint8_t> data = {0x00, 0x1A, 2, 3, 0, 0, 0, 0, 0x00, 0x60, 1, 0, 1, 1, 0, 0};
  auto pdos = decodeSiiPdos(data, 0x50);
  ASSERT_FALSE(pdos.ok());
  EXPECT_NE(pdos.error().context.find("0x1A00"), std::string::npos);
}

TEST(SiiParse, RawCategoriesComeInEncoderOrder) {
  // A SyncUnit category before a device-specific one (found by mutating el2828.hex): the
  // encoder writes device-specific/vendor categories first, so the decoder lists them first.
  std::vector<std::uint8_t> bytes(sii::kHeaderBytes, 0);
  writeLe16(bytes, 2 * sii::kWordSize, 1);
  for (int word : {0x002B, 1, 0xFFF0, 0x0003, 1, 0x1234, 0xFFFF}) {
    bytes.push_back(static_cast<std::uint8_t>(word));
    bytes.push_back(static_cast<std::uint8_t>(word >> 8));
  }
  auto image = SiiImage::parse(bytes);
  ASSERT_TRUE(image.ok()) << image.error().message();
  ASSERT_EQ(image->contents().otherCategories.size(), 2u);
  EXPECT_EQ(image->contents().otherCategories[0].type, 0x0003);
  EXPECT_EQ(image->contents().otherCategories[1].type, 0x002B);
  EXPECT_EQ(image->categories()[0].type, 0x002B);  // the category list keeps image order
  auto again = encodeSii(image->contents());
  ASSERT_TRUE(again.ok());
  auto reparsed = SiiImage::parse(*again);
  ASSERT_TRUE(reparsed.ok());
  EXPECT_EQ(reparsed->contents(), image->contents());
}

TEST(SiiCategoryReader, SkipsNothingAndReportsVendorCategories) {
  auto bytes = encodeSii(sampleContents());
  ASSERT_TRUE(bytes.ok());
  SiiCategoryReader reader(*bytes);
  std::vector<std::uint16_t> types;
  while (true) {
    auto next = reader.next();
    ASSERT_TRUE(next.ok());
    if (!next->has_value()) break;
    types.push_back((*next)->type);
  }
  EXPECT_EQ(types, (std::vector<std::uint16_t>{0x0800, 10, 30, 40, 41, 50, 60}));
}

// --- real EEPROM images (/work/shared/eeprom, identities as its MANIFEST.md lists them) -------

struct RealImage {
  const char* file;
  SiiIdentity identity;
  SiiMailbox standardMailbox;
  std::uint16_t mailboxProtocols;
  std::uint16_t sizeField;
  std::vector<std::uint16_t> categoryTypes;  // in image order
};

void PrintTo(const RealImage& r, std::ostream* os) {
  *os << r.file;
}

const std::vector<RealImage> kRealImages = {
    {"ek1100.hex", {0x2, 0x044C2C52, 0x00120000, 0}, {}, 0, 15, {10, 30}},
    {"el2004-eeprom-dump.bin",
     {0x2, 0x07D43052, 0x00100000, 0},
     {},
     0,
     15,
     {10, 30, 40, 41, 43, 51}},
    {"el2828.hex", {0x2, 0x0B0C3052, 0x00110000, 0}, {}, 0, 15, {3, 10, 30, 40, 41, 43, 51}},
    {"el2889.hex", {0x2, 0x0B493052, 0x00110000, 0}, {}, 0, 15, {10, 30, 40, 41, 43, 51}},
    {"el2262.bin",
     {0x2, 0x08D63052, 0x00030000, 0},
     {},
     0,
     15,
     {1, 10, 30, 40, 41, 42, 43, 50, 51, 60}},
    {"akd.hex",
     {0x6A, 0x00414B44, 2, 0x99830093},
     {0x1800, 1024, 0x1C00, 1024},
     0x0E,
     15,
     {0x0800, 0x0801, 10, 30, 40, 41, 43, 50, 51, 60}},
    {"hbm_clipx_eeprom_dump.bin",
     {0x11D, 0x0F01, 1, 0xE502A405},
     {0x1000, 128, 0x1080, 128},
     0x0C,
     31,
     {10, 30, 40, 41}},
    {"ni_9144_rev_1.bin",
     {0x1F9, 0x23B8, 1, 0},
     {0x1F00, 256, 0x1C00, 768},
     0x0D,
     15,
     {10, 30, 40, 41, 42, 50, 60}},
    {"ni_9144_rev_2.bin",
     {0x1F9, 0x23B8, 2, 0},
     {0x1F00, 256, 0x1C00, 768},
     0x0D,
     15,
     {10, 30, 40, 41, 42, 50, 60}},
    {"Orbita2d.bin",
     {0x0, 0x1, 0x1, 0},
     {0x1000, 128, 0x1180, 128},
     0x0C,
     31,
     {10, 30, 41, 50, 50, 51, 60, 60}},
    {"STMBL_ECAT_eeprom.bin",
     {0x1337, 0x20192, 1, 1},
     {0x1000, 512, 0x1200, 512},
     0x04,
     15,
     {10, 30, 40, 41}},
    {"SOES_lan9252demo_slave.bin",
     {0x1337, 0x4D2, 0, 0},
     {0x1000, 128, 0x1080, 128},
     0x0C,
     1,
     {10, 30, 40, 41}},
};

class RealSiiImage : public ::testing::TestWithParam<RealImage> {};

TEST_P(RealSiiImage, ParsesWithManifestIdentity) {
  REQUIRE_EEPROM_DIR(dir);
  const RealImage& expected = GetParam();
  const auto bytes = readFile(dir / expected.file);
  ASSERT_FALSE(bytes.empty()) << expected.file;
  auto image = SiiImage::parse(bytes);
  ASSERT_TRUE(image.ok()) << expected.file << ": " << image.error().message();
  EXPECT_TRUE(image->checksumOk());
  EXPECT_EQ(image->identity(), expected.identity);
  EXPECT_EQ(image->contents().standardMailbox, expected.standardMailbox);
  EXPECT_EQ(image->contents().mailboxProtocols, expected.mailboxProtocols);
  EXPECT_EQ(image->contents().sizeField, expected.sizeField);
  EXPECT_EQ(image->contents().version, 1);
  std::vector<std::uint16_t> types;
  for (const auto& cat : image->categories()) types.push_back(cat.type);
  EXPECT_EQ(types, expected.categoryTypes);
  ASSERT_TRUE(image->contents().general.has_value());
  EXPECT_FALSE(image->contents().strings.empty());
  // Every SM of a mailbox slave agrees with the mailbox words (SOEM programs SM0/SM1 from the
  // SM category and the mailbox from the words).
  const auto& sms = image->contents().syncManagers;
  if (expected.standardMailbox.receiveSize != 0 && sms.size() >= 2) {
    EXPECT_EQ(sms[0].startAddress, expected.standardMailbox.receiveOffset);
    EXPECT_EQ(sms[0].length, expected.standardMailbox.receiveSize);
    EXPECT_EQ(sms[0].type, SiiSyncManagerType::kMailboxOut);
    EXPECT_EQ(sms[1].startAddress, expected.standardMailbox.sendOffset);
    EXPECT_EQ(sms[1].type, SiiSyncManagerType::kMailboxIn);
  }
}

TEST_P(RealSiiImage, ContentsRoundTripThroughEncoder) {
  REQUIRE_EEPROM_DIR(dir);
  const auto bytes = readFile(dir / GetParam().file);
  auto image = SiiImage::parse(bytes);
  ASSERT_TRUE(image.ok());
  auto again = encodeSii(image->contents());
  ASSERT_TRUE(again.ok()) << again.error().message();
  auto reparsed = SiiImage::parse(*again);
  ASSERT_TRUE(reparsed.ok()) << reparsed.error().message();
  SiiContents expected = image->contents();
  // Categories of one type are merged by the encoder (Orbita2d has two TXPDO and two DC
  // categories); the decoded contents are the same.
  EXPECT_EQ(reparsed->contents(), expected);
  // Header words are byte-identical.
  EXPECT_TRUE(std::equal(bytes.begin(), bytes.begin() + sii::kHeaderBytes, again->begin()));
}

INSTANTIATE_TEST_SUITE_P(Eeprom, RealSiiImage, ::testing::ValuesIn(kRealImages),
                         [](const auto& param_info) {
                           std::string name = param_info.param.file;
                           for (auto& ch : name) {
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           }
                           return name;
                         });

TEST(RealSiiImage, EveryFileInTheDirectoryIsCovered) {
  REQUIRE_EEPROM_DIR(dir);
  std::size_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const auto ext = entry.path().extension();
    if (ext == ".bin" || ext == ".hex") ++files;
  }
  EXPECT_EQ(files, kRealImages.size() + 1);  // + akd_null_strings.hex, tested below
}

TEST(RealSiiImage, DetailsOfRealDumps) {
  REQUIRE_EEPROM_DIR(dir);
  auto ek1100 = SiiImage::parse(readFile(dir / "ek1100.hex"));
  ASSERT_TRUE(ek1100.ok());
  EXPECT_EQ(ek1100->contents().config.pdiControl, 0x0D00);
  EXPECT_EQ(ek1100->string(1), "EK1100");
  EXPECT_EQ(ek1100->string(ek1100->contents().general->nameIndex),
            "EK1100 EtherCAT-Koppler (2A E-Bus)");
  EXPECT_EQ(ek1100->contents().general->currentOnEbus, -2000);
  EXPECT_EQ(ek1100->contents().general->port(0), SiiPortPhysics::kMii);
  EXPECT_EQ(ek1100->contents().general->port(1), SiiPortPhysics::kEbus);

  auto el2889 = SiiImage::parse(readFile(dir / "el2889.hex"));
  ASSERT_TRUE(el2889.ok());
  EXPECT_EQ(el2889->contents().rxPdos.size(), 16u);
  EXPECT_EQ(el2889->contents().rxPdos[0].index, 0x1600);
  EXPECT_EQ(el2889->contents().rxPdos[0].entries.at(0).index, 0x7000);
  EXPECT_EQ(el2889->contents().rxPdos[0].entries.at(0).bitLength, 1);

  auto el2262 = SiiImage::parse(readFile(dir / "el2262.bin"));
  ASSERT_TRUE(el2262.ok());
  ASSERT_EQ(el2262->contents().dcOpModes.size(), 4u);  // 96 bytes of 24
  EXPECT_EQ(el2262->contents().dcOpModes[0].assignActivate, 0x0730);
  bool sawMicro = false;
  for (const auto& s : el2262->contents().strings) {
    if (s.find("1\xb5s") != std::string::npos) sawMicro = true;  // Latin-1 kept as a byte
  }
  EXPECT_TRUE(sawMicro);

  auto akd = SiiImage::parse(readFile(dir / "akd.hex"));
  ASSERT_TRUE(akd.ok());
  EXPECT_EQ(akd->contents().bootstrapMailbox, (SiiMailbox{0x1800, 1024, 0x1C00, 1024}));
  ASSERT_EQ(akd->contents().dcOpModes.size(), 2u);
  EXPECT_EQ(akd->string(akd->contents().dcOpModes[0].nameIndex), "DcSync");
  EXPECT_EQ(akd->string(akd->contents().dcOpModes[1].nameIndex), "DcOff");
  EXPECT_EQ(akd->contents().dcOpModes[0].assignActivate, 0x0300);

  auto hbm = SiiImage::parse(readFile(dir / "hbm_clipx_eeprom_dump.bin"));
  ASSERT_TRUE(hbm.ok());
  EXPECT_EQ(hbm->string(1).substr(0, 2), "BM");  // a BMP icon stored as string 1

  auto ni1 = SiiImage::parse(readFile(dir / "ni_9144_rev_1.bin"));
  auto ni2 = SiiImage::parse(readFile(dir / "ni_9144_rev_2.bin"));
  ASSERT_TRUE(ni1.ok() && ni2.ok());
  EXPECT_EQ(ni1->contents().bootstrapMailbox, (SiiMailbox{0x1C00, 1024, 0x1800, 1024}));
  EXPECT_LT(ni1->contents().txPdos.size(), ni2->contents().txPdos.size());

  auto orbita = SiiImage::parse(readFile(dir / "Orbita2d.bin"));
  ASSERT_TRUE(orbita.ok());
  EXPECT_EQ(orbita->string(1), "SSC_Device");
  EXPECT_EQ(orbita->contents().txPdos.size(), 2u);  // from two TXPDO categories
  EXPECT_EQ(orbita->contents().dcOpModes.size(), 2u);
  EXPECT_EQ(orbita->bytes().size(), 1180u);
}

TEST(RealSiiImage, DamagedAkdGivesCleanErrorAndKeepsWhatCameBefore) {
  REQUIRE_EEPROM_DIR(dir);
  const auto bytes = readFile(dir / "akd_null_strings.hex");
  ASSERT_EQ(bytes.size(), 2036u);
  auto strict = SiiImage::parse(bytes);
  ASSERT_FALSE(strict.ok());
  EXPECT_EQ(strict.error().code, ErrorCode::kTruncated);
  EXPECT_NE(strict.error().context.find("SII word 0x0145"), std::string::npos)
      << strict.error().context;
  EXPECT_NE(strict.error().context.find("runs past the end"), std::string::npos);

  auto lenient = SiiImage::parseLenient(bytes);
  ASSERT_TRUE(lenient.ok()) << lenient.error().message();
  ASSERT_TRUE(lenient->damage().has_value());
  EXPECT_EQ(lenient->identity(), (SiiIdentity{0x6A, 0x00414B44, 2, 0x99830093}));
  EXPECT_EQ(lenient->contents().standardMailbox, (SiiMailbox{0x1800, 1024, 0x1C00, 1024}));
  ASSERT_EQ(lenient->categories().size(), 3u);  // 0x0800, 0x0801, STRINGS
  EXPECT_EQ(lenient->string(1), "AKD");
  EXPECT_EQ(lenient->string(4), "AKD EtherCA");
  EXPECT_FALSE(lenient->contents().general.has_value());
}

}  // namespace
}  // namespace ecsim
