// The ESI files of ecsim's own devices (examples/esi, documented in examples/README.md): every
// file parses; the devices, PDO layouts and dictionaries are the designed ones; dictionaries,
// PDOs and SyncManagers agree with each other; the SII images built from them re-parse.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <iterator>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "config/esi.hpp"
#include "config/sii_builder.hpp"
#include "protocol/sii.hpp"

namespace ecsim {
namespace {

namespace fs = std::filesystem;

constexpr std::uint32_t kVendorId = 0x00000E5C;
constexpr std::uint32_t kRevision = 0x00010000;
constexpr std::uint16_t kProcessRamStart = 0x1000;
constexpr std::uint16_t kProcessRamEnd = 0x2000;  // 4 KB: also fits a LAN9252-class ESC

fs::path examplesEsiDir() {
  return fs::path(ECSIM_SOURCE_DIR) / "examples" / "esi";
}

// --- a dictionary object expanded into its entries ----------------------------------------------

struct DictEntry {
  std::uint8_t subIndex{0};
  std::string type;
  std::uint32_t bits{0};
  EsiFlags flags;
  const EsiValueInfo* info{nullptr};
};

// VAR: sub 0. RECORD: its SubItems. ARRAY (sub 0 + an "Elements" SubItem of an array type):
// sub 0 and one entry per element. Defaults come from Object/Info/SubItem by position.
std::vector<DictEntry> expand(const EsiDictionary& dict, const EsiObject& o) {
  std::vector<DictEntry> out;
  const EsiDataType* dt = dict.findDataType(o.type);
  if (dt == nullptr || !dt->isRecord()) {
    out.push_back({0, o.type, o.bitSize, o.flags, &o.info});
    return out;
  }
  std::size_t position = 0;
  auto infoAt = [&](std::size_t p) {
    return p < o.subItems.size() ? &o.subItems[p].info : nullptr;
  };
  for (const EsiSubItemType& s : dt->subItems) {
    const EsiDataType* array = dict.findDataType(s.type);
    if (array != nullptr && array->isArray()) {
      const EsiArrayInfo& a = array->arrays.front();
      for (std::uint32_t k = 0; k < a.elements; ++k) {
        out.push_back({static_cast<std::uint8_t>(a.lowerBound + k), array->baseType,
                       array->bitSize / a.elements, s.flags, infoAt(position++)});
      }
    } else {
      out.push_back({s.subIndex, s.type, s.bitSize, s.flags, infoAt(position++)});
    }
  }
  return out;
}

const DictEntry* findEntry(const std::vector<DictEntry>& entries, std::uint8_t sub) {
  for (const auto& e : entries) {
    if (e.subIndex == sub) return &e;
  }
  return nullptr;
}

std::optional<std::int64_t> defaultOf(const DictEntry* e) {
  if (e == nullptr || e->info == nullptr || !e->info->defaultValue) return std::nullopt;
  auto v = parseEsiInteger(*e->info->defaultValue);
  return v.ok() ? std::optional<std::int64_t>(*v) : std::nullopt;
}

std::uint32_t bitsOf(const std::vector<const EsiPdo*>& pdos) {
  std::uint32_t bits = 0;
  for (const EsiPdo* p : pdos) bits += p->bitLength();
  return bits;
}

std::vector<const EsiPdo*> assigned(const std::vector<EsiPdo>& pdos) {
  std::vector<const EsiPdo*> out;
  for (const auto& p : pdos) {
    if (p.sm) out.push_back(&p);
  }
  return out;
}

const EsiPdo* findPdo(const EsiDevice& d, std::uint16_t index) {
  for (const auto* list : {&d.rxPdos, &d.txPdos}) {
    for (const auto& p : *list) {
      if (p.index == index) return &p;
    }
  }
  return nullptr;
}

// --- the file ------------------------------------------------------------------------------------

class ExamplesEsi : public ::testing::Test {
 protected:
  void SetUp() override {
    auto file = loadEsiFile(examplesEsiDir() / "ecsim_devices.xml");
    ASSERT_TRUE(file.ok()) << file.error().message();
    file_ = std::move(*file);
  }
  const EsiDevice* device(std::uint32_t productCode) const {
    for (const auto& d : file_.devices) {
      if (d.productCode == productCode) return &d;
    }
    return nullptr;
  }
  EsiFile file_;
};

#define ECSIM_DEVICE(var, product)        \
  const EsiDevice* var = device(product); \
  ASSERT_NE(var, nullptr) << "no device with product code " << std::hex << (product)

TEST(ExamplesEsiFiles, EveryFileParsesWithOurVendorAndRevision) {
  std::size_t files = 0;
  for (const auto& item : fs::directory_iterator(examplesEsiDir())) {
    if (item.path().extension() != ".xml") continue;
    ++files;
    SCOPED_TRACE(item.path().string());
    auto file = loadEsiFile(item.path());
    ASSERT_TRUE(file.ok()) << file.error().message();
    EXPECT_EQ(file->root, EsiRoot::kEtherCatInfo);
    EXPECT_EQ(file->vendor.id, kVendorId);
    EXPECT_EQ(file->vendor.name(), "ecsim project");
    EXPECT_FALSE(file->devices.empty());
    for (const EsiDevice& d : file->devices) {
      SCOPED_TRACE(d.type);
      EXPECT_TRUE(d.hasProductCode);
      EXPECT_EQ(d.revision, kRevision);
      EXPECT_TRUE(std::any_of(d.names.begin(), d.names.end(),
                              [](const EsiLocalText& t) { return t.lcid == 1033; }));
      EXPECT_EQ(d.name().rfind(d.type, 0), 0u) << "the name starts with the type: " << d.name();
      EXPECT_NE(file->findGroup(d.groupType), nullptr) << d.groupType;
      ASSERT_TRUE(d.eeprom.has_value());
      EXPECT_EQ(d.eeprom->byteSize, 2048u);
      EXPECT_EQ(d.eeprom->configData.size(), 14u) << "SII words 0-6";
      EXPECT_FALSE(d.mailbox.coeDetails.completeAccess) << "SOEM would try complete access";
    }
  }
  EXPECT_GE(files, 1u) << "no ESI file in " << examplesEsiDir();
}

TEST_F(ExamplesEsi, DeviceSetIsAsDesigned) {
  struct Expected {
    std::uint32_t product;
    const char* type;
    const char* physics;
    const char* group;
  };
  const Expected expected[] = {
      {0x1100, "ECS1100", "YY", "Coupler"}, {0x1122, "ECS1122", "YYYY", "Coupler"},
      {0x1008, "ECS1008", "YY", "DigIn"},   {0x2008, "ECS2008", "YY", "DigOut"},
      {0x3102, "ECS3102", "YY", "AnaIn"},   {0x7201, "ECS7201", "YY", "Drive"},
      {0x7211, "ECS7211", "YY", "Drive"},
  };
  ASSERT_EQ(file_.devices.size(), std::size(expected));
  for (const auto& e : expected) {
    ECSIM_DEVICE(d, e.product);
    EXPECT_EQ(d->type, e.type);
    EXPECT_EQ(d->physics, e.physics);
    EXPECT_EQ(d->groupType, e.group);
  }
}

TEST_F(ExamplesEsi, CouplersHaveNoProcessDataAndNoMailbox) {
  for (std::uint32_t product : {0x1100u, 0x1122u}) {
    ECSIM_DEVICE(d, product);
    EXPECT_TRUE(d->fmmus.empty());
    EXPECT_TRUE(d->syncManagers.empty());
    EXPECT_TRUE(d->rxPdos.empty() && d->txPdos.empty());
    EXPECT_FALSE(d->mailbox.present);
    EXPECT_TRUE(d->dictionary.objects.empty());
  }
}

void expectEightBits(const EsiPdo& pdo, std::uint16_t index, std::uint16_t object) {
  EXPECT_EQ(pdo.index, index);
  EXPECT_EQ(pdo.sm, 0);
  EXPECT_TRUE(pdo.fixed && pdo.mandatory);
  ASSERT_EQ(pdo.entries.size(), 8u);
  for (std::uint8_t i = 0; i < 8; ++i) {
    EXPECT_EQ(pdo.entries[i].index, object);
    EXPECT_EQ(pdo.entries[i].subIndex, i + 1);
    EXPECT_EQ(pdo.entries[i].bitLength, 1);
    EXPECT_EQ(pdo.entries[i].dataType, "BOOL");
  }
  EXPECT_EQ(pdo.bitLength(), 8u);
}

TEST_F(ExamplesEsi, DigitalInputAndOutputAreOneBitPackedByte) {
  ECSIM_DEVICE(in, 0x1008);
  ASSERT_EQ(in->syncManagers.size(), 1u);
  const EsiSyncManager& smIn = in->syncManagers[0];
  EXPECT_EQ(smIn.text, "Inputs");
  EXPECT_EQ(smIn.startAddress, 0x1000);
  EXPECT_EQ(smIn.defaultSize, 1);
  EXPECT_EQ(smIn.controlByte, 0x00);  // buffered, ECAT reads, no PDI interrupt (as EL1008)
  EXPECT_EQ(in->fmmus.size(), 1u);
  EXPECT_EQ(in->fmmus.at(0).text, "Inputs");
  EXPECT_TRUE(in->rxPdos.empty());
  ASSERT_EQ(in->txPdos.size(), 1u);
  expectEightBits(in->txPdos[0], 0x1A00, 0x6000);
  EXPECT_FALSE(in->mailbox.present);

  ECSIM_DEVICE(out, 0x2008);
  ASSERT_EQ(out->syncManagers.size(), 1u);
  const EsiSyncManager& smOut = out->syncManagers[0];
  EXPECT_EQ(smOut.text, "Outputs");
  EXPECT_EQ(smOut.startAddress, 0x1000);
  EXPECT_EQ(smOut.defaultSize, 1);
  EXPECT_EQ(smOut.controlByte, 0x44);  // buffered, ECAT writes, watchdog trigger
  EXPECT_EQ(out->fmmus.at(0).text, "Outputs");
  EXPECT_TRUE(out->txPdos.empty());
  ASSERT_EQ(out->rxPdos.size(), 1u);
  expectEightBits(out->rxPdos[0], 0x1600, 0x7000);
  EXPECT_FALSE(out->mailbox.present);
}

void expectMailboxSms(const EsiDevice& d) {
  ASSERT_GE(d.syncManagers.size(), 2u);
  EXPECT_EQ(d.syncManagers[0].text, "MBoxOut");
  EXPECT_EQ(d.syncManagers[0].startAddress, 0x1000);
  EXPECT_EQ(d.syncManagers[0].defaultSize, 128);
  EXPECT_EQ(d.syncManagers[0].controlByte, 0x26);
  EXPECT_EQ(d.syncManagers[1].text, "MBoxIn");
  EXPECT_EQ(d.syncManagers[1].startAddress, 0x1080);
  EXPECT_EQ(d.syncManagers[1].defaultSize, 128);
  EXPECT_EQ(d.syncManagers[1].controlByte, 0x22);
  EXPECT_TRUE(d.mailbox.coe);
  EXPECT_TRUE(d.mailbox.coeDetails.sdoInfo);
  EXPECT_TRUE(d.mailbox.coeDetails.pdoAssign);
  EXPECT_TRUE(d.mailbox.coeDetails.pdoConfig);
  EXPECT_EQ(d.mailbox.protocolMask(), SiiMailboxProtocol::kCoe);
}

struct ObjectSpec {
  std::uint16_t index;
  const char* type;
  EsiAccess access;
  const char* pdoMapping;
};

void expectObjects(const EsiDevice& d, const std::vector<ObjectSpec>& specs) {
  for (const auto& s : specs) {
    const EsiObject* o = d.dictionary.findObject(s.index);
    ASSERT_NE(o, nullptr) << std::hex << s.index;
    EXPECT_EQ(o->type, s.type) << std::hex << s.index;
    EXPECT_EQ(o->flags.access, s.access) << std::hex << s.index;
    EXPECT_EQ(o->flags.pdoMapping, s.pdoMapping) << std::hex << s.index;
  }
}

// Entry types of records and arrays: {index, sub, type}.
struct EntrySpec {
  std::uint16_t index;
  std::uint8_t sub;
  const char* type;
};

void expectEntries(const EsiDevice& d, const std::vector<EntrySpec>& specs) {
  for (const auto& s : specs) {
    const EsiObject* o = d.dictionary.findObject(s.index);
    ASSERT_NE(o, nullptr) << std::hex << s.index;
    const auto entries = expand(d.dictionary, *o);
    const DictEntry* e = findEntry(entries, s.sub);
    ASSERT_NE(e, nullptr) << std::hex << s.index << ":" << int{s.sub};
    EXPECT_EQ(e->type, s.type) << std::hex << s.index << ":" << int{s.sub};
  }
}

constexpr auto kRo = EsiAccess::kReadOnly;
constexpr auto kRw = EsiAccess::kReadWrite;

TEST_F(ExamplesEsi, AnalogInputHasTwoStatusValueChannels) {
  ECSIM_DEVICE(d, 0x3102);
  expectMailboxSms(*d);
  ASSERT_EQ(d->syncManagers.size(), 4u);
  EXPECT_EQ(d->syncManagers[2].text, "Outputs");
  EXPECT_EQ(d->syncManagers[2].defaultSize, 0) << "no outputs";
  EXPECT_EQ(d->syncManagers[3].text, "Inputs");
  EXPECT_EQ(d->syncManagers[3].startAddress, 0x1180);
  EXPECT_EQ(d->syncManagers[3].defaultSize, 8);
  EXPECT_TRUE(d->dcOpModes.empty());
  EXPECT_TRUE(d->rxPdos.empty());
  ASSERT_EQ(d->txPdos.size(), 2u);
  for (std::uint16_t ch = 0; ch < 2; ++ch) {
    const EsiPdo& p = d->txPdos[ch];
    EXPECT_EQ(p.index, 0x1A00 + ch);
    EXPECT_EQ(p.sm, 3);
    ASSERT_EQ(p.entries.size(), 2u);
    EXPECT_EQ(p.entries[0].index, 0x6000 + 0x10 * ch);
    EXPECT_EQ(p.entries[0].subIndex, 0x01);
    EXPECT_EQ(p.entries[0].dataType, "UINT");
    EXPECT_EQ(p.entries[1].subIndex, 0x11);
    EXPECT_EQ(p.entries[1].dataType, "INT");
    EXPECT_EQ(p.bitLength(), 32u);
  }
  expectObjects(*d, {{0x1000, "UDINT", kRo, ""},
                     {0x1001, "USINT", kRo, "T"},
                     {0x1008, "STRING(7)", kRo, ""},
                     {0x1009, "STRING(3)", kRo, ""},
                     {0x100A, "STRING(5)", kRo, ""},
                     {0x1018, "DT1018", kRo, ""},
                     {0x1A00, "DT1A00", kRw, ""},
                     {0x1A01, "DT1A01", kRw, ""},
                     {0x1C00, "DT1C00", kRo, ""},
                     {0x1C12, "DT1C12", kRw, ""},
                     {0x1C13, "DT1C13", kRw, ""},
                     {0x1C33, "DT1C33", kRo, ""},
                     {0x6000, "DT6000", kRo, ""},
                     {0x6010, "DT6000", kRo, ""},
                     {0x8000, "DT8000", kRw, ""},
                     {0x8010, "DT8000", kRw, ""}});
  EXPECT_EQ(d->dictionary.objects.size(), 16u);
  expectEntries(*d, {{0x6000, 0x01, "UINT"},
                     {0x6000, 0x11, "INT"},
                     {0x8000, 0x01, "BOOL"},
                     {0x8000, 0x02, "BOOL"},
                     {0x8000, 0x03, "BOOL"},
                     {0x8000, 0x11, "INT"},
                     {0x8000, 0x12, "INT"},
                     {0x8000, 0x13, "UINT"},
                     {0x1C33, 0x01, "UINT"},
                     {0x1C33, 0x20, "BOOL"}});
  const auto rxAssign = expand(d->dictionary, *d->dictionary.findObject(0x1C12));
  ASSERT_EQ(rxAssign.size(), 1u) << "0x1C12 holds no PDO";
  EXPECT_EQ(defaultOf(&rxAssign[0]), 0);
}

const std::vector<ObjectSpec> kDriveObjects = {
    {0x1000, "UDINT", kRo, ""},  {0x1001, "USINT", kRo, "T"}, {0x1008, "STRING(7)", kRo, ""},
    {0x1018, "DT1018", kRo, ""}, {0x1C00, "DT1C00", kRo, ""}, {0x1C12, "DT1C12", kRw, ""},
    {0x1C13, "DT1C13", kRw, ""}, {0x1C32, "DT1C32", kRo, ""}, {0x1C33, "DT1C33", kRo, ""},
    {0x603F, "UINT", kRo, "T"},  {0x6040, "UINT", kRw, "R"},  {0x6041, "UINT", kRo, "T"},
    {0x605A, "INT", kRw, ""},    {0x6060, "SINT", kRw, "R"},  {0x6061, "SINT", kRo, "T"},
    {0x6064, "DINT", kRo, "T"},  {0x6065, "UDINT", kRw, ""},  {0x6066, "UINT", kRw, ""},
    {0x606C, "DINT", kRo, "T"},  {0x6071, "INT", kRw, "R"},   {0x6072, "UINT", kRw, "R"},
    {0x6077, "INT", kRo, "T"},   {0x607A, "DINT", kRw, "R"},  {0x607D, "DT607D", kRw, ""},
    {0x6080, "UDINT", kRw, ""},  {0x6081, "UDINT", kRw, "R"}, {0x6083, "UDINT", kRw, "R"},
    {0x6084, "UDINT", kRw, "R"}, {0x6098, "SINT", kRw, ""},   {0x6099, "DT6099", kRw, ""},
    {0x609A, "UDINT", kRw, ""},  {0x60C2, "DT60C2", kRw, ""}, {0x60F4, "DINT", kRo, "T"},
    {0x60FF, "DINT", kRw, "R"},  {0x6502, "UDINT", kRo, ""},
};

const std::vector<EntrySpec> kDriveEntries = {
    {0x1018, 1, "UDINT"}, {0x1018, 4, "UDINT"}, {0x607D, 1, "DINT"},  {0x607D, 2, "DINT"},
    {0x6099, 1, "UDINT"}, {0x6099, 2, "UDINT"}, {0x60C2, 1, "USINT"}, {0x60C2, 2, "SINT"},
    {0x1C32, 1, "UINT"},  {0x1C32, 2, "UDINT"}, {0x1C32, 4, "UINT"},  {0x1C32, 0x20, "BOOL"},
};

void expectDriveBasics(const EsiDevice& d) {
  expectMailboxSms(d);
  ASSERT_EQ(d.syncManagers.size(), 4u);
  EXPECT_EQ(d.syncManagers[2].startAddress, 0x1100);
  EXPECT_EQ(d.syncManagers[2].controlByte, 0x64);
  EXPECT_EQ(d.syncManagers[3].startAddress, 0x1180);
  EXPECT_EQ(d.syncManagers[3].controlByte, 0x20);
  EXPECT_EQ(d.mailbox.coeDetails.ds402Channels, 1);
  EXPECT_EQ(d.profileNo, 402u);
  ASSERT_EQ(d.dcOpModes.size(), 2u);
  EXPECT_EQ(d.dcOpModes[0].description, "Free Run");
  EXPECT_EQ(d.dcOpModes[0].assignActivate, 0x0000);
  EXPECT_EQ(d.dcOpModes[1].description, "DC-Synchron");
  EXPECT_EQ(d.dcOpModes[1].assignActivate, 0x0300);
  EXPECT_EQ(d.dcOpModes[1].cycleTimeSync0, 1000000u);
  expectObjects(d, kDriveObjects);
  expectEntries(d, kDriveEntries);
  const EsiObject* deviceType = d.dictionary.findObject(0x1000);
  ASSERT_NE(deviceType, nullptr);
  EXPECT_EQ(parseEsiInteger(deviceType->info.defaultValue.value_or("")).valueOr(0), 0x00020192)
      << "CiA 402, servo drive";
  const EsiObject* modes = d.dictionary.findObject(0x6502);
  ASSERT_NE(modes, nullptr);
  // pp (bit 0), pv (2), hm (5), csp (7), csv (8), cst (9)
  EXPECT_EQ(parseEsiInteger(modes->info.defaultValue.value_or("")).valueOr(0), 0x3A5);

  const EsiPdo* rx = findPdo(d, 0x1600);
  ASSERT_NE(rx, nullptr);
  EXPECT_EQ(rx->sm, 2);
  EXPECT_EQ(rx->bitLength(), 13u * 8);
  std::vector<std::uint16_t> rxObjects;
  for (const auto& e : rx->entries) rxObjects.push_back(e.index);
  EXPECT_EQ(rxObjects, (std::vector<std::uint16_t>{0x6040, 0x607A, 0x60FF, 0x6071, 0x6060}));
  const EsiPdo* tx = findPdo(d, 0x1A00);
  ASSERT_NE(tx, nullptr);
  EXPECT_EQ(tx->sm, 3);
  EXPECT_EQ(tx->bitLength(), 15u * 8);
  std::vector<std::uint16_t> txObjects;
  for (const auto& e : tx->entries) txObjects.push_back(e.index);
  EXPECT_EQ(txObjects,
            (std::vector<std::uint16_t>{0x6041, 0x6064, 0x606C, 0x6077, 0x6061, 0x603F}));
  for (std::uint16_t alternative : {std::uint16_t{0x1601}, std::uint16_t{0x1A01}}) {
    const EsiPdo* p = findPdo(d, alternative);
    ASSERT_NE(p, nullptr) << std::hex << alternative;
    EXPECT_FALSE(p->sm.has_value()) << "CSV-only PDOs are alternatives, not assigned";
    const std::uint16_t standard = alternative == 0x1601 ? 0x1600 : 0x1A00;
    EXPECT_NE(std::find(p->excludes.begin(), p->excludes.end(), standard), p->excludes.end());
  }
}

TEST_F(ExamplesEsi, ServoDriveIsCia402WithDc) {
  ECSIM_DEVICE(d, 0x7201);
  expectDriveBasics(*d);
  EXPECT_EQ(d->rxPdos.size(), 2u);
  EXPECT_EQ(d->txPdos.size(), 2u);
  EXPECT_EQ(d->syncManagers[2].defaultSize, 13);
  EXPECT_EQ(d->syncManagers[3].defaultSize, 15);
  EXPECT_EQ(findPdo(*d, 0x1601)->bitLength(), 6u * 8);
  EXPECT_EQ(findPdo(*d, 0x1A01)->bitLength(), 10u * 8);
}

TEST_F(ExamplesEsi, RobotDriveAddsIoAbsolutePositionAndPdoChoices) {
  ECSIM_DEVICE(d, 0x7211);
  expectDriveBasics(*d);
  // Bytes per PDO, in index order (examples/README.md has the layouts).
  const std::map<std::uint16_t, std::uint32_t> bytes = {
      {0x1600, 13}, {0x1601, 6},  {0x1602, 6}, {0x1603, 4}, {0x1604, 4}, {0x1605, 12},
      {0x1A00, 15}, {0x1A01, 10}, {0x1A02, 6}, {0x1A03, 8}, {0x1A04, 4}, {0x1A05, 8}};
  EXPECT_EQ(d->rxPdos.size() + d->txPdos.size(), bytes.size());
  for (const auto& [index, size] : bytes) {
    const EsiPdo* p = findPdo(*d, index);
    ASSERT_NE(p, nullptr) << std::hex << index;
    EXPECT_EQ(p->bitLength(), size * 8) << std::hex << index;
  }
  std::vector<std::uint16_t> defaults;
  for (const auto* list : {&d->rxPdos, &d->txPdos}) {
    for (const EsiPdo* p : assigned(*list)) defaults.push_back(p->index);
  }
  EXPECT_EQ(defaults, (std::vector<std::uint16_t>{0x1600, 0x1604, 0x1A00, 0x1A04}));
  EXPECT_EQ(d->syncManagers[2].defaultSize, 17);
  EXPECT_EQ(d->syncManagers[3].defaultSize, 19);
  expectObjects(*d, {{0x2010, "DINT", kRo, "T"},
                     {0x2011, "UDINT", kRo, ""},
                     {0x6000, "DT6000", kRo, ""},
                     {0x7000, "DT7000", kRw, ""}});
  expectEntries(
      *d, {{0x6000, 1, "USINT"}, {0x6000, 4, "USINT"}, {0x7000, 1, "USINT"}, {0x7000, 4, "USINT"}});
  const auto outputs = expand(d->dictionary, *d->dictionary.findObject(0x7000));
  for (std::uint8_t sub = 1; sub <= 4; ++sub) {
    const DictEntry* e = findEntry(outputs, sub);
    ASSERT_NE(e, nullptr);
    EXPECT_TRUE(e->flags.rxMappable());
    EXPECT_EQ(e->flags.access, kRw);
  }
}

// --- consistency of every CoE device ---------------------------------------------------------

TEST_F(ExamplesEsi, DictionariesAgreeWithPdosAndSyncManagers) {
  for (const EsiDevice& d : file_.devices) {
    if (!d.mailbox.coe) continue;
    SCOPED_TRACE(d.type);
    const EsiDictionary& dict = d.dictionary;
    auto entriesOf = [&](std::uint16_t index) {
      const EsiObject* o = dict.findObject(index);
      EXPECT_NE(o, nullptr) << std::hex << index;
      return o != nullptr ? expand(dict, *o) : std::vector<DictEntry>{};
    };
    // Every mapped entry exists with the PDO's type and size, mappable in its direction.
    for (bool rx : {true, false}) {
      for (const EsiPdo& p : rx ? d.rxPdos : d.txPdos) {
        SCOPED_TRACE(p.name());
        const auto mapping = entriesOf(p.index);
        EXPECT_EQ(defaultOf(findEntry(mapping, 0)), static_cast<std::int64_t>(p.entries.size()));
        for (std::size_t k = 0; k < p.entries.size(); ++k) {
          const EsiPdoEntry& pe = p.entries[k];
          const auto entries = entriesOf(pe.index);
          const DictEntry* e = findEntry(entries, pe.subIndex);
          ASSERT_NE(e, nullptr) << std::hex << pe.index << ":" << int{pe.subIndex};
          EXPECT_EQ(e->type, pe.dataType) << pe.name;
          EXPECT_EQ(e->bits, pe.bitLength) << pe.name;
          EXPECT_TRUE(rx ? e->flags.rxMappable() : e->flags.txMappable()) << pe.name;
          EXPECT_EQ(e->flags.access, rx ? kRw : kRo) << pe.name;
          const std::int64_t value =
              (std::int64_t{pe.index} << 16) | (pe.subIndex << 8) | pe.bitLength;
          EXPECT_EQ(defaultOf(findEntry(mapping, static_cast<std::uint8_t>(k + 1))), value)
              << "mapping object " << std::hex << p.index;
        }
        for (std::uint16_t x : p.excludes) {
          const EsiPdo* other = findPdo(d, x);
          ASSERT_NE(other, nullptr) << std::hex << x;
          EXPECT_NE(std::find(other->excludes.begin(), other->excludes.end(), p.index),
                    other->excludes.end())
              << "excludes are mutual: " << std::hex << x << " / " << p.index;
        }
      }
    }
    // Assign objects hold the PDOs with an Sm attribute; SM sizes are their sizes.
    for (bool rx : {true, false}) {
      const auto defaults = assigned(rx ? d.rxPdos : d.txPdos);
      const auto assign = entriesOf(rx ? 0x1C12 : 0x1C13);
      EXPECT_EQ(defaultOf(findEntry(assign, 0)), static_cast<std::int64_t>(defaults.size()));
      for (std::size_t k = 0; k < defaults.size(); ++k) {
        EXPECT_EQ(defaultOf(findEntry(assign, static_cast<std::uint8_t>(k + 1))),
                  defaults[k]->index);
      }
      const EsiSyncManager& sm = d.syncManagers.at(rx ? 2 : 3);
      EXPECT_EQ(sm.defaultSize, bitsOf(defaults) / 8);
      for (const EsiPdo* p : defaults) EXPECT_EQ(p->sm, rx ? 2 : 3);
    }
    const auto types = entriesOf(0x1C00);
    for (std::uint8_t sub = 0; sub <= 4; ++sub) {
      EXPECT_EQ(defaultOf(findEntry(types, sub)), sub == 0 ? 4 : sub) << "0x1C00:" << int{sub};
    }
    const auto identity = entriesOf(0x1018);
    EXPECT_EQ(defaultOf(findEntry(identity, 1)), kVendorId);
    EXPECT_EQ(defaultOf(findEntry(identity, 2)), d.productCode);
    EXPECT_EQ(defaultOf(findEntry(identity, 3)), d.revision);
    const EsiObject* name = dict.findObject(0x1008);
    ASSERT_NE(name, nullptr);
    EXPECT_EQ(name->info.defaultString, d.type);
  }
}

TEST_F(ExamplesEsi, DataTypesAreConsistent) {
  for (const EsiDevice& d : file_.devices) {
    SCOPED_TRACE(d.type);
    const EsiDictionary& dict = d.dictionary;
    for (const EsiObject& o : dict.objects) {
      SCOPED_TRACE(o.name());
      const EsiDataType* dt = dict.findDataType(o.type);
      ASSERT_NE(dt, nullptr) << "undeclared type " << o.type;
      EXPECT_EQ(dt->bitSize, o.bitSize);
      if (o.type.rfind("STRING(", 0) == 0) {
        ASSERT_TRUE(o.info.defaultString.has_value());
        EXPECT_EQ(o.info.defaultString->size() * 8, o.bitSize);
      }
      if (!dt->isRecord()) continue;
      std::uint32_t end = 0;
      int previousSub = -1;
      for (const EsiSubItemType& s : dt->subItems) {
        const EsiDataType* sub = dict.findDataType(s.type);
        ASSERT_NE(sub, nullptr) << "undeclared type " << s.type;
        EXPECT_EQ(sub->bitSize, s.bitSize) << s.name;
        if (sub->isArray()) {
          const std::uint32_t elements = sub->arrays.front().elements;
          const EsiDataType* base = dict.findDataType(sub->baseType);
          ASSERT_NE(base, nullptr) << sub->baseType;
          EXPECT_EQ(base->bitSize * elements, sub->bitSize) << s.name;
        } else {
          EXPECT_GT(static_cast<int>(s.subIndex), previousSub) << s.name;
          previousSub = s.subIndex;
        }
        EXPECT_GE(s.bitOffset, end) << s.name << " overlaps";
        end = s.bitOffset + s.bitSize;
      }
      EXPECT_LE(end, dt->bitSize);
      EXPECT_EQ(o.subItems.size(), expand(dict, o).size()) << "one Info/SubItem per entry";
    }
  }
}

// Largest process image of one direction: the heaviest set of that direction's PDOs that
// excludes nothing within itself and fits the assign object's capacity.
std::uint32_t largestBits(const EsiDevice& d, bool rx) {
  const std::vector<EsiPdo>& pdos = rx ? d.rxPdos : d.txPdos;
  std::size_t capacity = pdos.size();
  if (const EsiObject* o = d.dictionary.findObject(rx ? 0x1C12 : 0x1C13); o != nullptr) {
    capacity = expand(d.dictionary, *o).size() - 1;
  }
  std::uint32_t best = 0;
  for (std::uint32_t set = 0; set < (1u << pdos.size()); ++set) {
    std::vector<const EsiPdo*> chosen;
    for (std::size_t i = 0; i < pdos.size(); ++i) {
      if ((set >> i) & 1u) chosen.push_back(&pdos[i]);
    }
    bool valid = chosen.size() <= capacity;
    for (const EsiPdo* a : chosen) {
      for (const EsiPdo* b : chosen) {
        valid = valid &&
                std::find(a->excludes.begin(), a->excludes.end(), b->index) == a->excludes.end();
      }
    }
    if (valid) best = std::max(best, bitsOf(chosen));
  }
  return best;
}

TEST_F(ExamplesEsi, SyncManagerAreasDoNotOverlapForAnyPdoChoice) {
  for (const EsiDevice& d : file_.devices) {
    SCOPED_TRACE(d.type);
    std::vector<std::pair<std::uint32_t, std::uint32_t>> areas;  // [start, end)
    for (const EsiSyncManager& sm : d.syncManagers) {
      std::uint32_t bytes = sm.defaultSize;
      if (sm.text == "Outputs" || sm.text == "Inputs") {
        bytes = 3 * std::max<std::uint32_t>(bytes, (largestBits(d, sm.text == "Outputs") + 7) / 8);
      }
      EXPECT_GE(sm.startAddress, kProcessRamStart);
      areas.emplace_back(sm.startAddress, sm.startAddress + bytes);
    }
    std::sort(areas.begin(), areas.end());
    for (std::size_t i = 0; i < areas.size(); ++i) {
      EXPECT_LE(areas[i].second, kProcessRamEnd);
      if (i + 1 < areas.size()) {
        EXPECT_LE(areas[i].second, areas[i + 1].first) << "SM at " << std::hex << areas[i].first;
      }
    }
  }
}

// --- SII images ------------------------------------------------------------------------------

TEST_F(ExamplesEsi, SiiImagesReparseWithTheSameDevice) {
  const std::map<std::uint32_t, std::uint16_t> pdiControl = {
      {0x1100, 0x0100}, {0x1122, 0x0100}, {0x1008, 0x0104}, {0x2008, 0x0104},
      {0x3102, 0x0005}, {0x7201, 0x0C05}, {0x7211, 0x0C05}};
  for (const EsiDevice& d : file_.devices) {
    SCOPED_TRACE(d.type);
    auto bytes = buildSiiImage(d, file_.vendor.id);
    ASSERT_TRUE(bytes.ok()) << bytes.error().message();
    EXPECT_EQ(bytes->size(), 2048u) << "ByteSize, and within the 4 KB SOEM reads";
    auto image = SiiImage::parse(*bytes);
    ASSERT_TRUE(image.ok()) << image.error().message();
    EXPECT_TRUE(image->checksumOk());
    const SiiContents& c = image->contents();
    EXPECT_EQ(c.identity, (SiiIdentity{kVendorId, d.productCode, kRevision, 0}));
    EXPECT_EQ(c.string(1), d.name());
    EXPECT_EQ(c.config.pdiControl, pdiControl.at(d.productCode));
    ASSERT_TRUE(c.general.has_value());
    for (std::size_t port = 0; port < 4; ++port) {
      EXPECT_EQ(c.general->port(port),
                port < d.physics.size() ? SiiPortPhysics::kMii : SiiPortPhysics::kNotUsed);
    }
    const bool coe = d.mailbox.coe;
    EXPECT_EQ(c.mailboxProtocols, coe ? SiiMailboxProtocol::kCoe : 0);
    EXPECT_EQ(c.general->coeDetails, coe ? 0x0F : 0) << "SDO, info, PDO assign and config";
    EXPECT_EQ(c.standardMailbox, coe ? (SiiMailbox{0x1000, 128, 0x1080, 128}) : SiiMailbox{});
    ASSERT_EQ(c.syncManagers.size(), d.syncManagers.size());
    for (std::size_t i = 0; i < d.syncManagers.size(); ++i) {
      const EsiSyncManager& sm = d.syncManagers[i];
      EXPECT_EQ(c.syncManagers[i].startAddress, sm.startAddress);
      EXPECT_EQ(c.syncManagers[i].length, sm.defaultSize);
      EXPECT_EQ(c.syncManagers[i].control, sm.controlByte);
      EXPECT_EQ(c.syncManagers[i].enable, SiiSyncManagerEnable::kEnable);
      const SiiSyncManagerType type = sm.text == "MBoxOut"   ? SiiSyncManagerType::kMailboxOut
                                      : sm.text == "MBoxIn"  ? SiiSyncManagerType::kMailboxIn
                                      : sm.text == "Outputs" ? SiiSyncManagerType::kOutputs
                                                             : SiiSyncManagerType::kInputs;
      EXPECT_EQ(c.syncManagers[i].type, type) << "SM" << i;
    }
    EXPECT_EQ(c.fmmus.size(), (d.fmmus.size() + 1) / 2 * 2);
    for (std::size_t i = 0; i < d.fmmus.size(); ++i) {
      const std::string& f = d.fmmus[i].text;
      EXPECT_EQ(c.fmmus[i], f == "Outputs"  ? SiiFmmuUsage::kOutputs
                            : f == "Inputs" ? SiiFmmuUsage::kInputs
                                            : SiiFmmuUsage::kSyncManagerStatus);
    }
    for (bool rx : {true, false}) {
      const auto expected = assigned(rx ? d.rxPdos : d.txPdos);
      const std::vector<SiiPdo>& got = rx ? c.rxPdos : c.txPdos;
      ASSERT_EQ(got.size(), expected.size());
      for (std::size_t i = 0; i < got.size(); ++i) {
        EXPECT_EQ(got[i].index, expected[i]->index);
        EXPECT_EQ(got[i].syncManager, *expected[i]->sm);
        EXPECT_EQ(got[i].bitLength(), expected[i]->bitLength());
        for (const SiiPdoEntry& e : got[i].entries) EXPECT_NE(e.dataType, 0) << "known type";
      }
    }
    ASSERT_EQ(c.dcOpModes.size(), d.dcOpModes.size());
    for (std::size_t i = 0; i < d.dcOpModes.size(); ++i) {
      EXPECT_EQ(c.dcOpModes[i].assignActivate, d.dcOpModes[i].assignActivate);
      EXPECT_EQ(c.dcOpModes[i].cycleTime0, d.dcOpModes[i].cycleTimeSync0);
    }
  }
}

}  // namespace
}  // namespace ecsim
