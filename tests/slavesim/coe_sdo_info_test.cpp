// SDO information through a real Segment (ETG.1000.6 §5.6.3), in the layout SOEM parses
// (notes/soem-interop.md §3.5): OD list fragmented over small mailboxes, object and entry
// descriptions, SDO-information errors.
#include <gtest/gtest.h>

#include "tests/slavesim/coe_test_support.hpp"

namespace ecsim::testing {
namespace {

std::vector<std::uint16_t> allIndexes(const slavesim::coe::ObjectDictionary& od) {
  std::vector<std::uint16_t> out;
  for (const auto& [index, object] : od.objects()) out.push_back(index);
  return out;
}

TEST(CoeSdoInfo, OdListIsFragmentedOverASmallMailbox) {
  CoeTestSlave t(32);  // 32-byte mailbox: 20 bytes of service data per fragment
  auto reply = t.master->info(OdListRequest{1});
  ASSERT_TRUE(reply.response);
  const auto* list = std::get_if<OdList>(&*reply.response);
  ASSERT_NE(list, nullptr);
  EXPECT_EQ(list->listType, 1);
  EXPECT_EQ(list->indexes, allIndexes(*t.od));
  const std::size_t bytes = 2 + 2 * t.od->size();
  EXPECT_EQ(reply.fragments, static_cast<int>((bytes + 19) / 20));
  ASSERT_GE(reply.fragments, 3);
  // SOEM's parse: every fragment's mailbox length is 6 + its data, fragments-left counts down,
  // the first fragment carries the list type before the indexes.
  const auto& first = reply.raw.front();
  EXPECT_EQ(first[8], 0x82) << "opcode 2 with the incomplete bit";
  EXPECT_EQ(readLe16(first, 10), reply.fragments - 1);
  EXPECT_EQ(readLe16(first, 12), 1) << "list type";
  EXPECT_EQ(readLe16(first, 14), 0x1000) << "first index";
  EXPECT_EQ(readLe16(first, 0), 26) << "mbx length = 2 CoE + 4 info + 20 data";
  const auto& last = reply.raw.back();
  EXPECT_EQ(last[8], 0x02);
  EXPECT_EQ(readLe16(last, 10), 0);
}

TEST(CoeSdoInfo, OdListOfOtherTypes) {
  CoeTestSlave t;
  auto rx = t.master->info(OdListRequest{2});
  ASSERT_TRUE(rx.response);
  EXPECT_EQ(std::get<OdList>(*rx.response).indexes, (std::vector<std::uint16_t>{0x7000}));
  auto tx = t.master->info(OdListRequest{3});
  EXPECT_EQ(std::get<OdList>(*tx.response).indexes, (std::vector<std::uint16_t>{0x6000}));
  auto lengths = t.master->info(OdListRequest{0});
  EXPECT_EQ(std::get<OdList>(*lengths.response).indexes,
            (std::vector<std::uint16_t>{static_cast<std::uint16_t>(t.od->size()), 1, 1, 0, 0}));
}

TEST(CoeSdoInfo, ObjectDescriptions) {
  CoeTestSlave t;
  struct Case {
    std::uint16_t index;
    std::uint16_t dataType;
    std::uint8_t maxSub;
    ObjectCode code;
    const char* name;
  };
  const Case cases[] = {
      {0x1000, 0x0007, 0, ObjectCode::kVar, "Device type"},
      {0x1018, 0x0023, 4, ObjectCode::kRecord, "Identity"},
      {0x1C12, 0x0006, 2, ObjectCode::kArray, "Sync manager 2 PDO assignment"},
      {0x1600, 0x0021, 4, ObjectCode::kRecord, "Outputs A"},
      {0x1C32, 0x0029, 12, ObjectCode::kRecord, "SM output parameter"},
  };
  for (const Case& c : cases) {
    auto reply = t.master->info(ObjectDescriptionRequest{c.index});
    ASSERT_TRUE(reply.response) << std::hex << c.index;
    const auto& d = std::get<ObjectDescription>(*reply.response);
    EXPECT_EQ(d.index, c.index);
    EXPECT_EQ(d.dataType, c.dataType) << std::hex << c.index;
    EXPECT_EQ(d.maxSubindex, c.maxSub) << std::hex << c.index;
    EXPECT_EQ(d.objectCode, static_cast<std::uint8_t>(c.code)) << std::hex << c.index;
    EXPECT_EQ(d.name, c.name);
    // SOEM: name length = mbx length - 12.
    EXPECT_EQ(readLe16(reply.raw.front(), 0) - 12u, std::string(c.name).size());
  }
}

TEST(CoeSdoInfo, EntryDescriptionAsSoemAsksForIt) {
  CoeTestSlave t;
  auto reply = t.master->info(EntryDescriptionRequest{0x1018, 2, 0x07});
  ASSERT_TRUE(reply.response);
  const auto& d = std::get<EntryDescription>(*reply.response);
  EXPECT_EQ(d.dataType, 0x0007);
  EXPECT_EQ(d.bitLength, 32);
  EXPECT_EQ(d.objectAccess, 0x0007) << "read in PREOP, SAFEOP, OP";
  EXPECT_EQ(d.name, "Product code");
  // The name follows the access word directly: data offset 12 + 10 = byte 22, length
  // mbx length - 16 (notes/soem-interop.md §3.5).
  const auto& raw = reply.raw.front();
  EXPECT_EQ(readLe16(raw, 0) - 16u, d.name.size());
  EXPECT_EQ(std::string(raw.begin() + 22, raw.begin() + 22 + 12), "Product code");

  auto out = t.master->info(EntryDescriptionRequest{0x7000, 2, 0x07});
  const auto& bits = std::get<EntryDescription>(*out.response);
  EXPECT_EQ(bits.dataType, 0x0032) << "BIT3";
  EXPECT_EQ(bits.bitLength, 3);
  EXPECT_EQ(bits.objectAccess, 0x003F | 0x0040) << "rw in all states, RX mappable";
  auto assign = t.master->info(EntryDescriptionRequest{0x1C12, 1, 0x07});
  EXPECT_EQ(std::get<EntryDescription>(*assign.response).objectAccess, 0x000F)
      << "read always, write in PREOP only";
}

TEST(CoeSdoInfo, EntryDescriptionWithDefaultAndLimits) {
  CoeTestSlave t;
  auto reply = t.master->info(EntryDescriptionRequest{0x2000, 0, 0x78});
  ASSERT_TRUE(reply.response);
  const auto& d = std::get<EntryDescription>(*reply.response);
  EXPECT_EQ(d.valueInfo, 0x78);
  EXPECT_EQ(d.unitType, 0);
  EXPECT_EQ(d.defaultValue, (std::vector<std::uint8_t>{0}));
  EXPECT_EQ(d.minimumValue, (std::vector<std::uint8_t>{10}));
  EXPECT_EQ(d.maximumValue, (std::vector<std::uint8_t>{200}));
  auto noLimits = t.master->info(EntryDescriptionRequest{0x2001, 0, 0x60});
  EXPECT_EQ(std::get<EntryDescription>(*noLimits.response).valueInfo, 0x00)
      << "limits the entry does not have are left out and their bits cleared";
}

TEST(CoeSdoInfo, Errors) {
  CoeTestSlave t;
  auto reply = t.master->info(ObjectDescriptionRequest{0x5555});
  ASSERT_TRUE(reply.response);
  EXPECT_EQ(std::get<SdoInfoError>(*reply.response).abortCode, 0x06020000u);
  reply = t.master->info(EntryDescriptionRequest{0x1018, 7, 0x07});
  EXPECT_EQ(std::get<SdoInfoError>(*reply.response).abortCode, 0x06090011u);
  reply = t.master->info(OdListRequest{9});
  EXPECT_EQ(std::get<SdoInfoError>(*reply.response).abortCode, 0x06090030u);
  // An SDO-information error keeps its own service (8) and opcode 7 (ETG.1000.6 SDO
  // information services); it is not an SDO abort.
  ASSERT_EQ(reply.raw.size(), 1u);
  EXPECT_EQ(readLe16(reply.raw.front(), 6) >> 12, 8);
  EXPECT_EQ(reply.raw.front()[8] & 0x7F, 0x07);
}

TEST(CoeSdoInfo, NotServedWhenTheDeviceHasNoSdoInfo) {
  slavesim::coe::CoeServerOptions options;
  options.sdoInfo = false;
  CoeTestSlave t(128, options);
  auto reply = t.master->info(OdListRequest{1});
  EXPECT_FALSE(reply.response);
  ASSERT_EQ(reply.raw.size(), 1u);
  EXPECT_EQ(reply.raw.front()[5] & 0x0F, 0) << "mailbox error reply";
  EXPECT_EQ(readLe16(reply.raw.front(), 8), 0x0004) << "service not supported";
}

}  // namespace
}  // namespace ecsim::testing
