// SII images built from ESI devices: round trip through the SII reader for every device of
// every real file, and comparison with the real images of the ESI/SII pairs.
#include "config/sii_builder.hpp"

#include <gtest/gtest.h>

#include <cctype>
#include <string>

#include "config/esi.hpp"
#include "tests/config/shared_data.hpp"

namespace ecsim {
namespace {

TEST(CoeDataTypeCode, KnownNames) {
  EXPECT_EQ(coeDataTypeCode("BOOL"), 0x01);
  EXPECT_EQ(coeDataTypeCode("SINT"), 0x02);
  EXPECT_EQ(coeDataTypeCode("UINT"), 0x06);
  EXPECT_EQ(coeDataTypeCode("UDINT"), 0x07);
  EXPECT_EQ(coeDataTypeCode("DINT"), 0x04);
  EXPECT_EQ(coeDataTypeCode(" uint "), 0x06);
  EXPECT_EQ(coeDataTypeCode("STRING(10)"), 0x09);
  EXPECT_EQ(coeDataTypeCode("BIT2"), 0x31);
  EXPECT_EQ(coeDataTypeCode("BIT7"), 0x36);
  EXPECT_EQ(coeDataTypeCode("UINT16"), 0x06);  // Orbita2d.xml spelling
  EXPECT_EQ(coeDataTypeCode("DT1018"), 0x00);
}

const char* const kSmallDevice = R"(<EtherCATInfo><Vendor><Id>#x1337</Id></Vendor>
<Descriptions><Devices><Device Physics="YK">
  <Type ProductCode="#x42" RevisionNo="#x2">IO-8</Type>
  <Name LcId="1033">Eight inputs</Name><GroupType>DigIn</GroupType>
  <Fmmu>Inputs</Fmmu>
  <Sm StartAddress="#x1000" ControlByte="#x20" Enable="1">Inputs</Sm>
  <TxPdo Fixed="1" Mandatory="1" Sm="0"><Index>#x1A00</Index><Name>Inputs</Name>
    <Entry><Index>#x6000</Index><SubIndex>1</SubIndex><BitLen>8</BitLen><Name>In</Name>
      <DataType>USINT</DataType></Entry></TxPdo>
  <TxPdo><Index>#x1A01</Index><Name>Alternative</Name></TxPdo>
</Device></Devices></Descriptions></EtherCATInfo>)";

TEST(SiiBuilder, SmallDeviceWithoutEepromElementGetsDefaults) {
  auto file = parseEsi(kSmallDevice, "small.xml");
  ASSERT_TRUE(file.ok()) << file.error().message();
  auto contents = makeSiiContents(file->devices[0], file->vendor.id);
  ASSERT_TRUE(contents.ok()) << contents.error().message();
  const SiiContents& c = *contents;
  EXPECT_EQ(c.identity, (SiiIdentity{0x1337, 0x42, 0x2, 0}));
  EXPECT_EQ(c.config.pdiControl, 0x0104);  // no mailbox, no DC: digital I/O, device emulation
  EXPECT_EQ(c.sizeField, 1);               // 2 Kbit default
  EXPECT_EQ(c.mailboxProtocols, 0);
  EXPECT_EQ(c.standardMailbox, SiiMailbox{});
  EXPECT_EQ(c.string(1), "Eight inputs");
  ASSERT_TRUE(c.general.has_value());
  EXPECT_EQ(c.string(c.general->groupIndex), "DigIn");
  EXPECT_EQ(c.string(c.general->orderIndex), "IO-8");
  EXPECT_EQ(c.general->port(0), SiiPortPhysics::kMii);
  EXPECT_EQ(c.general->port(1), SiiPortPhysics::kEbus);
  EXPECT_EQ(c.general->port(2), SiiPortPhysics::kNotUsed);
  ASSERT_EQ(c.syncManagers.size(), 1u);
  EXPECT_EQ(c.syncManagers[0].type, SiiSyncManagerType::kInputs);
  ASSERT_EQ(c.txPdos.size(), 1u);  // 0x1A01 has no Sm: not assigned by default
  EXPECT_EQ(c.txPdos[0].index, 0x1A00);
  EXPECT_EQ(c.txPdos[0].flags, 0x0011);  // mandatory + fixed, as Orbita2d.bin has them
  EXPECT_EQ(c.txPdos[0].entries.at(0).dataType, 0x05);
  EXPECT_EQ(c.string(c.txPdos[0].entries[0].nameIndex), "In");
  EXPECT_EQ(c.fmmus, (std::vector<SiiFmmuUsage>{SiiFmmuUsage::kInputs, SiiFmmuUsage::kNotUsed}));

  SiiBuildOptions typeFirst;
  typeFirst.deviceNameFirst = false;
  typeFirst.serial = 7;
  auto other = makeSiiContents(file->devices[0], file->vendor.id, typeFirst);
  ASSERT_TRUE(other.ok());
  EXPECT_EQ(other->string(1), "IO-8");
  EXPECT_EQ(other->string(other->general->nameIndex), "Eight inputs");
  EXPECT_EQ(other->identity.serial, 7u);
}

TEST(SiiBuilder, ImageGrowsPastAByteSizeItCannotHold) {
  // Beckhoff_EtherCAT_Terminals.xml says ByteSize 128 (1 Kbit): only the header fits.
  const char* text = R"(<EtherCATInfo><Descriptions><Devices><Device>
    <Type ProductCode="#x1" RevisionNo="#x1">X</Type><Name>A device</Name>
    <Eeprom><ByteSize>128</ByteSize><ConfigData>0001</ConfigData></Eeprom>
    </Device></Devices></Descriptions></EtherCATInfo>)";
  auto file = parseEsi(text, "tiny.xml");
  ASSERT_TRUE(file.ok());
  auto bytes = buildSiiImage(file->devices[0], 2);
  ASSERT_TRUE(bytes.ok()) << bytes.error().message();
  EXPECT_EQ(bytes->size(), 256u);
  auto image = SiiImage::parse(*bytes);
  ASSERT_TRUE(image.ok());
  EXPECT_EQ(image->contents().config.pdiControl, 0x0100);  // ConfigData "0001": word 0 only
  EXPECT_EQ(image->contents().sizeField, 1);
}

// --- every device of every real file --------------------------------------------------------

class EsiFileToSii : public ::testing::TestWithParam<const char*> {};

TEST_P(EsiFileToSii, EveryDeviceRoundTripsWithItsIdentity) {
  ECSIM_REQUIRE_SHARED_FILE(path, "esi", GetParam());
  auto file = loadEsiFile(path);
  ASSERT_TRUE(file.ok()) << file.error().message();
  for (const EsiDevice& d : file->devices) {
    SCOPED_TRACE(d.type + " rev " + std::to_string(d.revision) + " line " + std::to_string(d.line));
    auto bytes = buildSiiImage(d, file->vendor.id);
    ASSERT_TRUE(bytes.ok()) << bytes.error().message();
    auto image = SiiImage::parse(*bytes);
    ASSERT_TRUE(image.ok()) << image.error().message();
    const SiiContents& c = image->contents();
    EXPECT_TRUE(image->checksumOk());
    EXPECT_EQ(c.identity, (SiiIdentity{file->vendor.id, d.productCode, d.revision, 0}));
    EXPECT_EQ(bytes->size(), c.eepromBytes());
    if (d.eeprom && d.eeprom->byteSize) {
      EXPECT_GE(bytes->size(), *d.eeprom->byteSize);
    }
    auto expected = makeSiiContents(d, file->vendor.id);
    ASSERT_TRUE(expected.ok());
    EXPECT_EQ(c, *expected);  // nothing lost between SiiContents and bytes
    EXPECT_EQ(c.string(1), d.name().substr(0, 255));
    ASSERT_EQ(c.syncManagers.size(), d.syncManagers.size());
    for (std::size_t i = 0; i < d.syncManagers.size(); ++i) {
      EXPECT_EQ(c.syncManagers[i].startAddress, d.syncManagers[i].startAddress);
      EXPECT_EQ(c.syncManagers[i].length, d.syncManagers[i].defaultSize);
      EXPECT_EQ(c.syncManagers[i].control, d.syncManagers[i].controlByte);
    }
    std::size_t assigned = 0;
    for (const auto* pdos : {&d.rxPdos, &d.txPdos}) {
      // PDOs the dictionary cannot hold (EL1262's TxPdo 0x1C00) are left out of both.
      for (const auto& p : *pdos) assigned += p.sm.has_value() && p.inCoeRange() ? 1 : 0;
    }
    EXPECT_EQ(c.rxPdos.size() + c.txPdos.size(), assigned);
    EXPECT_EQ(c.dcOpModes.size(), d.dcOpModes.size());
    EXPECT_EQ(c.mailboxProtocols, d.mailbox.protocolMask());
  }
}

INSTANTIATE_TEST_SUITE_P(Files, EsiFileToSii,
                         ::testing::Values("Beckhoff_AX2xxx.xml", "Beckhoff_EJ5xxx.xml",
                                           "Beckhoff_EK11xx.xml", "Beckhoff_EL1xxx_2011.xml",
                                           "Beckhoff_EL47xx.xml", "Beckhoff_EL7xxx_2011.xml",
                                           "Beckhoff_EM2xxx.xml", "Beckhoff_EtherCAT_EvaBoard.xml",
                                           "Beckhoff_EtherCAT_Terminals.xml", "NI9144.xml",
                                           "Orbita2d.xml", "SMC_EX250-SEN1-X156.xml",
                                           "SOES_lan9252demo_slave.xml", "STMBL_ECAT.xml",
                                           "Weidmueller_UR20_FBC.xml", "ingenia_esi.xml"),
                         [](const auto& param_info) {
                           std::string name = param_info.param;
                           for (auto& ch : name) {
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           }
                           return name;
                         });

// --- ESI/SII pairs (MANIFESTs of /work/shared/esi and /work/shared/eeprom) ------------------

struct Pair {
  const char* esi;
  std::uint32_t revision;  // selects the device in the ESI
  const char* sii;
  SiiBuildOptions options;
  // Fields that legitimately differ, see below.
  std::optional<std::uint32_t> realVendorId;
  bool realSmTypesUnused;
};

void PrintTo(const Pair& p, std::ostream* os) {
  *os << p.sii;
}

SiiBuildOptions withSerial(std::uint32_t serial) {
  SiiBuildOptions o;
  o.serial = serial;
  return o;
}

SiiBuildOptions withoutPdoCategories() {
  SiiBuildOptions o;
  o.pdoCategories = false;
  return o;
}

// Known differences between our image and the real one:
//  - STMBL_ECAT_eeprom.bin carries serial 1; the ESI has no serial (we pass it as an option).
//  - Orbita2d.bin has vendor id 0 where the ESI says 0xF3F (the flashing tool's bug); and its
//    SM2/SM3 type bytes are 0 because siitool did not recognise the vendor's own SM names
//    "OrbitaIn"/"OrbitaOut" — we derive 3 (outputs) / 4 (inputs) from the control bytes.
//  - SOES_lan9252demo_slave.bin has no PDO categories; with them our image needs 4 Kbit, so
//    this pair is built without them to also match the 2 Kbit size word.
const std::vector<Pair> kPairs = {
    {"SOES_lan9252demo_slave.xml",
     0,
     "SOES_lan9252demo_slave.bin",
     withoutPdoCategories(),
     {},
     false},
    {"STMBL_ECAT.xml", 1, "STMBL_ECAT_eeprom.bin", withSerial(1), {}, false},
    {"NI9144.xml", 1, "ni_9144_rev_1.bin", {}, {}, false},
    {"NI9144.xml", 2, "ni_9144_rev_2.bin", {}, {}, false},
    {"Orbita2d.xml", 1, "Orbita2d.bin", {}, 0u, true},
};

class EsiSiiPair : public ::testing::TestWithParam<Pair> {};

TEST_P(EsiSiiPair, GeneratedImageMatchesRealImage) {
  const Pair& pair = GetParam();
  ECSIM_REQUIRE_SHARED_FILE(esiPath, "esi", pair.esi);
  ECSIM_REQUIRE_SHARED_FILE(siiPath, "eeprom", pair.sii);
  auto file = loadEsiFile(esiPath);
  ASSERT_TRUE(file.ok()) << file.error().message();
  const EsiDevice* device = nullptr;
  for (const auto& d : file->devices) {
    if (d.revision == pair.revision) device = &d;
  }
  ASSERT_NE(device, nullptr);
  auto built = buildSiiImage(*device, file->vendor.id, pair.options);
  ASSERT_TRUE(built.ok()) << built.error().message();
  auto ours = SiiImage::parse(*built);
  auto real = SiiImage::parse(testdata::readBytes(siiPath));
  ASSERT_TRUE(ours.ok() && real.ok());
  const SiiContents& a = ours->contents();
  const SiiContents& b = real->contents();

  SiiIdentity expectedIdentity = a.identity;
  if (pair.realVendorId) {
    EXPECT_EQ(b.identity.vendorId, *pair.realVendorId);
    EXPECT_NE(a.identity.vendorId, b.identity.vendorId);
    expectedIdentity.vendorId = *pair.realVendorId;
  }
  EXPECT_EQ(expectedIdentity, b.identity);
  EXPECT_EQ(a.config, b.config);  // from Eeprom/ConfigData
  EXPECT_EQ(a.bootstrapMailbox, b.bootstrapMailbox);
  EXPECT_EQ(a.standardMailbox, b.standardMailbox);
  EXPECT_EQ(a.mailboxProtocols, b.mailboxProtocols);
  EXPECT_EQ(a.sizeField, b.sizeField);
  EXPECT_EQ(a.version, b.version);
  // The first 0x40 words agree byte for byte once the known differences are applied.
  if (!pair.realVendorId) {
    EXPECT_TRUE(
        std::equal(built->begin(), built->begin() + sii::kHeaderBytes, real->bytes().begin()));
  }
  ASSERT_EQ(a.syncManagers.size(), b.syncManagers.size());
  for (std::size_t i = 0; i < a.syncManagers.size(); ++i) {
    SCOPED_TRACE("SM" + std::to_string(i));
    SiiSyncManager expected = a.syncManagers[i];
    if (pair.realSmTypesUnused && i >= 2) {
      EXPECT_EQ(b.syncManagers[i].type, SiiSyncManagerType::kUnused);
      expected.type = SiiSyncManagerType::kUnused;
    }
    EXPECT_EQ(expected, b.syncManagers[i]);
  }
  // Where both images have PDO and DC categories, the PDO indexes and entries and the DC
  // AssignActivate agree too (Orbita2d.bin's DC categories lost their AssignActivate).
  if (pair.options.pdoCategories && !b.txPdos.empty()) {
    ASSERT_EQ(a.txPdos.size(), b.txPdos.size());
    for (std::size_t i = 0; i < a.txPdos.size(); ++i) {
      EXPECT_EQ(a.txPdos[i].index, b.txPdos[i].index);
      EXPECT_EQ(a.txPdos[i].syncManager, b.txPdos[i].syncManager);
      ASSERT_EQ(a.txPdos[i].entries.size(), b.txPdos[i].entries.size());
      for (std::size_t e = 0; e < a.txPdos[i].entries.size(); ++e) {
        EXPECT_EQ(a.txPdos[i].entries[e].index, b.txPdos[i].entries[e].index);
        EXPECT_EQ(a.txPdos[i].entries[e].subIndex, b.txPdos[i].entries[e].subIndex);
        EXPECT_EQ(a.txPdos[i].entries[e].bitLength, b.txPdos[i].entries[e].bitLength);
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Pairs, EsiSiiPair, ::testing::ValuesIn(kPairs),
                         [](const auto& param_info) {
                           std::string name = param_info.param.sii;
                           for (auto& ch : name) {
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           }
                           return name;
                         });

TEST(EsiSiiPairs, NiDcOpModesMatchTheDump) {
  ECSIM_REQUIRE_SHARED_FILE(esiPath, "esi", "NI9144.xml");
  ECSIM_REQUIRE_SHARED_FILE(siiPath, "eeprom", "ni_9144_rev_1.bin");
  auto file = loadEsiFile(esiPath);
  ASSERT_TRUE(file.ok());
  auto ours = makeSiiContents(file->devices.at(0), file->vendor.id);
  auto real = SiiImage::parse(testdata::readBytes(siiPath));
  ASSERT_TRUE(ours.ok() && real.ok());
  ASSERT_EQ(ours->dcOpModes.size(), real->contents().dcOpModes.size());
  for (std::size_t i = 0; i < ours->dcOpModes.size(); ++i) {
    EXPECT_EQ(ours->dcOpModes[i].assignActivate, real->contents().dcOpModes[i].assignActivate);
    EXPECT_EQ(ours->string(ours->dcOpModes[i].nameIndex),
              real->string(real->contents().dcOpModes[i].nameIndex));
  }
  EXPECT_EQ(ours->general->coeDetails, real->contents().general->coeDetails);
  EXPECT_EQ(ours->general->physicalPorts, real->contents().general->physicalPorts);
}

}  // namespace
}  // namespace ecsim
