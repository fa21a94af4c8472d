// ESI reader on small documents written for these tests (the real files are in
// esi_corpus_test.cpp).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "config/esi.hpp"

namespace ecsim {
namespace {

const char* const kDevice = R"(<?xml version="1.0" encoding="UTF-8"?>
<EtherCATInfo Version="1.6">
  <Vendor>
    <Id>#x00000abc</Id>
    <Name LcId="1031">Hersteller</Name>
    <Name LcId="1033">Maker &amp; Co</Name>
  </Vendor>
  <Descriptions>
    <Groups><Group><Type>Drives</Type><Name LcId="1033">Drives</Name></Group></Groups>
    <Devices>
      <Device Physics="K KY">
        <Type ProductCode="4919" RevisionNo="0x10" UseLrdLwr="1">  Servo 1 </Type>
        <Name LcId="1031"><![CDATA[Servo (DE)]]></Name>
        <Name LcId="1033"><![CDATA[Servo <one> & more]]></Name>
        <GroupType>Drives</GroupType>
        <Info><Electrical><EBusCurrent>-500</EBusCurrent></Electrical></Info>
        <Profile>
          <ProfileNo>402</ProfileNo>
          <Dictionary>
            <DataTypes>
              <DataType><Name>UDINT</Name><BitSize>32</BitSize></DataType>
              <DataType>
                <Name>DT1C12ARR</Name><BaseType>UINT</BaseType><BitSize>32</BitSize>
                <ArrayInfo><LBound>1</LBound><Elements>2</Elements></ArrayInfo>
              </DataType>
              <DataType>
                <Name>DT1018</Name><BitSize>80</BitSize>
                <SubItem><SubIdx>0</SubIdx><Name>Count</Name><Type>USINT</Type>
                  <BitSize>8</BitSize><BitOffs>0</BitOffs><Flags><Access>ro</Access></Flags>
                </SubItem>
                <SubItem><SubIdx>#x1</SubIdx><Name>Vendor ID</Name><Type>UDINT</Type>
                  <BitSize>32</BitSize><BitOffs>16</BitOffs></SubItem>
              </DataType>
            </DataTypes>
            <Objects>
              <Object>
                <Index>#x1018</Index><Name>Identity</Name><Type>DT1018</Type>
                <BitSize>80</BitSize>
                <Info>
                  <SubItem><Name>Count</Name><Info><DefaultData>01</DefaultData></Info></SubItem>
                  <SubItem><Name>Vendor ID</Name><Info><DefaultData>bc0a0000</DefaultData></Info></SubItem>
                </Info>
                <Flags><Access>ro</Access><Category>m</Category></Flags>
              </Object>
              <Object>
                <Index>#x607A</Index><Name>Target position</Name><Type>DINT</Type>
                <BitSize>32</BitSize>
                <Info><DefaultValue>#x0</DefaultValue><MinValue>-2147483648</MinValue>
                  <MaxValue>2147483647</MaxValue></Info>
                <Flags><Access WriteRestrictions="PreOP">rw</Access><PdoMapping>R</PdoMapping></Flags>
              </Object>
            </Objects>
          </Dictionary>
        </Profile>
        <Fmmu>Outputs</Fmmu>
        <Fmmu Sm="3">Inputs</Fmmu>
        <Sm DefaultSize="128" StartAddress="#x1000" ControlByte="#x26" Enable="1">MBoxOut</Sm>
        <Sm DefaultSize="128" StartAddress="#x1080" ControlByte="#x22" Enable="true">MBoxIn</Sm>
        <Sm StartAddress="#x1100" ControlByte="#x64" Enable="9" OpOnly="1">Outputs</Sm>
        <Sm StartAddress="#x1180" ControlByte="#x20" Enable="0" Virtual="1">Inputs</Sm>
        <RxPdo Fixed="1" Mandatory="true" Sm="2">
          <Index>#x1600</Index><Name>Outputs</Name>
          <Exclude>#x1601</Exclude>
          <Entry><Index>#x6040</Index><SubIndex>0</SubIndex><BitLen>16</BitLen>
            <Name>Controlword</Name><DataType>UINT</DataType></Entry>
          <Entry><Index>#x0</Index><BitLen>8</BitLen></Entry>
        </RxPdo>
        <RxPdo>
          <Index>#x1601</Index><Name>Alternative</Name><Exclude>#x1600</Exclude>
          <Entry><Index>#x607A</Index><SubIndex>0</SubIndex><BitLen>32</BitLen>
            <Name>Target position</Name><DataType>DINT</DataType></Entry>
        </RxPdo>
        <TxPdo Sm="3"><Index DependOnSlot="1">#x1A00</Index><Name>Inputs</Name></TxPdo>
        <Mailbox DataLinkLayer="true">
          <AoE/>
          <CoE SdoInfo="true" PdoAssign="1" PdoConfig="0" CompleteAccess="true"
               SegmentedSdo="true" DS402Channels="1"/>
          <FoE/>
        </Mailbox>
        <Dc>
          <OpMode><Name>DcOff</Name><Desc>Free run</Desc><AssignActivate>#x0</AssignActivate></OpMode>
          <OpMode><Name>DcSync</Name><Desc>SYNC0</Desc><AssignActivate>#x300</AssignActivate>
            <CycleTimeSync0 Factor="1">0</CycleTimeSync0><ShiftTimeSync0>2000</ShiftTimeSync0>
            <CycleTimeSync1 Factor="-1">100</CycleTimeSync1></OpMode>
        </Dc>
        <Eeprom>
          <ByteSize>2048</ByteSize>
          <ConfigData>050E03440A000000</ConfigData>
          <BootStrap>0010800080108000</BootStrap>
          <Category><CatNo>1</CatNo><Data>5C12</Data></Category>
        </Eeprom>
        <Slots><Slot MinInstances="0" MaxInstances="4"><Name>Terminals</Name>
          <ModuleClass><Class>Di</Class></ModuleClass><ModuleIdent>#x91F84</ModuleIdent></Slot></Slots>
      </Device>
    </Devices>
  </Descriptions>
</EtherCATInfo>
)";

TEST(EsiReader, ReadsAFullDevice) {
  auto file = parseEsi(kDevice, "device.xml");
  ASSERT_TRUE(file.ok()) << file.error().message();
  EXPECT_EQ(file->root, EsiRoot::kEtherCatInfo);
  EXPECT_EQ(file->version, "1.6");
  EXPECT_EQ(file->vendor.id, 0xABCu);
  EXPECT_EQ(file->vendor.name(), "Maker & Co");
  ASSERT_EQ(file->groups.size(), 1u);
  ASSERT_EQ(file->devices.size(), 1u);
  const EsiDevice& d = file->devices[0];
  EXPECT_EQ(d.type, "Servo 1");
  EXPECT_EQ(d.productCode, 4919u);
  EXPECT_EQ(d.revision, 0x10u);
  EXPECT_TRUE(d.hasProductCode);
  EXPECT_TRUE(d.useLrdLwr);
  EXPECT_EQ(d.name(), "Servo <one> & more");
  EXPECT_EQ(d.name(1031), "Servo (DE)");
  EXPECT_EQ(d.physics, "K KY");
  EXPECT_EQ(d.groupType, "Drives");
  EXPECT_EQ(d.ebusCurrent, -500);
  EXPECT_EQ(d.profileNo, 402u);
  EXPECT_EQ(d.line, 11);

  ASSERT_EQ(d.fmmus.size(), 2u);
  EXPECT_EQ(d.fmmus[1].text, "Inputs");
  EXPECT_EQ(d.fmmus[1].sm, 3);
  ASSERT_EQ(d.syncManagers.size(), 4u);
  EXPECT_EQ(d.syncManagers[0].text, "MBoxOut");
  EXPECT_EQ(d.syncManagers[0].startAddress, 0x1000);
  EXPECT_EQ(d.syncManagers[0].defaultSize, 128);
  EXPECT_EQ(d.syncManagers[0].controlByte, 0x26);
  EXPECT_EQ(d.syncManagers[1].enable, 1);
  EXPECT_EQ(d.syncManagers[2].enable, 9);
  EXPECT_TRUE(d.syncManagers[2].opOnly);
  EXPECT_EQ(d.syncManagers[2].defaultSize, 0);
  EXPECT_EQ(d.syncManagers[3].enable, 0);
  EXPECT_TRUE(d.syncManagers[3].isVirtual);

  ASSERT_EQ(d.rxPdos.size(), 2u);
  const EsiPdo& rx = d.rxPdos[0];
  EXPECT_EQ(rx.index, 0x1600);
  EXPECT_EQ(rx.sm, 2);
  EXPECT_TRUE(rx.fixed);
  EXPECT_TRUE(rx.mandatory);
  EXPECT_EQ(rx.excludes, std::vector<std::uint16_t>{0x1601});
  ASSERT_EQ(rx.entries.size(), 2u);
  EXPECT_EQ(rx.entries[0].index, 0x6040);
  EXPECT_EQ(rx.entries[0].bitLength, 16);
  EXPECT_EQ(rx.entries[0].name, "Controlword");
  EXPECT_EQ(rx.entries[0].dataType, "UINT");
  EXPECT_EQ(rx.entries[1].index, 0);  // gap
  EXPECT_EQ(rx.bitLength(), 24u);
  EXPECT_FALSE(d.rxPdos[1].sm.has_value());  // optional alternative
  EXPECT_FALSE(d.rxPdos[1].fixed);
  ASSERT_EQ(d.txPdos.size(), 1u);
  EXPECT_TRUE(d.txPdos[0].dependOnSlot);

  EXPECT_TRUE(d.mailbox.present);
  EXPECT_TRUE(d.mailbox.dataLinkLayer);
  EXPECT_TRUE(d.mailbox.aoe && d.mailbox.coe && d.mailbox.foe);
  EXPECT_FALSE(d.mailbox.eoe || d.mailbox.soe || d.mailbox.voe);
  EXPECT_EQ(d.mailbox.protocolMask(), 0x0D);
  EXPECT_TRUE(d.mailbox.coeDetails.sdoInfo);
  EXPECT_TRUE(d.mailbox.coeDetails.pdoAssign);
  EXPECT_FALSE(d.mailbox.coeDetails.pdoConfig);
  EXPECT_TRUE(d.mailbox.coeDetails.completeAccess);
  EXPECT_TRUE(d.mailbox.coeDetails.segmentedSdo);
  EXPECT_EQ(d.mailbox.coeDetails.ds402Channels, 1);

  ASSERT_EQ(d.dcOpModes.size(), 2u);
  EXPECT_EQ(d.dcOpModes[1].name, "DcSync");
  EXPECT_EQ(d.dcOpModes[1].description, "SYNC0");
  EXPECT_EQ(d.dcOpModes[1].assignActivate, 0x0300);
  EXPECT_EQ(d.dcOpModes[1].cycleTimeSync0Factor, 1);
  EXPECT_EQ(d.dcOpModes[1].shiftTimeSync0, 2000);
  EXPECT_EQ(d.dcOpModes[1].cycleTimeSync1, 100u);
  EXPECT_EQ(d.dcOpModes[1].cycleTimeSync1Factor, -1);

  ASSERT_TRUE(d.eeprom.has_value());
  EXPECT_EQ(d.eeprom->byteSize, 2048u);
  EXPECT_EQ(d.eeprom->configData.size(), 8u);
  EXPECT_EQ(d.eeprom->bootStrap.size(), 8u);
  ASSERT_EQ(d.eeprom->categories.size(), 1u);
  EXPECT_EQ(d.eeprom->categories[0].type, 1);
  EXPECT_EQ(d.eeprom->categories[0].data, (std::vector<std::uint8_t>{0x5C, 0x12}));

  ASSERT_EQ(d.slots.size(), 1u);
  EXPECT_EQ(d.slots[0].maxInstances, 4u);
  EXPECT_EQ(d.slots[0].moduleClasses, std::vector<std::string>{"Di"});
  EXPECT_EQ(d.slots[0].moduleIdents, std::vector<std::uint32_t>{0x91F84});
}

TEST(EsiReader, ReadsTheDictionary) {
  auto file = parseEsi(kDevice, "device.xml");
  ASSERT_TRUE(file.ok()) << file.error().message();
  const EsiDictionary& dict = file->devices[0].dictionary;
  ASSERT_EQ(dict.dataTypes.size(), 3u);
  const EsiDataType* array = dict.findDataType("DT1C12ARR");
  ASSERT_NE(array, nullptr);
  EXPECT_TRUE(array->isArray());
  EXPECT_EQ(array->baseType, "UINT");
  EXPECT_EQ(array->arrays[0].lowerBound, 1);
  EXPECT_EQ(array->arrays[0].elements, 2u);
  const EsiDataType* record = dict.findDataType("DT1018");
  ASSERT_NE(record, nullptr);
  ASSERT_TRUE(record->isRecord());
  EXPECT_EQ(record->subItems[1].subIndex, 1);
  EXPECT_EQ(record->subItems[1].bitOffset, 16u);
  EXPECT_EQ(record->subItems[0].flags.access, EsiAccess::kReadOnly);

  const EsiObject* identity = dict.findObject(0x1018);
  ASSERT_NE(identity, nullptr);
  EXPECT_EQ(identity->name(), "Identity");
  EXPECT_EQ(identity->flags.category, "m");
  ASSERT_EQ(identity->subItems.size(), 2u);
  EXPECT_EQ(identity->subItems[1].info.defaultData,
            (std::vector<std::uint8_t>{0xBC, 0x0A, 0x00, 0x00}));
  const EsiObject* target = dict.findObject(0x607A);
  ASSERT_NE(target, nullptr);
  EXPECT_EQ(target->flags.access, EsiAccess::kReadWrite);
  EXPECT_EQ(target->flags.writeRestrictions, "PreOP");
  EXPECT_TRUE(target->flags.rxMappable());
  EXPECT_FALSE(target->flags.txMappable());
  EXPECT_EQ(target->info.minValue, "-2147483648");
  EXPECT_EQ(target->info.defaultValue, "#x0");
  EXPECT_EQ(dict.findObject(0x6041), nullptr);
}

// --- errors name the file and the line ------------------------------------------------------

TEST(EsiReader, SyntaxErrorNamesFileAndLine) {
  const char* broken =
      "<?xml version=\"1.0\"?>\n"
      "<EtherCATInfo>\n"
      "  <Vendor>\n"
      "    <Id>1</Id>\n"
      "  </Vendr>\n"
      "</EtherCATInfo>\n";
  auto file = parseEsi(broken, "broken.xml");
  ASSERT_FALSE(file.ok());
  EXPECT_EQ(file.error().code, ErrorCode::kParse);
  // tinyxml2 reports a mismatched end tag at the line of the element it fails to close.
  EXPECT_NE(file.error().context.find("broken.xml, line 3"), std::string::npos)
      << file.error().context;
  EXPECT_NE(file.error().context.find("Vendor"), std::string::npos) << file.error().context;

  const char* cutTag = "<EtherCATInfo>\n<Vendor>\n<Id>1</Id\n</Vendor>\n</EtherCATInfo>\n";
  auto cut = parseEsi(cutTag, "cut.xml");
  ASSERT_FALSE(cut.ok());
  EXPECT_NE(cut.error().context.find("cut.xml, line 3"), std::string::npos) << cut.error().context;

  auto twoRoots = parseEsi("<EtherCATInfo/>\n\n<EtherCATInfo/>", "two.xml");
  ASSERT_FALSE(twoRoots.ok());
  EXPECT_NE(twoRoots.error().context.find("two.xml, line 3"), std::string::npos)
      << twoRoots.error().context;
}

TEST(EsiReader, RawAmpersandIsAnErrorWithItsLine) {
  // tinyxml2 lets "AB&T" through; XML does not (DS402_PDOs_EasyCatProject.xml line 36).
  const char* text = "<EtherCATInfo>\n<Vendor>\n<Name>AB&T</Name>\n</Vendor>\n</EtherCATInfo>";
  auto file = parseEsi(text, "amp.xml");
  ASSERT_FALSE(file.ok());
  EXPECT_NE(file.error().context.find("amp.xml, line 3"), std::string::npos)
      << file.error().context;
  const char* inAttribute = "<EtherCATInfo>\n\n<Vendor a=\"x&y\"/></EtherCATInfo>";
  auto attr = parseEsi(inAttribute, "attr.xml");
  ASSERT_FALSE(attr.ok());
  EXPECT_NE(attr.error().context.find("line 3"), std::string::npos) << attr.error().context;
}

TEST(EsiReader, AmpersandInCdataCommentsAndReferencesIsFine) {
  const char* text =
      "<?xml version=\"1.0\"?>\n<!-- AB&T -->\n<EtherCATInfo>\n"
      "<Vendor><Id>1</Id><Name><![CDATA[A&B]]></Name></Vendor>\n"
      "<Descriptions><Devices><Device><Type>x &#181; &#xB5; &lt;&gt;&quot;&apos;</Type>"
      "</Device></Devices></Descriptions></EtherCATInfo>";
  auto file = parseEsi(text, "ok.xml");
  ASSERT_TRUE(file.ok()) << file.error().message();
  EXPECT_EQ(file->vendor.name(), "A&B");
  EXPECT_EQ(file->devices[0].type, "x \xc2\xb5 \xc2\xb5 <>\"'");
}

TEST(EsiReader, BadNumberNamesItsLine) {
  const char* text =
      "<EtherCATInfo><Descriptions><Devices>\n<Device>\n"
      "<Type ProductCode=\"#x1FFFFFFFF\">X</Type>\n</Device></Devices></Descriptions>"
      "</EtherCATInfo>";
  auto file = parseEsi(text, "num.xml");
  ASSERT_FALSE(file.ok());
  EXPECT_NE(file.error().context.find("num.xml, line 3"), std::string::npos)
      << file.error().context;
  EXPECT_NE(file.error().context.find("ProductCode"), std::string::npos);
}

// Issue #15 item 11: a malformed value inside one object (DefaultData with an odd number of hex
// digits, an Index that is no number) must not make the file unusable: a warning naming file
// and line, the nearest sensible value (the whole bytes written; the object left out when even
// its index is unreadable), and the rest of the file as written.
TEST(EsiReader, MalformedValueInsideAnObjectIsAWarning) {
  const char* text =
      "<EtherCATInfo><Descriptions><Devices><Device>\n"
      "<Type ProductCode=\"#x1\">X</Type><Profile><Dictionary><Objects>\n"
      "<Object><Index>#x2000</Index><Name>Odd</Name><Type>UDINT</Type><BitSize>32</BitSize>\n"
      "<Info><DefaultData>0A1</DefaultData></Info></Object>\n"
      "<Object><Index>#xZZ</Index><Name>Bad</Name><Type>UINT</Type><BitSize>16</BitSize>"
      "</Object>\n"
      "<Object><Index>#x2002</Index><Name>Good</Name><Type>UINT</Type><BitSize>16</BitSize>"
      "<Info><DefaultData>3412</DefaultData></Info></Object>\n"
      "</Objects></Dictionary></Profile></Device></Devices></Descriptions></EtherCATInfo>";
  auto file = parseEsi(text, "odd.xml");
  ASSERT_TRUE(file.ok()) << file.error().message();
  const EsiDictionary& dict = file->devices.at(0).dictionary;
  ASSERT_EQ(dict.objects.size(), 2u);
  const EsiObject* odd = dict.findObject(0x2000);
  ASSERT_NE(odd, nullptr);
  EXPECT_EQ(odd->info.defaultData, std::vector<std::uint8_t>{0x0A}) << "the whole byte kept";
  ASSERT_NE(dict.findObject(0x2002), nullptr);
  EXPECT_EQ(dict.findObject(0x2002)->info.defaultData, (std::vector<std::uint8_t>{0x34, 0x12}));
  ASSERT_EQ(file->warnings.size(), 2u);
  EXPECT_NE(file->warnings[0].find("odd.xml, line 4"), std::string::npos) << file->warnings[0];
  EXPECT_NE(file->warnings[0].find("odd number of hex digits"), std::string::npos);
  EXPECT_NE(file->warnings[1].find("odd.xml, line 5"), std::string::npos) << file->warnings[1];
  EXPECT_NE(file->warnings[1].find("left out"), std::string::npos) << file->warnings[1];
}

// Issue #15 item 11: SMs that overlap in the ESI are a warning naming both; the device is read
// as written. A 3-buffer SM takes 3 x its length (ESC datasheet section I, SyncManager
// chapter); an SM of length 1 is no buffer and takes its one byte (Beckhoff_EM2xxx.xml's
// 0x0F00/0x0F01 pair, see EsiCorpus: no warning there).
TEST(EsiReader, OverlappingSyncManagersAreAWarning) {
  const char* text =
      "<EtherCATInfo><Descriptions><Devices><Device>\n"
      "<Type ProductCode=\"#x1\">X</Type>\n"
      "<Sm StartAddress=\"#x1100\" DefaultSize=\"8\" ControlByte=\"#x64\">Outputs</Sm>\n"
      "<Sm StartAddress=\"#x1110\" DefaultSize=\"4\" ControlByte=\"#x20\">Inputs</Sm>\n"  // 3 x 4
      "<Sm StartAddress=\"#x0F00\" DefaultSize=\"1\" ControlByte=\"#x44\">Outputs</Sm>\n"
      "<Sm StartAddress=\"#x0F01\" DefaultSize=\"1\" ControlByte=\"#x44\">Outputs</Sm>\n"
      "</Device></Devices></Descriptions></EtherCATInfo>";
  auto file = parseEsi(text, "sm.xml");
  ASSERT_TRUE(file.ok()) << file.error().message();
  ASSERT_EQ(file->devices.at(0).syncManagers.size(), 4u) << "read as written";
  ASSERT_EQ(file->warnings.size(), 1u);
  EXPECT_NE(file->warnings[0].find("sm.xml, line 4: Sm 1 (0x1110-0x111B) overlaps Sm 0 (line 3, "
                                   "0x1100-0x1117)"),
            std::string::npos)
      << file->warnings[0];
}

TEST(EsiReader, UnknownRootIsAnError) {
  auto file = parseEsi("<EtherCATConfig/>", "eni.xml");
  ASSERT_FALSE(file.ok());
  EXPECT_NE(file.error().context.find("EtherCATConfig"), std::string::npos);
}

TEST(EsiReader, MissingFileIsNotFound) {
  auto file = loadEsiFile("/nonexistent/esi.xml");
  ASSERT_FALSE(file.ok());
  EXPECT_EQ(file.error().code, ErrorCode::kNotFound);
}

// --- other roots, old-style PDO templates, encodings ----------------------------------------

TEST(EsiReader, DictAndModuleRoots) {
  auto dict = parseEsi(
      "<EtherCATDict><Dictionary><Objects><Object><Index>1</Index><Name LcId=\"1033\">Cycle"
      "</Name><Type>UINT</Type><BitSize>16</BitSize><Info><MinValue>62</MinValue></Info>"
      "<Flags><Attribute>#x60110001</Attribute></Flags></Object></Objects></Dictionary>"
      "</EtherCATDict>",
      "dict.xml");
  ASSERT_TRUE(dict.ok()) << dict.error().message();
  EXPECT_EQ(dict->root, EsiRoot::kEtherCatDict);
  EXPECT_TRUE(dict->devices.empty());
  ASSERT_EQ(dict->dictionary.objects.size(), 1u);
  EXPECT_EQ(dict->dictionary.objects[0].index, 1u);
  EXPECT_EQ(dict->dictionary.objects[0].info.minValue, "62");

  auto modules = parseEsi(
      "<EtherCATModule><Vendor><Id>560</Id></Vendor><Modules><Module>"
      "<Type ModuleClass=\"Di\" ModuleIdent=\"#x00091F84\">UR20-4DI-P</Type>"
      "<Name LcId=\"1031\">Eingang</Name>"
      "<TxPdo Sm=\"3\"><Index DependOnSlot=\"1\">#x1A00</Index></TxPdo>"
      "</Module></Modules></EtherCATModule>",
      "modules.xml");
  ASSERT_TRUE(modules.ok()) << modules.error().message();
  EXPECT_EQ(modules->root, EsiRoot::kEtherCatModule);
  EXPECT_EQ(modules->vendor.id, 560u);
  ASSERT_EQ(modules->modules.size(), 1u);
  EXPECT_EQ(modules->modules[0].moduleIdent, 0x91F84u);
  EXPECT_EQ(modules->modules[0].moduleClass, "Di");
  EXPECT_EQ(modules->modules[0].name(), "Eingang");
  EXPECT_TRUE(modules->modules[0].txPdos.at(0).dependOnSlot);
}

TEST(EsiReader, ResolvesPdoTemplatesByRefAndChannel) {
  // The 2006-era layout of Beckhoff_EtherCAT_Terminals.xml.
  const char* text = R"(<EtherCATInfo><Descriptions><Devices>
    <Device><Type ProductCode="#x03ec3052" RevisionNo="#x270b0000">EL1004</Type>
      <TxPdo Ref="DigInputBit" Chn="2" Fixed="1" Sm="0"/></Device></Devices>
    <Pdos><Pdo RefName="DigInputBit"><Name ChnFac="1">Channel #1</Name>
      <Index ChnFac="1">#x1a00</Index>
      <Entry><Index>#x3101</Index><SubIndex ChnFac="1">1</SubIndex><BitLen>1</BitLen>
        <Name>Input</Name><DataType>BOOL</DataType></Entry></Pdo></Pdos>
  </Descriptions></EtherCATInfo>)";
  auto file = parseEsi(text, "old.xml");
  ASSERT_TRUE(file.ok()) << file.error().message();
  const EsiPdo& pdo = file->devices.at(0).txPdos.at(0);
  EXPECT_EQ(pdo.ref, "DigInputBit");
  EXPECT_EQ(pdo.index, 0x1A02);
  EXPECT_EQ(pdo.name(), "Channel #3");
  EXPECT_EQ(pdo.sm, 0);
  ASSERT_EQ(pdo.entries.size(), 1u);
  EXPECT_EQ(pdo.entries[0].index, 0x3101);  // no ChnFac: unchanged
  EXPECT_EQ(pdo.entries[0].subIndex, 3);

  auto dangling = parseEsi(
      "<EtherCATInfo><Descriptions><Devices><Device><Type>X</Type>\n"
      "<RxPdo Ref=\"Nowhere\"/></Device></Devices></Descriptions></EtherCATInfo>",
      "dangling.xml");
  ASSERT_FALSE(dangling.ok());
  EXPECT_NE(dangling.error().context.find("line 2"), std::string::npos);
}

TEST(EsiReader, Latin1FileKeepsBytesAndConvertsForDisplay) {
  std::string text =
      "<?xml version=\"1.0\" encoding=\"ISO-8859-1\"?>\n<EtherCATInfo><Vendor><Id>2</Id>"
      "<Name>Min. inhibit time[\xb5s]</Name></Vendor></EtherCATInfo>";
  auto file = parseEsi(text, "latin1.xml");
  ASSERT_TRUE(file.ok()) << file.error().message();
  EXPECT_EQ(file->encoding, EsiEncoding::kLatin1);
  EXPECT_EQ(file->vendor.name(), "Min. inhibit time[\xb5s]");
  EXPECT_EQ(file->display(file->vendor.name()), "Min. inhibit time[\xc2\xb5s]");

  auto utf8 = parseEsi("<?xml version='1.0' encoding='utf-8'?><EtherCATInfo/>", "u.xml");
  ASSERT_TRUE(utf8.ok());
  EXPECT_EQ(utf8->encoding, EsiEncoding::kUtf8);
  EXPECT_EQ(utf8->display("\xc2\xb5"), "\xc2\xb5");
}

}  // namespace
}  // namespace ecsim
