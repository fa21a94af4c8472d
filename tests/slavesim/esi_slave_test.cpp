// Slaves built from real ESI files (/work/shared/esi), driven only with frames as SOEM drives
// them (notes/soem-interop.md §3.3): station address, SII read through the EEPROM registers,
// mailbox SMs from the SII, INIT->PREOP; SM lengths from CoE (0x1C00, 0x1C1x, mapping
// objects) or, without CoE mapping, from the SII PDO categories; SMs from the SII SM
// category, FMMUs, PREOP->SAFEOP, one LRW, SAFEOP->OP.
#include "slavesim/esi_slave.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>

#include "config/esi.hpp"
#include "tests/slavesim/coe_test_support.hpp"

namespace ecsim::testing {
namespace {

namespace fs = std::filesystem;

fs::path esiDir() {
  return sharedDir() / "esi";
}

struct Outcome {
  AlState reached{AlState::kInit};
  std::string reason;  // why it stopped there (empty when OP was reached)
  std::uint16_t outBytes{0};
  std::uint16_t inBytes{0};
  bool coeMapping{false};
  std::uint16_t lrwWkc{0};
  std::uint16_t expectedWkc{0};
  struct Sm {
    unsigned index;
    std::uint16_t start;
    std::uint8_t control;
    bool outputs;
  };
  std::vector<Sm> processDataSms;  // as the master programmed them
};

// Why a device stopped before OP, in terms of what is (not) modelled; "" when unexplained.
std::string classify(const Outcome& o) {
  if (o.reached == AlState::kOp) return "OP";
  for (const auto& sm : o.processDataSms) {
    if (o.reached == AlState::kPreOp &&
        (sm.control & reg::sm::kControlModeMask) == reg::sm::kControlModeMailbox) {
      return "a process-data SM in 1-buffer (mailbox) mode: the ESM accepts 3-buffer SMs only";
    }
  }
  for (const auto& sm : o.processDataSms) {
    if (o.reached == AlState::kSafeOp && sm.outputs && sm.start < reg::kRegisterSpaceEnd) {
      return "an output SM over ESC registers (0x0F00): the ESC keeps no buffer there, so "
             "outputs never become valid";
    }
  }
  return "";
}

std::string hex(std::uint32_t v) {
  std::ostringstream s;
  s << "0x" << std::hex << v;
  return s.str();
}

// Reaches as far as the device allows; the slave is segment slave 0, station 0x1001.
Outcome driveLikeSoem(topology::Segment& seg) {
  Outcome out;
  const std::uint16_t station = kStation;
  one(seg, Command::kApwr, phys(0, reg::kConfiguredStationAddress.address), le16(station));
  std::vector<std::uint8_t> siiBytes = readSiiThroughFrames(seg, station);
  auto image = SiiImage::parseLenient(siiBytes);
  if (!image.ok()) {
    out.reason = "SII unreadable: " + image.error().message();
    return out;
  }
  const SiiContents& sii = image->contents();
  const auto& sms = sii.syncManagers;
  const SiiMailbox& mbx = sii.standardMailbox;
  std::unique_ptr<MailboxMaster> master;
  if (mbx.receiveSize > 0) {
    const std::uint16_t inSize = mbx.sendSize != 0 ? mbx.sendSize : mbx.receiveSize;
    master = std::make_unique<MailboxMaster>(seg, station, mbx.receiveOffset, mbx.receiveSize,
                                             mbx.sendOffset, inSize);
    const std::uint8_t c0 = sms.size() > 0 ? sms[0].control : 0x26;
    const std::uint8_t c1 = sms.size() > 1 ? sms[1].control : 0x22;
    one(seg, Command::kFpwr, phys(station, reg::smChannel(0)),
        smRegisterBytes(mbx.receiveOffset, mbx.receiveSize, c0));
    one(seg, Command::kFpwr, phys(station, reg::smChannel(1)),
        smRegisterBytes(mbx.sendOffset, inSize, c1));
  }
  requestState(seg, station, 0x0002);
  std::uint16_t status = alStatus(seg, station);
  if (status != 0x0002) {
    out.reason =
        "PREOP refused, AL status " + hex(status) + " code " + hex(alStatusCode(seg, station));
    return out;
  }
  out.reached = AlState::kPreOp;

  // SM lengths in bits, SOEM's way: CoE first, SII PDOs when CoE gives nothing.
  std::map<unsigned, std::uint32_t> bits;
  std::map<unsigned, bool> isOutput;
  if (master && (sii.mailboxProtocols & SiiMailboxProtocol::kCoe) != 0) {
    Upload count = master->upload(0x1C00, 0);
    if (count.abort == 0 && !count.data.empty() && count.data[0] > 2) {
      for (unsigned sm = 2; sm < count.data[0]; ++sm) {
        const auto type =
            master->uploadValue<std::uint8_t>(0x1C00, static_cast<std::uint8_t>(sm + 1));
        if (type != 3 && type != 4) continue;
        const auto assign = static_cast<std::uint16_t>(0x1C10 + sm);
        const auto pdos = master->uploadValue<std::uint8_t>(assign, 0);
        for (std::uint8_t k = 1; k <= pdos; ++k) {
          const auto pdo = master->uploadValue<std::uint16_t>(assign, k);
          const auto entries = master->uploadValue<std::uint8_t>(pdo, 0);
          for (std::uint8_t e = 1; e <= entries; ++e) {
            bits[sm] += master->uploadValue<std::uint32_t>(pdo, e) & 0xFF;
          }
        }
        isOutput[sm] = type == 3;
      }
    }
  }
  std::uint32_t total = 0;
  for (const auto& [sm, b] : bits) total += b;
  out.coeMapping = total > 0;
  if (total == 0) {
    bits.clear();
    for (int dir = 0; dir < 2; ++dir) {
      for (const SiiPdo& pdo : dir == 0 ? sii.rxPdos : sii.txPdos) {
        if (pdo.syncManager >= 8) continue;
        bits[pdo.syncManager] += pdo.bitLength();
        isOutput[pdo.syncManager] = dir == 0;
      }
    }
  }
  // SMs, then FMMUs: outputs from logical 0, inputs after them.
  std::uint32_t logical = 0;
  unsigned fmmu = 0;
  for (int pass = 0; pass < 2; ++pass) {
    for (const auto& [sm, b] : bits) {
      if (b == 0 || isOutput[sm] != (pass == 0)) continue;
      if (sm >= sms.size()) {
        out.reason =
            "PDOs assigned to SM" + std::to_string(sm) + ", which the SII does not describe";
        return out;
      }
      const auto bytes = static_cast<std::uint16_t>((b + 7) / 8);
      one(seg, Command::kFpwr, phys(station, reg::smChannel(sm)),
          smRegisterBytes(sms[sm].startAddress, bytes, sms[sm].control));
      out.processDataSms.push_back({sm, sms[sm].startAddress, sms[sm].control, pass == 0});
      one(seg, Command::kFpwr, phys(station, reg::fmmuChannel(fmmu++)),
          fmmuRegisterBytes(logical, bytes, sms[sm].startAddress, pass == 0 ? 2 : 1));
      logical += bytes;
      (pass == 0 ? out.outBytes : out.inBytes) += bytes;
    }
  }
  out.expectedWkc =
      static_cast<std::uint16_t>((out.outBytes > 0 ? 2 : 0) + (out.inBytes > 0 ? 1 : 0));
  requestState(seg, station, 0x0004);
  status = alStatus(seg, station);
  if (status != 0x0004) {
    out.reason =
        "SAFEOP refused, AL status " + hex(status) + " code " + hex(alStatusCode(seg, station));
    std::ostringstream detail;
    detail << " (slave expects";
    for (const auto& pd : seg.slave(0).profile().processData) {
      detail << " SM" << pd.index << "=" << pd.length;
    }
    detail << "; master set";
    for (const auto& [sm, b] : bits) {
      const auto c = seg.slave(0).esc().smConfig(sm);
      detail << " SM" << sm << "=" << c.length << "/ctrl " << hex(c.control.encode());
    }
    out.reason += detail.str() + ")";
    return out;
  }
  out.reached = AlState::kSafeOp;
  if (logical > 0) {
    out.lrwWkc = one(seg, Command::kLrw, 0, std::vector<std::uint8_t>(logical, 0)).wkc;
  }
  requestState(seg, station, 0x0008);
  status = alStatus(seg, station);
  if (status != 0x0008) {
    out.reason =
        "OP refused, AL status " + hex(status) + " code " + hex(alStatusCode(seg, station));
    return out;
  }
  out.reached = AlState::kOp;
  return out;
}

// The corpus, parsed once per test program.
struct Corpus {
  std::vector<std::pair<std::string, EsiFile>> files;  // file name, content
  std::vector<std::string> errors;
};

const Corpus& corpus() {
  static const Corpus loaded = [] {
    Corpus c;
    if (!fs::exists(esiDir())) return c;
    std::vector<fs::path> paths;
    for (const auto& entry : fs::directory_iterator(esiDir())) {
      if (entry.path().extension() == ".xml") paths.push_back(entry.path());
    }
    std::sort(paths.begin(), paths.end());
    for (const auto& path : paths) {
      const std::string name = path.filename().string();
      if (name == "DS402_PDOs_EasyCatProject.xml") continue;  // not well-formed XML (MANIFEST)
      auto esi = loadEsiFile(path);
      if (!esi.ok()) {
        c.errors.push_back(esi.error().message());
        continue;
      }
      c.files.emplace_back(name, std::move(esi).value());
    }
    return c;
  }();
  return loaded;
}

struct DeviceCase {
  std::size_t file{0};
  std::size_t device{0};
  std::string name;  // test name: file, type, revision, position
};

void PrintTo(const DeviceCase& c, std::ostream* os) {
  *os << c.name;
}

std::vector<DeviceCase> deviceCases() {
  std::vector<DeviceCase> out;
  const Corpus& c = corpus();
  for (std::size_t f = 0; f < c.files.size(); ++f) {
    const auto& [name, esi] = c.files[f];
    for (std::size_t d = 0; d < esi.devices.size(); ++d) {
      std::string id = name.substr(0, name.size() - 4) + "_" + esi.devices[d].type + "_rev" +
                       hex(esi.devices[d].revision) + "_" + std::to_string(d);
      for (char& ch : id) {
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
      }
      out.push_back({f, d, id});
    }
  }
  return out;
}

std::string labelOf(const DeviceCase& c) {
  const auto& [name, esi] = corpus().files[c.file];
  const EsiDevice& d = esi.devices[c.device];
  return name + " " + d.type + " rev " + hex(d.revision);
}

Result<Outcome> runCase(const DeviceCase& c) {
  const auto& [name, esi] = corpus().files[c.file];
  const EsiDevice& device = esi.devices[c.device];
  ECSIM_ASSIGN_OR_RETURN(auto slave, slavesim::makeSlaveFromEsi(esi, device, device.type));
  topology::Segment seg;
  seg.addSlave(std::move(slave));
  return driveLikeSoem(seg);
}

// Every device of every ESI file: built, then driven like SOEM as far as it goes. A device
// must reach PREOP; when it stops before OP the reason must be one classify() explains.
class EsiCorpus : public ::testing::TestWithParam<DeviceCase> {};

TEST_P(EsiCorpus, ReachesWhatItsConfigurationAllows) {
  const std::string label = labelOf(GetParam());
  auto outcome = runCase(GetParam());
  ASSERT_TRUE(outcome.ok()) << label << ": " << outcome.error().message();
  const Outcome& o = *outcome;
  EXPECT_GE(o.reached, AlState::kPreOp) << label << ": " << o.reason;
  EXPECT_FALSE(classify(o).empty()) << label << " stopped for an unexplained reason: " << o.reason;
  if (o.reached == AlState::kOp && o.outBytes + o.inBytes > 0) {
    EXPECT_EQ(o.lrwWkc, o.expectedWkc) << label;
  }
}

INSTANTIATE_TEST_SUITE_P(SharedEsi, EsiCorpus, ::testing::ValuesIn(deviceCases()),
                         [](const ::testing::TestParamInfo<DeviceCase>& param) {
                           return param.param.name;
                         });
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(EsiCorpus);

// The same run, summarised: how many devices reach which state, and why the others stop.
TEST(EsiSlave, CorpusStatistics) {
  ECSIM_REQUIRE_SHARED(esiDir());
  EXPECT_TRUE(corpus().errors.empty()) << corpus().errors.front();
  std::map<AlState, int> byState;
  std::map<std::string, int> reasons;
  std::ostringstream table;
  const std::vector<DeviceCase> cases = deviceCases();
  for (const DeviceCase& c : cases) {
    auto outcome = runCase(c);
    ASSERT_TRUE(outcome.ok()) << outcome.error().message();
    const Outcome& o = *outcome;
    ++byState[o.reached];
    ++reasons[classify(o)];
    table << "  " << toString(o.reached) << "\t" << labelOf(c) << "  out " << o.outBytes << " in "
          << o.inBytes << (o.coeMapping ? " (CoE)" : " (SII)")
          << (o.reason.empty() ? "" : "  -- " + o.reason) << "\n";
  }
  std::cout << "ESI devices driven like SOEM: " << cases.size() << "\n"
            << "  reached INIT " << byState[AlState::kInit] << ", PREOP "
            << byState[AlState::kPreOp] << ", SAFEOP " << byState[AlState::kSafeOp] << ", OP "
            << byState[AlState::kOp] << "\n";
  for (const auto& [why, n] : reasons) std::cout << "  " << n << " x " << why << "\n";
  std::cout << table.str();
  EXPECT_GT(cases.size(), 150u);
  EXPECT_EQ(byState[AlState::kInit], 0);
}

// ---- single devices ----------------------------------------------------------------------------

const EsiDevice* findDevice(const EsiFile& file, std::string_view type, std::uint32_t revision) {
  for (const auto& d : file.devices) {
    if (d.type == type && d.revision == revision) return &d;
  }
  return nullptr;
}

std::unique_ptr<slavesim::Slave> build(const EsiFile& file, const EsiDevice& device,
                                       slavesim::EsiSlaveOptions options = {}) {
  auto slave = slavesim::makeSlaveFromEsi(file, device, device.type, options);
  EXPECT_TRUE(slave.ok()) << (slave.ok() ? "" : slave.error().message());
  return slave.ok() ? std::move(slave).value() : nullptr;
}

MailboxMaster mailboxMasterFor(topology::Segment& seg) {
  const auto& m = *seg.slave(0).profile().mailbox;
  return MailboxMaster(seg, kStation, m.outStart, m.outSize, m.inStart, m.inSize);
}

TEST(EsiSlave, StmblServoThroughFramesFromSdoToProcessData) {
  const auto path = esiDir() / "STMBL_ECAT.xml";
  ECSIM_REQUIRE_SHARED(path);
  auto file = loadEsiFile(path);
  ASSERT_TRUE(file.ok());
  // Static process data (model="none"): the inputs set below stay as set. With its model the
  // STMBL is a CiA 402 drive (tests/embed/vendor_drive_test.cpp).
  slavesim::EsiSlaveOptions options;
  options.model = slavesim::devices::DeviceModelKind::kNone;
  auto slave = build(*file, file->devices.at(0), options);
  ASSERT_NE(slave, nullptr);
  EXPECT_EQ(slave->esc().type().kind, slavesim::EscKind::kLan9252) << "4 SMs, 2 ports";
  slavesim::coe::ObjectDictionary* od = slavesim::objectDictionaryOf(*slave);
  ASSERT_NE(od, nullptr);
  ASSERT_NE(slavesim::coeServerOf(*slave), nullptr);
  topology::Segment seg;
  seg.addSlave(std::move(slave));
  const Outcome o = driveLikeSoem(seg);
  ASSERT_EQ(o.reached, AlState::kOp) << o.reason;
  EXPECT_TRUE(o.coeMapping);
  EXPECT_EQ(o.outBytes, 6);
  EXPECT_EQ(o.inBytes, 6);

  MailboxMaster master = mailboxMasterFor(seg);
  EXPECT_EQ(master.uploadValue<std::uint32_t>(0x1018, 2), 0x20192u) << "as in the SII";
  EXPECT_EQ(master.uploadValue<std::uint32_t>(0x1018, 1), 4919u);
  Upload name = master.upload(0x1008, 0);
  EXPECT_EQ(name.command, 0x41);
  EXPECT_EQ(std::string(name.data.begin(), name.data.end()), "STMBL ECAT");
  EXPECT_EQ(master.upload(0x1C12, 0, true).abort, 0x06010004u) << "CompleteAccess=false";
  auto list = master.info(OdListRequest{1});
  ASSERT_TRUE(list.response);
  EXPECT_EQ(std::get<OdList>(*list.response).indexes.size(), 23u);

  // Process data: 0x6040 (16) + 0x607A (32) out, 0x6041 (16) + 0x6064 (32) in.
  ASSERT_TRUE(od->set<std::uint16_t>(0x6041, 0, 0x0237).ok());
  ASSERT_TRUE(od->set<std::int32_t>(0x6064, 0, -123456).ok());
  seg.pollSlaves(0);
  std::vector<std::uint8_t> frame(12, 0);
  writeLe16(frame, 0, 0x000F);
  writeLe32(frame, 2, 1000);
  auto r = one(seg, Command::kLrw, 0, frame);
  EXPECT_EQ(r.wkc, 3);
  EXPECT_EQ(readLe16(r.data, 6), 0x0237);
  EXPECT_EQ(static_cast<std::int32_t>(readLe32(r.data, 8)), -123456);
  EXPECT_EQ(od->get<std::uint16_t>(0x6040, 0).value(), 0x000F);
  EXPECT_EQ(od->get<std::int32_t>(0x607A, 0).value(), 1000);
}

TEST(EsiSlave, SiiOnlyInputTerminalUsesAnInternalDictionary) {
  const auto path = esiDir() / "Beckhoff_EL1xxx_2011.xml";
  ECSIM_REQUIRE_SHARED(path);
  auto file = loadEsiFile(path);
  ASSERT_TRUE(file.ok());
  const EsiDevice* el1004 = findDevice(*file, "EL1004", 0x00100000);
  ASSERT_NE(el1004, nullptr);
  auto slave = build(*file, *el1004);
  ASSERT_NE(slave, nullptr);
  EXPECT_EQ(slavesim::coeServerOf(*slave), nullptr) << "no mailbox: nothing answers CoE";
  slavesim::coe::ObjectDictionary* od = slavesim::objectDictionaryOf(*slave);
  ASSERT_NE(od, nullptr);
  topology::Segment seg;
  seg.addSlave(std::move(slave));
  const Outcome o = driveLikeSoem(seg);
  ASSERT_EQ(o.reached, AlState::kOp) << o.reason;
  EXPECT_FALSE(o.coeMapping);
  EXPECT_EQ(o.inBytes, 1);
  // Channels 2 and 4 (0x6010:01, 0x6030:01) are bits 1 and 3 of the input byte.
  ASSERT_TRUE(od->set<bool>(0x6010, 1, true).ok());
  ASSERT_TRUE(od->set<bool>(0x6030, 1, true).ok());
  seg.pollSlaves(0);
  auto r = one(seg, Command::kLrw, 0, {0});
  EXPECT_EQ(r.wkc, 1);
  EXPECT_EQ(r.data[0], 0x0A);
}

// Issue #15 item 11: a PDO index CoE cannot hold (Beckhoff_EL1xxx_2011.xml, EL1262 rev
// #x00020000 at line 2652: TxPdo Sm="1" with Index #x1C00 at line 2784) is left out of the SII
// PDO categories as it is left out of the dictionary, so a master sizing the SMs from the SII
// asks for what the slave checks at PREOP->SAFEOP. Before: SII 7 bytes, slave 6, SAFEOP refused.
TEST(EsiSlave, PdoOutsideTheCoeRangeIsLeftOutOfSiiAndDictionaryAlike) {
  ECSIM_REQUIRE_SHARED(esiDir());
  const EsiFile* file = nullptr;
  for (const auto& [name, esi] : corpus().files) file = name == "Beckhoff_EL1xxx_2011.xml" ? &esi : file;
  ASSERT_NE(file, nullptr);
  const EsiDevice* el1262 = findDevice(*file, "EL1262", 0x00020000);
  ASSERT_NE(el1262, nullptr);
  auto slave = build(*file, *el1262);
  ASSERT_NE(slave, nullptr);
  auto image = SiiImage::parseLenient(slave->esc().sii());
  ASSERT_TRUE(image.ok());
  for (const SiiPdo& pdo : image->contents().txPdos) EXPECT_NE(pdo.index, 0x1C00);
  topology::Segment seg;
  seg.addSlave(std::move(slave));
  const Outcome o = driveLikeSoem(seg);
  EXPECT_EQ(o.reached, AlState::kOp) << o.reason;
}

// Issue #15 item 11: Enable="0" on the mailbox SMs is kept in the SII SM category (its enable
// byte, ETG.2010 SyncM category), while the standard mailbox words still describe the mailbox.
// A master that copies the SII enable byte into 0x0806 (SOEM ecx_config_init: SMflags = Creg +
// (Activate << 16)) leaves SM0/SM1 off, and the slave refuses PREOP with 0x0016 (invalid
// mailbox configuration) as an SSC slave does; a master that enables them (TwinCAT) gets PREOP.
TEST(EsiSlave, MailboxSmEnableZeroIsWhatTheSiiSays) {
  const std::string xml = R"(<EtherCATInfo><Vendor><Id>#x1337</Id></Vendor><Descriptions><Devices>
    <Device Physics="YY"><Type ProductCode="#x56" RevisionNo="#x1">Off</Type><Name>Off</Name>
    <Sm StartAddress="#x1000" ControlByte="#x26" Enable="0" DefaultSize="128">MBoxOut</Sm>
    <Sm StartAddress="#x1080" ControlByte="#x22" Enable="0" DefaultSize="128">MBoxIn</Sm>
    <Mailbox><CoE/></Mailbox></Device></Devices></Descriptions></EtherCATInfo>)";
  auto file = parseEsi(xml, "off.xml");
  ASSERT_TRUE(file.ok()) << file.error().message();
  for (const bool copyEnable : {true, false}) {
    auto slave = build(*file, file->devices.at(0));
    ASSERT_NE(slave, nullptr);
    auto image = SiiImage::parseLenient(slave->esc().sii());
    ASSERT_TRUE(image.ok());
    const SiiContents& sii = image->contents();
    ASSERT_GE(sii.syncManagers.size(), 2u);
    EXPECT_EQ(sii.syncManagers[0].enable & SiiSyncManagerEnable::kEnable, 0);
    EXPECT_EQ(sii.syncManagers[1].enable & SiiSyncManagerEnable::kEnable, 0);
    EXPECT_EQ(sii.standardMailbox.receiveOffset, 0x1000);
    topology::Segment seg;
    seg.addSlave(std::move(slave));
    one(seg, Command::kApwr, phys(0, reg::kConfiguredStationAddress.address), le16(kStation));
    for (unsigned sm = 0; sm < 2; ++sm) {
      const auto& c = sii.syncManagers[sm];
      one(seg, Command::kFpwr, phys(kStation, reg::smChannel(sm)),
          smRegisterBytes(c.startAddress, c.length, c.control,
                          copyEnable ? static_cast<std::uint8_t>(c.enable & SiiSyncManagerEnable::kEnable) : 1));
    }
    requestState(seg, kStation, 0x0002);
    if (copyEnable) {
      EXPECT_EQ(alStatus(seg, kStation), 0x0011) << "INIT with the error flag";
      EXPECT_EQ(alStatusCode(seg, kStation), 0x0016);
    } else {
      EXPECT_EQ(alStatus(seg, kStation), 0x0002);
    }
  }
}

TEST(EsiSlave, MailboxWithoutCoeAnswersUnsupportedProtocol) {
  const auto path = esiDir() / "Beckhoff_EtherCAT_Terminals.xml";
  ECSIM_REQUIRE_SHARED(path);
  auto file = loadEsiFile(path);
  ASSERT_TRUE(file.ok());
  const EsiDevice* el4102 = findDevice(*file, "EL4102", 0x270B0000);
  ASSERT_NE(el4102, nullptr);
  ASSERT_FALSE(el4102->mailbox.coe);
  auto slave = build(*file, *el4102);
  ASSERT_NE(slave, nullptr);
  slavesim::coe::ObjectDictionary* od = slavesim::objectDictionaryOf(*slave);
  topology::Segment seg;
  seg.addSlave(std::move(slave));
  const Outcome o = driveLikeSoem(seg);
  ASSERT_EQ(o.reached, AlState::kOp) << o.reason;
  EXPECT_EQ(o.outBytes, 4);
  auto r = one(seg, Command::kLrw, 0, {0x34, 0x12, 0x78, 0x56});
  EXPECT_EQ(r.wkc, 2);
  seg.pollSlaves(0);
  EXPECT_EQ(od->get<std::uint16_t>(0x6411, 1).value(), 0x1234);
  EXPECT_EQ(od->get<std::uint16_t>(0x6411, 2).value(), 0x5678);
  MailboxMaster master = mailboxMasterFor(seg);
  auto reply = master.transact(master.sdoRequest(SdoInitiateUploadRequest{0x1018, 2, false}));
  ASSERT_TRUE(reply);
  EXPECT_EQ((*reply)[5] & 0x0F, 0) << "mailbox error";
  EXPECT_EQ(readLe16(*reply, 8), 0x0002) << "unsupported protocol";
}

TEST(EsiSlave, VendorEepromImageIsUsedAsItIs) {
  const std::vector<std::uint8_t> image = makeSii(0x1337, 0x55, 0x1000, 64, 0x1040, 64);
  std::string hexImage;
  for (std::uint8_t b : image) {
    constexpr char kDigits[] = "0123456789ABCDEF";
    hexImage += kDigits[b >> 4];
    hexImage += kDigits[b & 0x0F];
  }
  const std::string xml = R"(<EtherCATInfo><Vendor><Id>#x1337</Id></Vendor><Descriptions><Devices>
    <Device Physics="YY"><Type ProductCode="#x55" RevisionNo="#x1">Imaged</Type><Name>Imaged</Name>
    <Sm StartAddress="#x1000" ControlByte="#x26" Enable="1" DefaultSize="128">MBoxOut</Sm>
    <Sm StartAddress="#x1080" ControlByte="#x22" Enable="1" DefaultSize="128">MBoxIn</Sm>
    <Mailbox><CoE/></Mailbox><Eeprom><Data>)" +
                          hexImage +
                          R"(</Data></Eeprom></Device></Devices></Descriptions></EtherCATInfo>)";
  auto file = parseEsi(xml, "imaged.xml");
  ASSERT_TRUE(file.ok()) << file.error().message();
  auto slave = build(*file, file->devices.at(0));
  ASSERT_NE(slave, nullptr);
  EXPECT_EQ(slave->esc().sii(), image);
  ASSERT_TRUE(slave->profile().mailbox.has_value());
  EXPECT_EQ(slave->profile().mailbox->outSize, 64) << "the image's mailbox, not the ESI's";
  EXPECT_EQ(slave->profile().mailbox->inStart, 0x1040);
  EXPECT_EQ(slavesim::objectDictionaryOf(*slave)->get<std::uint32_t>(0x1018, 4).value(), 0x1234u)
      << "0x1018 follows the image's serial";
}

TEST(EsiSlave, EscTypeFollowsTheDevicesNeeds) {
  const auto ek = esiDir() / "Beckhoff_EK11xx.xml";
  const auto ur20 = esiDir() / "Weidmueller_UR20_FBC.xml";
  const auto stmbl = esiDir() / "STMBL_ECAT.xml";
  ECSIM_REQUIRE_SHARED(ek);
  ECSIM_REQUIRE_SHARED(ur20);
  ECSIM_REQUIRE_SHARED(stmbl);
  auto couplers = loadEsiFile(ek);
  auto fbc = loadEsiFile(ur20);
  auto servo = loadEsiFile(stmbl);
  ASSERT_TRUE(couplers.ok() && fbc.ok() && servo.ok());
  const EsiDevice* ek1100 = findDevice(*couplers, "EK1100", 0x00100000);
  ASSERT_NE(ek1100, nullptr);
  EXPECT_EQ(slavesim::chooseEscType(*ek1100).kind, slavesim::EscKind::kEt1100) << "3 ports";
  EXPECT_EQ(slavesim::chooseEscType(fbc->devices.at(0)).kind, slavesim::EscKind::kEt1100)
      << "inputs SM at 0x2400, beyond 4 KB";
  EXPECT_EQ(slavesim::chooseEscType(servo->devices.at(0)).kind, slavesim::EscKind::kLan9252);
  slavesim::EsiSlaveOptions options;
  options.escType = slavesim::kEt1200;
  auto slave = slavesim::makeSlaveFromEsi(*servo, servo->devices.at(0), "stmbl", options);
  ASSERT_TRUE(slave.ok());
  EXPECT_EQ((*slave)->esc().type().kind, slavesim::EscKind::kEt1200) << "the caller decides";
}
}  // namespace
}  // namespace ecsim::testing
