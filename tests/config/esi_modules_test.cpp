// Modules in the slots of a modular device (config/esi_modules.hpp), on the real Weidmueller
// u-remote files (Weidmueller_UR20_FBC.xml: <Slots SlotIndexIncrement="16" SlotPdoIncrement="1">
// at line 3668; Weidmueller_UR20_IO.xml: UR20-4DI-P, ModuleIdent #x00091F84, TxPdo
// <Index DependOnSlot="1">#x1A00</Index> with entries #x6000:01..05 at lines 9-52) and on small
// documents for the default module (ETG.2001 <ModuleIdent Default="1">).
#include "config/esi_modules.hpp"

#include <gtest/gtest.h>

#include "tests/config/shared_data.hpp"

namespace ecsim {
namespace {

struct Ur20 {
  EsiFile fbc;
  EsiFile io;
};

const EsiDevice& coupler(const Ur20& files) {
  return files.fbc.devices.at(0);  // UR20-FBC-EC rev #x00000001
}

const EsiPdo* findPdo(const std::vector<EsiPdo>& pdos, std::uint16_t index) {
  for (const auto& p : pdos) {
    if (p.index == index) return &p;
  }
  return nullptr;
}

TEST(EsiModules, Ur20ModulesMovePerSlot) {
  ECSIM_REQUIRE_SHARED_FILE(fbcPath, "esi", "Weidmueller_UR20_FBC.xml");
  ECSIM_REQUIRE_SHARED_FILE(ioPath, "esi", "Weidmueller_UR20_IO.xml");
  auto fbc = loadEsiFile(fbcPath);
  auto io = loadEsiFile(ioPath);
  ASSERT_TRUE(fbc.ok() && io.ok());
  const Ur20 files{std::move(fbc).value(), std::move(io).value()};
  const EsiDevice& head = coupler(files);
  ASSERT_EQ(head.slots.size(), 1u);
  EXPECT_EQ(head.slots[0].indexIncrement, 16u);
  EXPECT_EQ(head.slots[0].pdoIncrement, 1u);

  EsiModuleCatalog catalog;
  catalog.add(files.fbc);
  catalog.add(files.io);
  const EsiModule* di = catalog.findByType("UR20-4DI-P");
  const EsiModule* doModule = catalog.findByType("UR20-4DO-P");
  ASSERT_NE(di, nullptr);
  ASSERT_NE(doModule, nullptr);
  EXPECT_EQ(catalog.findByIdent(0x00091F84u), di);

  std::vector<std::string> notes;
  auto device = instantiateModules(head, {di, doModule, di}, &notes);
  ASSERT_TRUE(device.ok()) << device.error().message();
  EXPECT_EQ(device->moduleIdents,
            (std::vector<std::uint32_t>{0x00091F84u, doModule->moduleIdent, 0x00091F84u}));
  // Slot 0: TxPdo 0x1A00 mapping 0x6000; slot 2: TxPdo 0x1A02 mapping 0x6020.
  const EsiPdo* first = findPdo(device->txPdos, 0x1A00);
  const EsiPdo* third = findPdo(device->txPdos, 0x1A02);
  ASSERT_NE(first, nullptr);
  ASSERT_NE(third, nullptr);
  EXPECT_EQ(first->entries.at(0).index, 0x6000);
  EXPECT_EQ(third->entries.at(0).index, 0x6020);
  EXPECT_EQ(third->entries.at(4).index, 0) << "the 4-bit gap stays a gap";
  // The output module in slot 1: RxPdo 0x1601 mapping 0x7010.
  const EsiPdo* outputs = findPdo(device->rxPdos, 0x1601);
  ASSERT_NE(outputs, nullptr);
  EXPECT_EQ(outputs->entries.at(0).index, 0x7010);
  // The head's own PDOs come first (ModulePdoGroup 0: 0x16FF/0x1AFF).
  EXPECT_EQ(device->txPdos.front().index, 0x1AFF);
  // Objects: the module's 0x6000 (Input UR20-4DI-P) in slot 0 and 2, its 0x1A00 at 0x1A02.
  EXPECT_NE(device->dictionary.findObject(0x6000), nullptr);
  EXPECT_NE(device->dictionary.findObject(0x6020), nullptr);
  EXPECT_NE(device->dictionary.findObject(0x1A02), nullptr);
  EXPECT_NE(device->dictionary.findObject(0x7010), nullptr);
  EXPECT_EQ(device->dictionary.findObject(0x7000), nullptr) << "slot 0 holds an input module";
  // SM sizes as TwinCAT computes them: the PDOs assigned to each. Inputs (SM3): the head's
  // 0x1AFF, 2 x UR20-4DI-P (16 bits each) and the UR20-4DO-P's own TxPdo.
  std::uint32_t inBits = 0;
  for (const auto& p : device->txPdos) inBits += p.sm == 3 ? p.bitLength() : 0;
  EXPECT_GE(inBits, 2 * first->bitLength() + findPdo(device->txPdos, 0x1AFF)->bitLength());
  EXPECT_EQ(device->syncManagers.at(3).defaultSize, (inBits + 7) / 8);
  EXPECT_EQ(head.syncManagers.at(3).defaultSize, 0) << "the ESI gives none";
}

TEST(EsiModules, ModuleOfAClassNoSlotTakesIsAnError) {
  ECSIM_REQUIRE_SHARED_FILE(fbcPath, "esi", "Weidmueller_UR20_FBC.xml");
  auto fbc = loadEsiFile(fbcPath);
  ASSERT_TRUE(fbc.ok());
  EsiModule alien;
  alien.type = "Alien";
  alien.moduleClass = "Xx";
  auto device = instantiateModules(fbc->devices.at(0), {&alien});
  ASSERT_FALSE(device.ok());
  EXPECT_NE(device.error().context.find("class 'Xx' fits no remaining slot"), std::string::npos)
      << device.error().context;
}

constexpr const char* kDefaultModuleDevice = R"(<EtherCATInfo><Vendor><Id>1</Id></Vendor>
<Descriptions><Devices><Device><Type ProductCode="#x10">Head</Type>
<Sm StartAddress="#x1000" ControlByte="#x64">Outputs</Sm>
<Sm StartAddress="#x1400" ControlByte="#x20">Inputs</Sm>
<Slots SlotIndexIncrement="16" SlotPdoIncrement="1">
  <Slot MinInstances="2" MaxInstances="4"><Name>Io</Name>
    <ModuleIdent>#x22</ModuleIdent><ModuleIdent Default="1">#x21</ModuleIdent></Slot>
</Slots></Device></Devices>
<Modules><Module><Type ModuleIdent="#x21">DI8</Type>
  <TxPdo Sm="1"><Index DependOnSlot="1">#x1A00</Index><Name>In</Name>
    <Entry><Index DependOnSlot="1">#x6000</Index><SubIndex>1</SubIndex><BitLen>8</BitLen>
    <DataType>USINT</DataType></Entry></TxPdo></Module></Modules>
</Descriptions></EtherCATInfo>)";

TEST(EsiModules, SlotsDefaultModuleFillsMinInstances) {
  auto file = parseEsi(kDefaultModuleDevice, "default.xml");
  ASSERT_TRUE(file.ok()) << file.error().message();
  const EsiDevice& head = file->devices.at(0);
  ASSERT_EQ(head.slots.size(), 1u);
  EXPECT_EQ(head.slots[0].defaultModuleIdent, 0x21u);
  EsiModuleCatalog catalog;
  catalog.add(*file);
  auto defaults = defaultModules(head, catalog);
  ASSERT_TRUE(defaults.ok()) << defaults.error().message();
  ASSERT_EQ(defaults->size(), 2u) << "MinInstances=2";
  auto device = instantiateModules(head, *defaults);
  ASSERT_TRUE(device.ok()) << device.error().message();
  ASSERT_EQ(device->txPdos.size(), 2u);
  EXPECT_EQ(device->txPdos[1].index, 0x1A01);
  EXPECT_EQ(device->txPdos[1].entries.at(0).index, 0x6010);
  EXPECT_EQ(device->syncManagers.at(1).defaultSize, 2);
}

TEST(EsiModules, DefaultModuleMissingFromTheFilesIsAnError) {
  std::string xml = kDefaultModuleDevice;
  const std::string from = "Default=\"1\">#x21";
  xml.replace(xml.find(from), from.size(), "Default=\"1\">#x99");
  auto file = parseEsi(xml, "default.xml");
  ASSERT_TRUE(file.ok()) << file.error().message();
  EsiModuleCatalog catalog;
  catalog.add(*file);
  auto defaults = defaultModules(file->devices.at(0), catalog);
  ASSERT_FALSE(defaults.ok());
  EXPECT_NE(defaults.error().context.find("#x00000099"), std::string::npos)
      << defaults.error().context;
}

}  // namespace
}  // namespace ecsim
