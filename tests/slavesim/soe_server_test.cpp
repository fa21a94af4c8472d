// SoE server (slavesim/soe/soe_server.hpp) through frames: a master writes SoE requests into
// SM0 and reads the answers from SM1 as SOEM's ecx_SoEread / ecx_SoEwrite do
// (soem/ethercatsoe.c v1.4), against the IDNs of the real AX5021 dictionary
// (../shared/esi/Beckhoff_AX5021-xxxx-0001_Dict.xml), 128-byte mailboxes.
#include <gtest/gtest.h>

#include "config/esi.hpp"
#include "protocol/soe.hpp"
#include "slavesim/soe/soe_server.hpp"
#include "tests/slavesim/coe_test_support.hpp"

namespace ecsim::testing {
namespace {

using slavesim::soe::IdnDictionary;
using slavesim::soe::SoeServer;

const std::filesystem::path kDict = sharedDir() / "esi" / "Beckhoff_AX5021-xxxx-0001_Dict.xml";

struct Reply {
  SoeHeader header;
  std::vector<std::uint8_t> data;  // fragments joined
  int fragments{0};
};

struct SoeSlave {
  CoeTestSlave t;
  SoeServer* server{nullptr};
  std::vector<std::string> warnings;

  explicit SoeSlave(std::size_t drives = 1) {
    auto file = loadEsiFile(kDict);
    EXPECT_TRUE(file.ok()) << (file.ok() ? "" : file.error().message());
    std::vector<IdnDictionary> d;
    for (std::size_t i = 0; i < drives && file.ok(); ++i) {
      d.push_back(slavesim::soe::buildIdnDictionary(file->dictionary, kDict.string(), &warnings));
    }
    auto s = std::make_unique<SoeServer>(std::move(d));
    server = s.get();
    t.server->addProtocol(std::move(s));
  }

  std::vector<std::uint8_t> request(SoeOpcode op, std::uint8_t elements, std::uint16_t idn,
                                    ConstBytes data = {}, std::uint8_t drive = 0,
                                    bool incomplete = false) {
    SoeHeader h;
    h.opcode = op;
    h.elements = elements;
    h.idn = idn;
    h.driveNo = drive;
    h.incomplete = incomplete;
    MailboxHeader mh;
    mh.counter = t.master->nextCounter();
    auto m = encodeSoeMailbox(h, data, mh);
    EXPECT_TRUE(m.ok());
    return m.ok() ? *m : std::vector<std::uint8_t>{};
  }

  // One request; the response's fragments read until one without `incomplete`.
  std::optional<Reply> transact(const std::vector<std::uint8_t>& message) {
    auto raw = t.master->transact(message);
    Reply r;
    while (raw) {
      auto m = decodeSoeMailbox(*raw);
      EXPECT_TRUE(m.ok());
      if (!m.ok()) return std::nullopt;
      ++r.fragments;
      r.header = m->soe;
      r.data.insert(r.data.end(), m->data.begin(), m->data.end());
      if (!m->soe.incomplete) return r;
      raw = t.master->receive();
    }
    return std::nullopt;
  }
  std::optional<Reply> read(std::uint8_t elements, std::uint16_t idn, std::uint8_t drive = 0) {
    return transact(request(SoeOpcode::kReadRequest, elements, idn, {}, drive));
  }
  std::optional<Reply> write(std::uint16_t idn, std::vector<std::uint8_t> value) {
    return transact(request(SoeOpcode::kWriteRequest, soe_element::kValue, idn, value));
  }
  static std::uint16_t errorOf(const Reply& r) {
    return r.header.error && r.data.size() >= 2 ? readLe16(r.data, r.data.size() - 2) : 0;
  }
};

TEST(SoeServer, ReadsAnIdnWithAllItsElementsFromTheDictionary) {
  ECSIM_REQUIRE_SHARED(kDict);
  SoeSlave s;
  // S-0-0001 Control unit cycle time: name, #x60110001, "us", 62..20000, default 500.
  const std::uint8_t all = soe_element::kName | soe_element::kAttribute | soe_element::kUnit |
                           soe_element::kMinimum | soe_element::kMaximum | soe_element::kValue |
                           soe_element::kDefault;
  auto r = s.read(all, 1);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->header.opcode, SoeOpcode::kReadResponse);
  EXPECT_FALSE(r->header.error);
  EXPECT_EQ(r->header.elements, all) << "SOEM checks the elements of the response";
  EXPECT_EQ(r->header.idn, 1);
  auto e = splitSoeElements(all, r->data);
  ASSERT_TRUE(e.ok()) << e.error().message();
  EXPECT_EQ(e->name, "Control unit cycle time (TNcyc)");
  EXPECT_EQ(e->attribute.raw, 0x60110001u);
  EXPECT_EQ(e->unit, "us");
  EXPECT_EQ(readLe16(e->minimum, 0), 62);
  EXPECT_EQ(readLe16(e->maximum, 0), 20000);
  EXPECT_EQ(readLe16(e->value, 0), 500);
  EXPECT_EQ(readLe16(e->defaultValue, 0), 500);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
}

TEST(SoeServer, ListOfAllIdnsComesInFragmentsAndNamesEveryDictionaryObject) {
  ECSIM_REQUIRE_SHARED(kDict);
  SoeSlave s;
  auto r = s.read(soe_element::kValue, 17);
  ASSERT_TRUE(r);
  // 119 IDNs: 4 + 238 bytes, 118 data bytes per 128-byte mailbox -> 3 fragments.
  EXPECT_EQ(r->fragments, 3);
  EXPECT_EQ(r->header.idn, 17) << "the last fragment carries the IDN";
  auto list = decodeSoeList(r->data);
  ASSERT_TRUE(list.ok());
  EXPECT_EQ(list->currentLength, 238);
  EXPECT_EQ(list->maxLength, 238);
  EXPECT_EQ(readLe16(list->data, 0), 1);        // S-0-0001 first
  EXPECT_EQ(readLe16(list->data, 236), 33790);  // P-0-1022 Debug command last
  EXPECT_EQ(s.server->counters().fragmentsSent, 2u);
}

TEST(SoeServer, AtAndMdtConfigurationListsAreWhatSoemSizesTheProcessDataFrom) {
  ECSIM_REQUIRE_SHARED(kDict);
  SoeSlave s;
  auto configurable = s.read(soe_element::kValue, 187);
  ASSERT_TRUE(configurable);
  auto c = decodeSoeList(configurable->data);
  ASSERT_TRUE(c.ok());
  EXPECT_EQ(c->currentLength, 2 * 18) << "the 18 IDNs with <PdoMapping>T";
  auto at = s.read(soe_element::kValue, 16);
  ASSERT_TRUE(at);
  auto a = decodeSoeList(at->data);
  ASSERT_TRUE(a.ok());
  EXPECT_EQ(a->maxLength, 32);
  EXPECT_EQ(a->currentLength, 32) << "as many as fit, S-0-0135 left out";
  EXPECT_EQ(readLe16(a->data, 0), 11);
  // The attribute of each AT IDN says its size (SOEM: 8 << length, lists skipped).
  auto attr = s.read(soe_element::kAttribute, 381);
  ASSERT_TRUE(attr);
  EXPECT_EQ(readLe32(attr->data, 0), 0x73220001u);
  // The MDT has only the control word, which travels outside the list: empty.
  auto mdt = s.read(soe_element::kValue, 24);
  ASSERT_TRUE(mdt);
  EXPECT_EQ(readLe16(mdt->data, 0), 0);

  // A master configures the AT in PREOP: accepted when configurable, else 0x7008.
  std::vector<std::uint8_t> mine =
      encodeSoeList(std::vector<std::uint8_t>{0x7C, 0x01}, 0);  // S-0-0380
  auto ok = s.write(16, mine);
  ASSERT_TRUE(ok);
  EXPECT_FALSE(ok->header.error) << std::hex << SoeSlave::errorOf(*ok);
  EXPECT_EQ(ok->header.opcode, SoeOpcode::kWriteResponse);
  auto back = s.read(soe_element::kValue, 16);
  EXPECT_EQ(back->data, (std::vector<std::uint8_t>{2, 0, 32, 0, 0x7C, 0x01}));
  auto refused = s.write(16, encodeSoeList(std::vector<std::uint8_t>{0x01, 0x00}, 0));  // S-0-0001
  ASSERT_TRUE(refused);
  EXPECT_EQ(SoeSlave::errorOf(*refused), 0x7008);
}

TEST(SoeServer, WriteChecksAccessPerStateLengthAndLimits) {
  ECSIM_REQUIRE_SHARED(kDict);
  SoeSlave s;
  // S-0-0001 writable in PREOP (#x60110001 protects CP3/CP4).
  auto ok = s.write(1, le16(1000));
  ASSERT_TRUE(ok);
  EXPECT_FALSE(ok->header.error);
  EXPECT_EQ(readLe16(s.read(soe_element::kValue, 1)->data, 0), 1000);
  EXPECT_EQ(SoeSlave::errorOf(*s.write(1, le16(61))), 0x7006) << "below MinValue 62";
  EXPECT_EQ(SoeSlave::errorOf(*s.write(1, le16(20001))), 0x7007) << "above MaxValue 20000";
  EXPECT_EQ(SoeSlave::errorOf(*s.write(1, {1})), 0x7002);
  EXPECT_EQ(SoeSlave::errorOf(*s.write(1, {1, 2, 3})), 0x7003);
  // S-0-0380 DC bus voltage #x71110001: read-only.
  EXPECT_EQ(SoeSlave::errorOf(*s.write(380, le16(5))), 0x7004);
  // The name is never writable.
  auto name = s.transact(s.request(SoeOpcode::kWriteRequest, soe_element::kName, 1,
                                   std::vector<std::uint8_t>{1, 0, 1, 0, 'x'}));
  ASSERT_TRUE(name);
  EXPECT_EQ(name->header.opcode, SoeOpcode::kWriteResponse);
  EXPECT_EQ(SoeSlave::errorOf(*name), 0x2004);
  // SAFEOP = CP3: S-0-0001 is write-protected now.
  ASSERT_EQ(s.t.toSafeOp(), 0x0004);
  EXPECT_EQ(SoeSlave::errorOf(*s.write(1, le16(1000))), 0x7005);
  // P-0-0302 Display value line 1 #x00210001 has no protection: still writable.
  EXPECT_FALSE(s.write(33070, le16(3))->header.error);
}

TEST(SoeServer, UnknownIdnMissingElementAndDriveAreErrors) {
  ECSIM_REQUIRE_SHARED(kDict);
  SoeSlave s;
  auto none = s.read(soe_element::kValue, 47);  // S-0-0047: not an AX5021 IDN
  ASSERT_TRUE(none);
  EXPECT_TRUE(none->header.error);
  EXPECT_EQ(none->header.opcode, SoeOpcode::kReadResponse);
  EXPECT_EQ(SoeSlave::errorOf(*none), 0x1001);
  EXPECT_EQ(SoeSlave::errorOf(*s.read(soe_element::kUnit, 16)), 0x4001) << "a list has no unit";
  EXPECT_EQ(SoeSlave::errorOf(*s.read(soe_element::kDefault, 380)), 0x8001);
  EXPECT_EQ(SoeSlave::errorOf(*s.read(soe_element::kValue, 1, 1)), 0x800A)
      << "SOEM's ecx_readIDNmap asks drives 1-7 too";
  EXPECT_EQ(SoeSlave::errorOf(*s.read(0, 1)), 0x800C);
}

TEST(SoeServer, ProcedureCommandRunsAndReportsItsState) {
  ECSIM_REQUIRE_SHARED(kDict);
  SoeSlave s;
  auto list = s.read(soe_element::kValue, 25);
  auto commands = decodeSoeList(list->data);
  ASSERT_TRUE(commands.ok());
  EXPECT_EQ(readLe16(commands->data, 0), 99) << "S-0-0099 first of the procedure commands";
  s.server->drive(0).find(11)->value = le16(0x0002);  // an amplifier overtemperature C1D
  auto state = [&] { return readLe16(s.read(soe_element::kDataState, 99)->data, 0); };
  EXPECT_EQ(state(), 0x0);
  EXPECT_FALSE(s.write(99, le16(3))->header.error);
  EXPECT_EQ(state(), 0x7) << "in progress";
  EXPECT_EQ(SoeSlave::errorOf(*s.write(99, le16(3))), 0x7010);
  s.t.seg.pollSlaves(SoeServer::kCommandDuration);
  EXPECT_EQ(state(), 0x3) << "executed correctly";
  EXPECT_EQ(readLe16(s.read(soe_element::kValue, 11)->data, 0), 0) << "C1D reset";
  EXPECT_FALSE(s.write(99, le16(0))->header.error);
  EXPECT_EQ(state(), 0x0) << "the master cancels it after execution";
  EXPECT_EQ(SoeSlave::errorOf(*s.write(99, le16(2))), 0x7013);
}

TEST(SoeServer, FragmentedWriteIsCollectedAndAnsweredOnce) {
  ECSIM_REQUIRE_SHARED(kDict);
  SoeSlave s;
  // S-0-0016 with 2 IDNs, sent as SOEM's ecx_SoEwrite splits it: 4 bytes, then 4.
  const std::vector<std::uint8_t> value{4, 0, 32, 0, 0x0B, 0x00, 0x7C, 0x01};
  ASSERT_EQ(s.t.master->send(s.request(SoeOpcode::kWriteRequest, soe_element::kValue, 1,
                                       ConstBytes(value).first(4), 0, true)),
            1);
  s.t.seg.pollSlaves(0);
  EXPECT_FALSE(s.t.master->receive(2)) << "no answer to a fragment";
  auto last = s.transact(
      s.request(SoeOpcode::kWriteRequest, soe_element::kValue, 16, ConstBytes(value).subspan(4)));
  ASSERT_TRUE(last);
  EXPECT_FALSE(last->header.error) << std::hex << SoeSlave::errorOf(*last);
  EXPECT_EQ(s.read(soe_element::kValue, 16)->data, value);
  EXPECT_EQ(s.server->counters().fragmentsReceived, 1u);
}

TEST(SoeServer, EachDriveHasItsOwnIdns) {
  ECSIM_REQUIRE_SHARED(kDict);
  SoeSlave s(2);
  EXPECT_FALSE(s.write(1, le16(250))->header.error);
  auto d1 = s.read(soe_element::kValue, 1, 1);
  ASSERT_TRUE(d1);
  EXPECT_FALSE(d1->header.error);
  EXPECT_EQ(d1->header.driveNo, 1);
  EXPECT_EQ(readLe16(d1->data, 0), 500) << "drive 1 keeps its default";
}

}  // namespace
}  // namespace ecsim::testing
