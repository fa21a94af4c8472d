// Every real ESI file in /work/shared/esi, checked against what its MANIFEST.md says.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <optional>
#include <ostream>
#include <set>
#include <string>

#include "config/esi.hpp"
#include "tests/config/shared_data.hpp"

namespace ecsim {
namespace {

namespace fs = std::filesystem;

struct CorpusFile {
  const char* file;
  EsiRoot root;
  std::uint32_t vendorId;
  std::size_t devices;                 // <Device> elements
  std::size_t devicesWithProductCode;  // real revisions (MANIFEST counts these)
  std::size_t modules;
  std::size_t objects;  // CoE objects over devices, modules and the root
  EsiEncoding encoding;
};

void PrintTo(const CorpusFile& f, std::ostream* os) {
  *os << f.file;
}

constexpr auto kInfo = EsiRoot::kEtherCatInfo;
constexpr auto kUtf8 = EsiEncoding::kUtf8;
constexpr auto kLatin1 = EsiEncoding::kLatin1;

// Counts from /work/shared/esi/MANIFEST.md where it gives them (revisions, objects, modules);
// the others were counted in the files (grep -c '<Device').
const std::vector<CorpusFile> kCorpus = {
    {"Beckhoff_AX2xxx.xml", kInfo, 2, 1, 1, 0, 356, kUtf8},
    {"Beckhoff_AX5021-xxxx-0001_Dict.xml", EsiRoot::kEtherCatDict, 0, 0, 0, 0, 119, kUtf8},
    {"Beckhoff_EJ5xxx.xml", kInfo, 2, 3, 3, 0, 92, kLatin1},
    {"Beckhoff_EK11xx.xml", kInfo, 2, 24, 24, 0, 0, kUtf8},
    {"Beckhoff_EL1xxx_2011.xml", kInfo, 2, 44, 44, 0, 0, kUtf8},
    {"Beckhoff_EL47xx.xml", kInfo, 2, 6, 6, 0, 0, kUtf8},
    {"Beckhoff_EL7xxx_2011.xml", kInfo, 2, 12, 12, 0, 624, kLatin1},
    {"Beckhoff_EM2xxx.xml", kInfo, 2, 1, 1, 0, 0, kUtf8},
    {"Beckhoff_EtherCAT_EvaBoard.xml", kInfo, 2, 19, 19, 0, 0, kUtf8},
    // 40 <Device>, of which 4 placeholders without ProductCode (EK0000, EK1200, EK1210,
    // EL0000): "36 revisions of 30 devices".
    {"Beckhoff_EtherCAT_Terminals.xml", kInfo, 2, 40, 36, 0, 0, kUtf8},
    {"NI9144.xml", kInfo, 505, 4, 4, 0, 0, kUtf8},
    {"Orbita2d.xml", kInfo, 0xF3F, 1, 1, 0, 0, kUtf8},
    {"SMC_EX250-SEN1-X156.xml", kInfo, 276, 1, 1, 0, 0, kUtf8},
    {"SOES_lan9252demo_slave.xml", kInfo, 0x1337, 1, 1, 0, 13, kUtf8},
    {"STMBL_ECAT.xml", kInfo, 4919, 1, 1, 0, 23, kUtf8},
    {"Weidmueller_UR20_FBC.xml", kInfo, 0x230, 2, 2, 2, 69, kUtf8},
    {"Weidmueller_UR20_IO.xml", EsiRoot::kEtherCatModule, 560, 0, 0, 82, 470, kUtf8},
    {"ingenia_esi.xml", kInfo, 0x29C, 1, 1, 0, 582, kUtf8},
};
constexpr const char* kBrokenFile = "DS402_PDOs_EasyCatProject.xml";

class EsiCorpus : public ::testing::TestWithParam<CorpusFile> {};

TEST_P(EsiCorpus, ParsesWithManifestCounts) {
  const CorpusFile& expected = GetParam();
  ECSIM_REQUIRE_SHARED_FILE(path, "esi", expected.file);
  // How long parsing takes is measured by a benchmark, not judged here: under ASan on a busy
  // machine the largest files took 1.5 s, which says nothing about the parser.
  auto file = loadEsiFile(path);
  ASSERT_TRUE(file.ok()) << file.error().message();
  EXPECT_EQ(file->root, expected.root);
  EXPECT_EQ(file->vendor.id, expected.vendorId);
  EXPECT_EQ(file->encoding, expected.encoding);
  EXPECT_EQ(file->devices.size(), expected.devices);
  EXPECT_EQ(std::count_if(file->devices.begin(), file->devices.end(),
                          [](const EsiDevice& d) { return d.hasProductCode; }),
            static_cast<std::ptrdiff_t>(expected.devicesWithProductCode));
  std::size_t modules = file->modules.size();
  std::size_t objects = file->dictionary.objects.size();
  for (const auto& d : file->devices) {
    modules += d.modules.size();
    objects += d.dictionary.objects.size();
  }
  for (const auto& m : file->modules) objects += m.dictionary.objects.size();
  EXPECT_EQ(modules, expected.modules);
  EXPECT_EQ(objects, expected.objects);
  // Nothing in the real files is malformed or overlapping: the tolerant reader replaced nothing.
  EXPECT_TRUE(file->warnings.empty()) << file->warnings.front();
  for (const auto& d : file->devices) {
    SCOPED_TRACE(d.type + " line " + std::to_string(d.line));
    EXPECT_FALSE(d.type.empty());
    EXPECT_EQ(d.type, trimEsiText(d.type));
    // A PDO's Sm names an SM the device has.
    for (const auto* pdos : {&d.rxPdos, &d.txPdos}) {
      for (const auto& pdo : *pdos) {
        if (pdo.sm) {
          EXPECT_LT(*pdo.sm, std::max<std::size_t>(d.syncManagers.size(), 1));
        }
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Files, EsiCorpus, ::testing::ValuesIn(kCorpus),
                         [](const auto& param_info) {
                           std::string name = param_info.param.file;
                           for (auto& ch : name) {
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           }
                           return name;
                         });

TEST(EsiCorpusFiles, EveryXmlFileInTheDirectoryIsListed) {
  ECSIM_REQUIRE_SHARED_FILE(dir, "esi", "");
  std::set<std::string> listed = {kBrokenFile};
  for (const auto& f : kCorpus) listed.insert(f.file);
  std::size_t seen = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() != ".xml") continue;
    ++seen;
    EXPECT_TRUE(listed.count(entry.path().filename().string()) == 1)
        << entry.path().filename() << " is not in the corpus table";
  }
  EXPECT_EQ(seen, listed.size());
}

TEST(EsiCorpusFiles, BrokenEasyCatFileGivesLine36) {
  ECSIM_REQUIRE_SHARED_FILE(path, "esi", kBrokenFile);
  auto file = loadEsiFile(path);
  ASSERT_FALSE(file.ok());
  EXPECT_EQ(file.error().code, ErrorCode::kParse);
  EXPECT_NE(file.error().context.find(kBrokenFile), std::string::npos) << file.error().context;
  EXPECT_NE(file.error().context.find("line 36"), std::string::npos) << file.error().context;
}

Result<EsiFile> load(const fs::path& path) {
  return loadEsiFile(path);
}

TEST(EsiCorpusDetails, ServoWithAlternativePdos) {
  ECSIM_REQUIRE_SHARED_FILE(path, "esi", "Beckhoff_AX2xxx.xml");
  auto file = load(path);
  ASSERT_TRUE(file.ok()) << file.error().message();
  const EsiDevice& d = file->devices.at(0);
  EXPECT_EQ(d.productCode, 0x07D06014u);
  EXPECT_EQ(d.revision, 0x00001B82u);
  EXPECT_EQ(d.profileNo, 402u);
  EXPECT_EQ(d.mailbox.coeDetails.ds402Channels, 1);
  EXPECT_TRUE(d.mailbox.coeDetails.pdoAssign);
  ASSERT_EQ(d.rxPdos.size(), 8u);  // 0x1701..0x1708
  ASSERT_EQ(d.txPdos.size(), 7u);  // 0x1B01, 0x1B03..0x1B08
  std::vector<std::uint16_t> assignedRx, assignedTx;
  for (const auto& p : d.rxPdos) {
    if (p.sm) assignedRx.push_back(p.index);
  }
  for (const auto& p : d.txPdos) {
    if (p.sm) assignedTx.push_back(p.index);
  }
  EXPECT_EQ(assignedRx, std::vector<std::uint16_t>{0x1702});
  EXPECT_EQ(assignedTx, std::vector<std::uint16_t>{0x1B03});
  EXPECT_EQ(d.rxPdos[0].excludes.size(), 7u);
  ASSERT_EQ(d.dcOpModes.size(), 2u);
  EXPECT_EQ(d.dcOpModes[0].assignActivate, 0x0000);
  EXPECT_EQ(d.dcOpModes[1].assignActivate, 0x0300);
  ASSERT_NE(d.dictionary.findObject(0x6040), nullptr);
  ASSERT_NE(d.dictionary.findObject(0x607A), nullptr);
}

TEST(EsiCorpusDetails, CouplerPhysicsKeepBlanks) {
  ECSIM_REQUIRE_SHARED_FILE(path, "esi", "Beckhoff_EK11xx.xml");
  auto file = load(path);
  ASSERT_TRUE(file.ok()) << file.error().message();
  std::set<std::string> physics;
  for (const auto& d : file->devices) {
    physics.insert(d.physics);
    if (d.type == "EK1100") {  // the pure coupler (EK1101 has an ID-switch TxPdo)
      EXPECT_TRUE(d.rxPdos.empty() && d.txPdos.empty() && !d.mailbox.present);
    }
  }
  for (const char* withBlank : {"K KY", "KK Y"}) EXPECT_EQ(physics.count(withBlank), 1u);
  EXPECT_EQ(physics.count("YKY"), 1u);
  EXPECT_EQ(physics.count("KYKY"), 1u);
  EXPECT_EQ(file->devices[0].type, "EK1100");
  EXPECT_EQ(file->devices[0].productCode, 0x044C2C52u);
}

TEST(EsiCorpusDetails, Latin1NamesConvertForDisplay) {
  ECSIM_REQUIRE_SHARED_FILE(path, "esi", "Beckhoff_EJ5xxx.xml");
  auto file = load(path);
  ASSERT_TRUE(file.ok()) << file.error().message();
  EXPECT_EQ(file->encoding, EsiEncoding::kLatin1);
  std::size_t micro = 0;
  for (const auto& d : file->devices) {
    for (const auto& o : d.dictionary.objects) {
      for (const auto& sub : o.subItems) {
        if (sub.name.find("[\xb5s]") != std::string::npos) {
          ++micro;
          EXPECT_NE(file->display(sub.name).find("[\xc2\xb5s]"), std::string::npos);
        }
      }
    }
  }
  EXPECT_GT(micro, 0u);  // "Min. inhibit time[µs]" kept as the Latin-1 byte 0xB5
}

TEST(EsiCorpusDetails, DecimalAndOddNumbers) {
  ECSIM_REQUIRE_SHARED_FILE(ingenia, "esi", "ingenia_esi.xml");
  auto i = load(ingenia);
  ASSERT_TRUE(i.ok()) << i.error().message();
  EXPECT_EQ(i->devices.at(0).productCode, 61935618u);
  EXPECT_EQ(i->devices.at(0).revision, 327685u);
  const EsiCoe& coe = i->devices[0].mailbox.coeDetails;
  EXPECT_TRUE(coe.sdoInfo && coe.completeAccess && coe.pdoAssign && coe.pdoConfig &&
              coe.segmentedSdo);
  EXPECT_TRUE(i->devices[0].mailbox.eoe && i->devices[0].mailbox.foe);

  ECSIM_REQUIRE_SHARED_FILE(stmbl, "esi", "STMBL_ECAT.xml");
  auto s = load(stmbl);
  ASSERT_TRUE(s.ok()) << s.error().message();
  EXPECT_EQ(s->devices.at(0).physics, "YY ");         // trailing blank kept
  EXPECT_EQ(s->devices.at(0).type, "AC servodrive");  // trailing blank trimmed
  EXPECT_EQ(s->devices.at(0).dcOpModes.at(1).assignActivate, 0x300);

  ECSIM_REQUIRE_SHARED_FILE(orbita, "esi", "Orbita2d.xml");
  auto o = load(orbita);
  ASSERT_TRUE(o.ok()) << o.error().message();
  EXPECT_EQ(o->vendor.name(), "Pollen Robotcs SAS");
  EXPECT_EQ(o->devices.at(0).rxPdos.at(0).entries.at(0).index, 0x6041);  // "#x0x6041"

  ECSIM_REQUIRE_SHARED_FILE(smc, "esi", "SMC_EX250-SEN1-X156.xml");
  auto m = load(smc);
  ASSERT_TRUE(m.ok()) << m.error().message();
  EXPECT_TRUE(m->devices.at(0).fmmus.empty());
  EXPECT_FALSE(m->devices.at(0).eeprom.has_value());
  EXPECT_EQ(m->devices.at(0).syncManagers.at(0).enable, 9);  // Enable="9"
}

// Counts the record SubItems (of DataTypes) whose flags satisfy `pick`.
std::size_t countSubItemFlags(const EsiFile& file, bool (*pick)(const EsiFlags&)) {
  std::size_t n = 0;
  for (const auto& d : file.devices) {
    for (const auto& type : d.dictionary.dataTypes) {
      for (const auto& sub : type.subItems) n += pick(sub.flags) ? 1 : 0;
    }
  }
  return n;
}

TEST(EsiCorpusDetails, AccessRestrictionsAndPdoMapping) {
  // ingenia_esi.xml: <Access WriteRestrictions="PreOP">rw</Access> on PDO mapping sub-items.
  ECSIM_REQUIRE_SHARED_FILE(ingenia, "esi", "ingenia_esi.xml");
  auto i = load(ingenia);
  ASSERT_TRUE(i.ok()) << i.error().message();
  EXPECT_GT(countSubItemFlags(*i,
                              [](const EsiFlags& f) {
                                return f.access == EsiAccess::kReadWrite &&
                                       f.writeRestrictions == "PreOP";
                              }),
            0u);
  // Beckhoff_EL7xxx_2011.xml: its 491 <PdoMapping> sit on record sub-items.
  ECSIM_REQUIRE_SHARED_FILE(path, "esi", "Beckhoff_EL7xxx_2011.xml");
  auto file = load(path);
  ASSERT_TRUE(file.ok()) << file.error().message();
  EXPECT_GT(countSubItemFlags(*file, [](const EsiFlags& f) { return f.txMappable(); }), 0u);
  EXPECT_GT(countSubItemFlags(*file, [](const EsiFlags& f) { return f.rxMappable(); }), 0u);
  const EsiDevice& el7031 = file->devices.at(0);
  EXPECT_EQ(el7031.productCode, 0x1B773052u);
  ASSERT_FALSE(el7031.dcOpModes.empty());
}

TEST(EsiCorpusDetails, ModulesAndSlots) {
  ECSIM_REQUIRE_SHARED_FILE(io, "esi", "Weidmueller_UR20_IO.xml");
  auto modules = load(io);
  ASSERT_TRUE(modules.ok()) << modules.error().message();
  const EsiModule& first = modules->modules.at(0);
  EXPECT_EQ(first.type, "UR20-4DI-P");
  EXPECT_EQ(first.moduleIdent, 0x00091F84u);
  EXPECT_EQ(first.moduleClass, "Di");
  EXPECT_FALSE(first.name().empty());  // only LcId 1031 (or none) in this file
  ASSERT_EQ(first.txPdos.size(), 1u);
  EXPECT_TRUE(first.txPdos[0].dependOnSlot);

  ECSIM_REQUIRE_SHARED_FILE(fbc, "esi", "Weidmueller_UR20_FBC.xml");
  auto coupler = load(fbc);
  ASSERT_TRUE(coupler.ok()) << coupler.error().message();
  const EsiDevice& d = coupler->devices.at(0);
  ASSERT_EQ(d.slots.size(), 1u);
  EXPECT_EQ(d.slots[0].maxInstances, 64u);
  EXPECT_EQ(d.slots[0].moduleClasses.size(), 8u);
}

TEST(EsiCorpusDetails, SoeDictionaryRoot) {
  ECSIM_REQUIRE_SHARED_FILE(path, "esi", "Beckhoff_AX5021-xxxx-0001_Dict.xml");
  auto file = load(path);
  ASSERT_TRUE(file.ok()) << file.error().message();
  const EsiObject* first = file->dictionary.findObject(1);  // S-0-0001
  ASSERT_NE(first, nullptr);
  EXPECT_EQ(first->name(), "Control unit cycle time (TNcyc)");
  EXPECT_EQ(first->info.minValue, "62");
  EXPECT_EQ(first->info.defaultValue, "500");
}

}  // namespace
}  // namespace ecsim
