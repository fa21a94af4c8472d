// ESI value syntax: numbers, booleans, hex binary, text helpers.
#include <gtest/gtest.h>

#include "config/esi.hpp"

namespace ecsim {
namespace {

TEST(EsiInteger, AcceptsTheThreeNotationsOfRealFiles) {
  EXPECT_EQ(*parseEsiInteger("#x1A00"), 0x1A00);  // ETG style
  EXPECT_EQ(*parseEsiInteger("#x300"), 0x300);    // 3 digits (STMBL_ECAT.xml)
  EXPECT_EQ(*parseEsiInteger("#X1a00"), 0x1A00);  // either case
  EXPECT_EQ(*parseEsiInteger("#xfa13052"), 0xFA13052);
  EXPECT_EQ(*parseEsiInteger("4919"), 4919);            // decimal vendor (STMBL_ECAT.xml)
  EXPECT_EQ(*parseEsiInteger("61935618"), 0x03B11002);  // decimal product (ingenia_esi.xml)
  EXPECT_EQ(*parseEsiInteger("0xF3F"), 0xF3F);          // C style (Orbita2d.xml)
  EXPECT_EQ(*parseEsiInteger("#x0x6041"), 0x6041);      // both prefixes (Orbita2d.xml)
  EXPECT_EQ(*parseEsiInteger("  #x0000029c \r\n"), 0x29C);
  EXPECT_EQ(*parseEsiInteger("-2000"), -2000);  // EBusCurrent
  EXPECT_EQ(*parseEsiInteger("0"), 0);
  EXPECT_EQ(*parseEsiInteger("#xFFFFFFFF"), 0xFFFFFFFF);
  EXPECT_EQ(*parseEsiInteger("-9223372036854775808"), INT64_MIN);
}

TEST(EsiInteger, RejectsMalformedNumbers) {
  for (const char* bad : {"", "  ", "#x", "0x", "12a", "#xG1", "1.5", "#", "x10", "--1",
                          "99999999999999999999", "#x1FFFFFFFFFFFFFFFF"}) {
    auto value = parseEsiInteger(bad);
    EXPECT_FALSE(value.ok()) << "'" << bad << "' gave " << (value.ok() ? *value : 0);
    if (!value.ok()) {
      EXPECT_EQ(value.error().code, ErrorCode::kParse);
    }
  }
}

TEST(EsiBool, AcceptsOneZeroTrueFalse) {
  EXPECT_TRUE(*parseEsiBool("1"));
  EXPECT_FALSE(*parseEsiBool("0"));
  EXPECT_TRUE(*parseEsiBool("true"));
  EXPECT_FALSE(*parseEsiBool("false"));
  EXPECT_TRUE(*parseEsiBool(" TRUE "));
  EXPECT_FALSE(parseEsiBool("yes").ok());
  EXPECT_FALSE(parseEsiBool("2").ok());
  EXPECT_FALSE(parseEsiBool("").ok());
}

TEST(EsiHexBinary, ParsesConfigDataStrings) {
  // NI9144.xml Eeprom/ConfigData
  auto bytes = parseEsiHexBinary("0800006600010000");
  ASSERT_TRUE(bytes.ok());
  EXPECT_EQ(*bytes, (std::vector<std::uint8_t>{0x08, 0x00, 0x00, 0x66, 0x00, 0x01, 0x00, 0x00}));
  EXPECT_EQ(*parseEsiHexBinary("0a0B\r\n ff"), (std::vector<std::uint8_t>{0x0A, 0x0B, 0xFF}));
  EXPECT_TRUE(parseEsiHexBinary("")->empty());
  EXPECT_FALSE(parseEsiHexBinary("123").ok());
  EXPECT_FALSE(parseEsiHexBinary("zz").ok());
}

TEST(EsiText, Latin1ToUtf8) {
  EXPECT_EQ(latin1ToUtf8("1\xb5s"), "1\xc2\xb5s");  // µ
  EXPECT_EQ(latin1ToUtf8("M\xfc"
                         "ller"),
            "M\xc3\xbcller");  // ü
  EXPECT_EQ(latin1ToUtf8("plain"), "plain");
}

TEST(EsiText, TrimKeepsInnerBlanks) {
  EXPECT_EQ(trimEsiText("  AC servodrive \r\n"), "AC servodrive");
  EXPECT_EQ(trimEsiText("K KY"), "K KY");
  EXPECT_EQ(trimEsiText(""), "");
}

TEST(EsiText, PickLocalTextFallsBack) {
  const std::vector<EsiLocalText> both = {{1031, "Koppler"}, {1033, "Coupler"}};
  EXPECT_EQ(pickLocalText(both), "Coupler");
  EXPECT_EQ(pickLocalText(both, 1031), "Koppler");
  const std::vector<EsiLocalText> germanOnly = {{1031, "Eingang"}};  // Weidmueller_UR20_IO.xml
  EXPECT_EQ(pickLocalText(germanOnly), "Eingang");
  const std::vector<EsiLocalText> noLcid = {{0, "Outputs"}, {1031, "Ausgaenge"}};
  EXPECT_EQ(pickLocalText(noLcid), "Outputs");
  EXPECT_EQ(pickLocalText({}), "");
}

}  // namespace
}  // namespace ecsim
