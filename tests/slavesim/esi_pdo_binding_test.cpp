// PDO descriptions that vendors' ESI files get wrong, and what a slave built from them does.
// The inline device copies the structure of Beckhoff_EL3xxx.xml's EL3632 (rev 0x00110000), a
// 2-channel oversampling terminal (not in ../shared; the file is public, e.g. in
// DiamondLightSource/ethercat etc/xml): its TxPdo 0x1A41 "Ch2 Sample" maps 16 bits of
// 0x6000:02 (channel 1's 1-bit status), its dictionary's 0x1A41 maps 0x6012:01, and the
// dictionary's sample mappings 0x1A01.. (one per oversampling step, OSFac up to 50) map
// 0x6002:nn, which the dictionary does not have. Built as written, the device's default PDO
// configuration could not be bound and PREOP->SAFEOP was refused with 0x001D, with nothing
// said at build time.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "config/esi.hpp"
#include "protocol/sii.hpp"
#include "slavesim/coe/standard_objects.hpp"
#include "slavesim/esi_slave.hpp"

namespace ecsim::testing {
namespace {

namespace coe = slavesim::coe;

const char* const kOversamplingEsi = R"(<EtherCATInfo><Vendor><Id>#x2</Id></Vendor>
<Descriptions><Devices><Device Physics="YY">
  <Type ProductCode="#xE303052" RevisionNo="#x00110000">OS-2</Type><Name>Oversampling test</Name>
  <Profile><Dictionary>
    <DataTypes>
      <DataType><Name>DT6000</Name><BitSize>24</BitSize>
        <SubItem><SubIdx>0</SubIdx><Name>SubIndex 000</Name><Type>USINT</Type><BitSize>8</BitSize>
          <BitOffs>0</BitOffs><Flags><Access>ro</Access></Flags></SubItem>
        <SubItem><SubIdx>1</SubIdx><Name>Underrange</Name><Type>BOOL</Type><BitSize>1</BitSize>
          <BitOffs>16</BitOffs><Flags><Access>ro</Access><PdoMapping>T</PdoMapping></Flags></SubItem>
        <SubItem><SubIdx>2</SubIdx><Name>Overrange</Name><Type>BOOL</Type><BitSize>1</BitSize>
          <BitOffs>17</BitOffs><Flags><Access>ro</Access><PdoMapping>T</PdoMapping></Flags></SubItem>
      </DataType>
      <DataType><Name>DTMAP1</Name><BitSize>48</BitSize>
        <SubItem><SubIdx>0</SubIdx><Name>SubIndex 000</Name><Type>USINT</Type><BitSize>8</BitSize>
          <BitOffs>0</BitOffs><Flags><Access>ro</Access></Flags></SubItem>
        <SubItem><SubIdx>1</SubIdx><Name>SubIndex 001</Name><Type>UDINT</Type><BitSize>32</BitSize>
          <BitOffs>16</BitOffs><Flags><Access>ro</Access></Flags></SubItem>
      </DataType>
      <DataType><Name>DTMAP3</Name><BitSize>112</BitSize>
        <SubItem><SubIdx>0</SubIdx><Name>SubIndex 000</Name><Type>USINT</Type><BitSize>8</BitSize>
          <BitOffs>0</BitOffs><Flags><Access>ro</Access></Flags></SubItem>
        <SubItem><SubIdx>1</SubIdx><Name>SubIndex 001</Name><Type>UDINT</Type><BitSize>32</BitSize>
          <BitOffs>16</BitOffs><Flags><Access>ro</Access></Flags></SubItem>
        <SubItem><SubIdx>2</SubIdx><Name>SubIndex 002</Name><Type>UDINT</Type><BitSize>32</BitSize>
          <BitOffs>48</BitOffs><Flags><Access>ro</Access></Flags></SubItem>
        <SubItem><SubIdx>3</SubIdx><Name>SubIndex 003</Name><Type>UDINT</Type><BitSize>32</BitSize>
          <BitOffs>80</BitOffs><Flags><Access>ro</Access></Flags></SubItem>
      </DataType>
      <DataType><Name>DT1C13ARR</Name><BaseType>UINT</BaseType><BitSize>64</BitSize>
        <ArrayInfo><LBound>1</LBound><Elements>4</Elements></ArrayInfo></DataType>
      <DataType><Name>DT1C13</Name><BitSize>80</BitSize>
        <SubItem><SubIdx>0</SubIdx><Name>SubIndex 000</Name><Type>USINT</Type><BitSize>8</BitSize>
          <BitOffs>0</BitOffs><Flags><Access>rw</Access></Flags></SubItem>
        <SubItem><Name>Elements</Name><Type>DT1C13ARR</Type><BitSize>64</BitSize><BitOffs>16</BitOffs>
          <Flags><Access>rw</Access></Flags></SubItem></DataType>
    </DataTypes>
    <Objects>
      <Object><Index>#x1A00</Index><Name>TxPDO-MapStatus Ch.1</Name><Type>DTMAP3</Type><BitSize>112</BitSize>
        <Info><SubItem><Name>SubIndex 000</Name><Info><DefaultData>03</DefaultData></Info></SubItem>
          <SubItem><Name>SubIndex 001</Name><Info><DefaultData>01010060</DefaultData></Info></SubItem>
          <SubItem><Name>SubIndex 002</Name><Info><DefaultData>01020060</DefaultData></Info></SubItem>
          <SubItem><Name>SubIndex 003</Name><Info><DefaultData>0E000000</DefaultData></Info></SubItem>
        </Info></Object>
      <Object><Index>#x1A01</Index><Name>TxPDO-MapSamples 1 Ch.1</Name><Type>DTMAP1</Type><BitSize>48</BitSize>
        <Info><SubItem><Name>SubIndex 000</Name><Info><DefaultData>01</DefaultData></Info></SubItem>
          <SubItem><Name>SubIndex 001</Name><Info><DefaultData>10010260</DefaultData></Info></SubItem>
        </Info></Object>
      <Object><Index>#x1A02</Index><Name>TxPDO-MapSamples 2 Ch.1</Name><Type>DTMAP1</Type><BitSize>48</BitSize>
        <Info><SubItem><Name>SubIndex 000</Name><Info><DefaultData>01</DefaultData></Info></SubItem>
          <SubItem><Name>SubIndex 001</Name><Info><DefaultData>10020260</DefaultData></Info></SubItem>
        </Info></Object>
      <Object><Index>#x1A41</Index><Name>TxPDO-MapSamples 1 Ch.2</Name><Type>DTMAP1</Type><BitSize>48</BitSize>
        <Info><SubItem><Name>SubIndex 000</Name><Info><DefaultData>01</DefaultData></Info></SubItem>
          <SubItem><Name>SubIndex 001</Name><Info><DefaultData>10011260</DefaultData></Info></SubItem>
        </Info></Object>
      <Object><Index>#x1C13</Index><Name>TxPDO assign</Name><Type>DT1C13</Type><BitSize>80</BitSize>
        <Info><SubItem><Name>SubIndex 000</Name><Info><DefaultData>00</DefaultData></Info></SubItem>
        </Info></Object>
      <Object><Index>#x6000</Index><Name>AI Inputs Ch.1</Name><Type>DT6000</Type><BitSize>24</BitSize>
        <Info><SubItem><Name>SubIndex 000</Name><Info><DefaultData>02</DefaultData></Info></SubItem>
        </Info></Object>
    </Objects>
  </Dictionary></Profile>
  <Sm StartAddress="#x1000" ControlByte="#x26" Enable="1" DefaultSize="128">MBoxOut</Sm>
  <Sm StartAddress="#x1080" ControlByte="#x22" Enable="1" DefaultSize="128">MBoxIn</Sm>
  <Sm StartAddress="#x1100" ControlByte="#x04" Enable="0" DefaultSize="0">Outputs</Sm>
  <Sm StartAddress="#x1110" ControlByte="#x20" Enable="1" DefaultSize="6">Inputs</Sm>
  <TxPdo Sm="3"><Index>#x1A00</Index><Name>Ch1 Status</Name>
    <Entry><Index>#x6000</Index><SubIndex>1</SubIndex><BitLen>1</BitLen><Name>Underrange</Name><DataType>BOOL</DataType></Entry>
    <Entry><Index>#x6000</Index><SubIndex>2</SubIndex><BitLen>1</BitLen><Name>Overrange</Name><DataType>BOOL</DataType></Entry>
    <Entry><Index>#x0</Index><BitLen>14</BitLen></Entry></TxPdo>
  <TxPdo Sm="3" OSFac="10" OSMin="1" OSMax="50" OSIndexInc="1"><Index>#x1A01</Index><Name>Ch1 Sample</Name>
    <Entry><Index>#x6002</Index><SubIndex>1</SubIndex><BitLen>16</BitLen><Name>Ch1 Value</Name><DataType>INT</DataType></Entry></TxPdo>
  <TxPdo Sm="3" OSFac="10" OSMin="1" OSMax="50" OSIndexInc="1"><Index>#x1A41</Index><Name>Ch2 Sample</Name>
    <Entry><Index>#x6000</Index><SubIndex>2</SubIndex><BitLen>16</BitLen><Name>Ch2 Value</Name><DataType>INT</DataType></Entry></TxPdo>
  <Mailbox><CoE SdoInfo="true" PdoAssign="true"/></Mailbox>
</Device></Devices></Descriptions></EtherCATInfo>)";

struct Built {
  std::unique_ptr<slavesim::Slave> slave;
  std::vector<std::string> warnings;
};

Built build(const char* esi) {
  auto file = parseEsi(esi, "os.xml");
  EXPECT_TRUE(file.ok()) << file.error().message();
  Built out;
  slavesim::EsiSlaveOptions options;
  options.warnings = &out.warnings;
  auto slave = slavesim::makeSlaveFromEsi(*file, file->devices.at(0), "AI", options);
  EXPECT_TRUE(slave.ok()) << slave.error().message();
  out.slave = std::move(slave).value();
  return out;
}

bool anyContains(const std::vector<std::string>& texts, std::initializer_list<const char*> parts) {
  return std::any_of(texts.begin(), texts.end(), [&](const std::string& t) {
    return std::all_of(parts.begin(), parts.end(),
                       [&](const char* p) { return t.find(p) != std::string::npos; });
  });
}

unsigned inputBytes(const slavesim::SlaveProfile& profile) {
  unsigned n = 0;
  for (const auto& pd : profile.processData) n += pd.outputs ? 0u : pd.length;
  return n;
}

TEST(EsiPdoBinding, PdoEntriesThatCannotBeMappedLeaveTheDictionarysMapping) {
  Built b = build(kOversamplingEsi);
  slavesim::ProcessDataDevice* pd = slavesim::processDataDeviceOf(*b.slave);
  ASSERT_NE(pd, nullptr);
  EXPECT_TRUE(pd->bindStatus().ok()) << pd->bindStatus().error().message();
  // The default assignment, from the device's PDOs with Sm=3: 2 + 2 + 2 bytes.
  EXPECT_EQ(inputBytes(b.slave->profile()), 6u);
  const auto mapping = coe::mappedObjects(pd->dictionary(), 0x1A41);
  ASSERT_EQ(mapping.size(), 1u);
  EXPECT_EQ(mapping[0].index, 0x6012);
  EXPECT_EQ(mapping[0].subindex, 1);
  // The SII PDO category says the same, so a master configuring from the SII builds the same
  // process image as one reading CoE.
  auto sii = SiiImage::parse(b.slave->esc().sii());
  ASSERT_TRUE(sii.ok()) << sii.error().message();
  const auto& tx = sii->contents().txPdos;
  auto pdo = std::find_if(tx.begin(), tx.end(), [](const SiiPdo& p) { return p.index == 0x1A41; });
  ASSERT_NE(pdo, tx.end());
  ASSERT_EQ(pdo->entries.size(), 1u);
  EXPECT_EQ(pdo->entries[0].index, 0x6012);
  EXPECT_EQ(pdo->entries[0].subIndex, 1);
  EXPECT_EQ(pdo->entries[0].bitLength, 16);
  // Said at build time, with the PDO's line in the file (its <TxPdo> is line 75).
  EXPECT_TRUE(anyContains(b.warnings, {"0x1A41", "line 75", "cannot be mapped", "0x6000:2"}))
      << ::testing::PrintToString(b.warnings);
}

TEST(EsiPdoBinding, OversamplingMappingsOfTheDictionaryCanBeAssigned) {
  Built b = build(kOversamplingEsi);
  slavesim::ProcessDataDevice* pd = slavesim::processDataDeviceOf(*b.slave);
  ASSERT_NE(pd, nullptr);
  // 0x1A02 (the second sample of an oversampling factor of 2) maps 0x6002:02, which no PDO of
  // the device describes and the dictionary lacks: it is made up from the mapping.
  const coe::Entry* sample2 = pd->dictionary().findEntry(0x6002, 2);
  ASSERT_NE(sample2, nullptr);
  EXPECT_EQ(sample2->bitLength, 16);
  EXPECT_NE(sample2->access & coe::access::kTxMappable, 0);
  EXPECT_TRUE(anyContains(b.warnings, {"made up from the mappings"}))
      << ::testing::PrintToString(b.warnings);
  // A master choosing oversampling factor 2 for channel 1: 0x1A00, 0x1A01, 0x1A02.
  coe::Object* assign = pd->dictionary().find(0x1C13);
  ASSERT_NE(assign, nullptr);
  const std::uint16_t pdos[] = {0x1A00, 0x1A01, 0x1A02};
  for (std::uint8_t i = 0; i < 3; ++i) {
    ASSERT_TRUE(pd->dictionary().set<std::uint16_t>(0x1C13, i + 1, pdos[i]).ok());
  }
  ASSERT_TRUE(pd->dictionary().set<std::uint8_t>(0x1C13, 0, 3).ok());
  slavesim::SlaveProfile profile = b.slave->profile();
  pd->updateProfile(profile);
  EXPECT_TRUE(pd->bindStatus().ok()) << pd->bindStatus().error().message();
  EXPECT_EQ(inputBytes(profile), 6u);
}

// A PDO that maps more bits than its object holds, with no mapping object in the dictionary to
// fall back on: the slave is built (a real device with this description refuses SAFEOP as the
// simulated one does), and the build says why instead of leaving only AL status code 0x001E.
TEST(EsiPdoBinding, UnbindableDefaultConfigurationIsReportedAtBuildTime) {
  const char* const esi = R"(<EtherCATInfo><Vendor><Id>#x2</Id></Vendor>
<Descriptions><Devices><Device Physics="YY">
  <Type ProductCode="#x10" RevisionNo="#x1">BAD-1</Type><Name>Bad</Name>
  <Profile><Dictionary><DataTypes/><Objects>
    <Object><Index>#x6000</Index><Name>Input</Name><Type>BOOL</Type><BitSize>1</BitSize>
      <Flags><Access>ro</Access><PdoMapping>T</PdoMapping></Flags></Object>
  </Objects></Dictionary></Profile>
  <Sm StartAddress="#x1000" ControlByte="#x26" Enable="1" DefaultSize="128">MBoxOut</Sm>
  <Sm StartAddress="#x1080" ControlByte="#x22" Enable="1" DefaultSize="128">MBoxIn</Sm>
  <Sm StartAddress="#x1100" ControlByte="#x04" Enable="0" DefaultSize="0">Outputs</Sm>
  <Sm StartAddress="#x1110" ControlByte="#x20" Enable="1" DefaultSize="2">Inputs</Sm>
  <TxPdo Sm="3" Fixed="1"><Index>#x1A00</Index><Name>In</Name>
    <Entry><Index>#x6000</Index><SubIndex>0</SubIndex><BitLen>16</BitLen><Name>Value</Name><DataType>UINT</DataType></Entry></TxPdo>
  <Mailbox><CoE SdoInfo="true"/></Mailbox>
</Device></Devices></Descriptions></EtherCATInfo>)";
  Built b = build(esi);
  slavesim::ProcessDataDevice* pd = slavesim::processDataDeviceOf(*b.slave);
  ASSERT_NE(pd, nullptr);
  EXPECT_FALSE(pd->bindStatus().ok());
  EXPECT_TRUE(anyContains(b.warnings, {"default PDO configuration cannot be bound", "0x6000"}))
      << ::testing::PrintToString(b.warnings);
}

}  // namespace
}  // namespace ecsim::testing
