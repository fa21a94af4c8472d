// SoE wire format (ETG.1000.6 §5.9). No SoE capture is in ../shared/pcap, so the byte layouts
// below are the ones SOEM v1.4 builds (soem/ethercatsoe.c, ec_SoEt: opCode:3, incomplete:1,
// error:1, driveNo:3, elementflags, idn/fragmentsleft; ecx_SoEread asks S-0-0024 with
// elementflags EC_SOE_VALUE_B = 0x40), and the attributes are the AX5021 dictionary's
// (../shared/esi/Beckhoff_AX5021-xxxx-0001_Dict.xml) read with SOEM's ec_SoEattributet.
#include "protocol/soe.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace ecsim {
namespace {

TEST(SoeHeader, DecodesTheRequestSoemSendsForTheMdtConfiguration) {
  // ecx_readIDNmap: ecx_SoEread(driveNr 1, EC_SOE_VALUE_B, EC_IDN_MDTCONFIG), counter 2.
  const std::vector<std::uint8_t> wire{0x04, 0x00, 0x00, 0x00, 0x00, 0x25, 0x21, 0x40, 0x18, 0x00};
  auto m = decodeSoeMailbox(wire);
  ASSERT_TRUE(m.ok()) << m.error().message();
  EXPECT_EQ(m->mailbox.type, MailboxType::kSoe);
  EXPECT_EQ(m->mailbox.counter, 2);
  EXPECT_EQ(m->soe.opcode, SoeOpcode::kReadRequest);
  EXPECT_EQ(m->soe.driveNo, 1);
  EXPECT_FALSE(m->soe.incomplete);
  EXPECT_FALSE(m->soe.error);
  EXPECT_EQ(m->soe.elements, soe_element::kValue);
  EXPECT_EQ(m->soe.idn, 24);
  EXPECT_TRUE(m->data.empty());

  SoeHeader h = m->soe;
  MailboxHeader mh;
  mh.counter = 2;
  auto again = encodeSoeMailbox(h, {}, mh);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(*again, wire);
}

TEST(SoeHeader, IncompleteFragmentCarriesFragmentsLeftAndErrorCarriesTheCodeLast) {
  SoeHeader h;
  h.opcode = SoeOpcode::kReadResponse;
  h.incomplete = true;
  h.driveNo = 7;
  h.elements = soe_element::kValue;
  h.idn = 3;  // fragments left
  std::uint8_t raw[4];
  ASSERT_TRUE(h.encode(raw).ok());
  EXPECT_EQ(raw[0], 0x02 | 0x08 | (7 << 5));
  EXPECT_EQ(raw[3], 0x00);
  EXPECT_EQ(raw[2], 0x03);
  h.driveNo = 8;
  EXPECT_FALSE(h.encode(raw).ok()) << "the drive number has 3 bits";

  SoeHeader write;
  write.opcode = SoeOpcode::kWriteRequest;
  write.elements = soe_element::kValue;
  write.idn = 0x8009;
  auto error = encodeSoeError(write, soe_error::kDataWriteProtectedNow);
  ASSERT_TRUE(error.ok());
  auto m = decodeSoeMailbox(*error);
  ASSERT_TRUE(m.ok());
  EXPECT_EQ(m->soe.opcode, SoeOpcode::kWriteResponse);
  EXPECT_TRUE(m->soe.error);
  EXPECT_EQ(m->soe.idn, 0x8009);
  // SOEM: errorcode = last 2 bytes of the mailbox (length + header size - 2).
  ASSERT_EQ(m->data.size(), 2u);
  EXPECT_EQ(readLe16(m->data, 0), 0x7005);
  EXPECT_EQ(soeErrorText(0x7005), "Operation data is write-protected at this time (state)");
}

TEST(SoeHeader, ShortOrForeignMailboxIsRefusedWithTheByte) {
  const std::vector<std::uint8_t> shortSoe{0x02, 0x00, 0x00, 0x00, 0x00, 0x15, 0x01, 0x40};
  auto m = decodeSoeMailbox(shortSoe);
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.error().context.find("byte 8"), std::string::npos) << m.error().context;
  const std::vector<std::uint8_t> coe{0x04, 0x00, 0x00, 0x00, 0x00, 0x13, 0x01, 0x40, 0x10, 0x00};
  EXPECT_FALSE(decodeSoeMailbox(coe).ok());
}

TEST(SoeIdn, FormatsAndParsesBothParameterSets) {
  EXPECT_EQ(formatIdn(16), "S-0-0016");
  EXPECT_EQ(formatIdn(32777), "P-0-0009");  // the dictionary's <Index>32777 is P-0-0009
  EXPECT_EQ(formatIdn(0x8000 | (2 << 12) | 300), "P-2-0300");
  EXPECT_EQ(*parseIdn("S-0-0016"), 16);
  EXPECT_EQ(*parseIdn("p-0-9"), 0x8009);
  EXPECT_EQ(*parseIdn("0x8009"), 0x8009);
  EXPECT_EQ(*parseIdn("47"), 47);
  auto bad = parseIdn("S-8-0001");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().context.find("parameter set must be 0-7"), std::string::npos);
  EXPECT_FALSE(parseIdn("S-0-4096").ok());
  EXPECT_FALSE(parseIdn("X-0-1").ok());
}

TEST(SoeAttribute, ReadsTheDictionaryAttributesAsSoemDoes) {
  // S-0-0001 #x60110001: u16, unsigned, writable in PREOP only (write-protected CP3, CP4).
  SoeAttribute cycle{0x60110001};
  EXPECT_EQ(cycle.elementSize(), 2u);
  EXPECT_FALSE(cycle.isList());
  EXPECT_EQ(cycle.dataType(), SoeDataType::kUnsigned);
  EXPECT_FALSE(cycle.writeProtectedInPhase(2));
  EXPECT_TRUE(cycle.writeProtectedInPhase(3));
  EXPECT_TRUE(cycle.writeProtectedInPhase(4));
  EXPECT_EQ(cycle.conversionFactor(), 1);
  // S-0-0016 #x60550001: a list of 2-byte IDNs.
  SoeAttribute at{0x60550001};
  EXPECT_TRUE(at.isList());
  EXPECT_EQ(at.elementSize(), 2u);
  EXPECT_EQ(at.dataType(), SoeDataType::kIdn);
  EXPECT_EQ(at.describe(), "IDN list");
  // S-0-0030 #x70440001: text, read-only.
  SoeAttribute text{0x70440001};
  EXPECT_EQ(text.dataType(), SoeDataType::kText);
  EXPECT_TRUE(text.isList());
  EXPECT_EQ(text.elementSize(), 1u);
  EXPECT_TRUE(text.readOnly());
  // S-0-0099 #x00090001: procedure command, 2 bytes.
  SoeAttribute command{0x00090001};
  EXPECT_TRUE(command.isProcedureCommand());
  EXPECT_EQ(command.elementSize(), 2u);
  // S-0-0381 #x73220001: i32 with 3 decimals.
  SoeAttribute current{0x73220001};
  EXPECT_EQ(current.describe(), "i32");
  EXPECT_EQ(current.decimals(), 3u);
  EXPECT_EQ(SoeAttribute::make(2, true, false, SoeDataType::kIdn, false, true, true).raw,
            0x60550000u);
}

TEST(SoeElements, SplitsAReadResponseInElementOrder) {
  std::vector<std::uint8_t> data{0x03, 0x00};  // data state
  for (std::uint8_t b : encodeSoeList(std::vector<std::uint8_t>{'A', 'T'}, 2)) data.push_back(b);
  for (int b : {0x01, 0x00, 0x55, 0x60}) data.push_back(static_cast<std::uint8_t>(b));  // attribute
  for (std::uint8_t b : encodeSoeList(std::vector<std::uint8_t>{0x0B, 0x00}, 32)) data.push_back(b);
  auto e = splitSoeElements(
      soe_element::kDataState | soe_element::kName | soe_element::kAttribute | soe_element::kValue,
      data);
  ASSERT_TRUE(e.ok()) << e.error().message();
  EXPECT_EQ(e->dataState, 3);
  EXPECT_EQ(e->name, "AT");
  EXPECT_EQ(e->attribute.raw, 0x60550001u);
  auto list = decodeSoeList(e->value);
  ASSERT_TRUE(list.ok());
  EXPECT_EQ(list->currentLength, 2);
  EXPECT_EQ(list->maxLength, 32);
  EXPECT_EQ(readLe16(list->data, 0), 11);

  // A fixed-length value needs the attribute: 2 bytes for #x60110001.
  std::vector<std::uint8_t> u16{0xF4, 0x01};
  auto v = splitSoeElements(soe_element::kValue, u16, SoeAttribute{0x60110001});
  ASSERT_TRUE(v.ok());
  EXPECT_EQ(readLe16(v->value, 0), 500);
  auto extra = splitSoeElements(soe_element::kValue, std::vector<std::uint8_t>{1, 2, 3},
                                SoeAttribute{0x60110001});
  EXPECT_FALSE(extra.ok()) << "a byte left over is an error";
  auto cut = decodeSoeList(std::vector<std::uint8_t>{4, 0, 4, 0, 1});
  ASSERT_FALSE(cut.ok());
  EXPECT_NE(cut.error().context.find("runs past"), std::string::npos);
}

// The value of one element, as the server compares it with its limits and ecmaster shows it.
TEST(SoeNumber, LittleEndianAndSignExtendedOnlyWhenSigned) {
  const std::vector<std::uint8_t> minus2{0xFE, 0xFF};
  EXPECT_EQ(soeNumber(minus2, true), -2);
  EXPECT_EQ(soeNumber(minus2, false), 0xFFFE);
  const std::vector<std::uint8_t> four{0x78, 0x56, 0x34, 0x12};
  EXPECT_EQ(soeNumber(four, true), 0x12345678);
  const std::vector<std::uint8_t> eight(8, 0xFF);
  EXPECT_EQ(soeNumber(eight, true), -1);
  EXPECT_EQ(static_cast<std::uint64_t>(soeNumber(eight, false)), ~std::uint64_t{0});
  EXPECT_EQ(soeNumber(ConstBytes{}, true), 0);
}

}  // namespace
}  // namespace ecsim
