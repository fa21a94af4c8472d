#include "protocol/al_status.hpp"

#include <gtest/gtest.h>

#include <set>
#include <string>

namespace ecsim {
namespace {

TEST(AlState, NamesAndRawValues) {
  EXPECT_EQ(toString(AlState::kInit), "INIT");
  EXPECT_EQ(toString(AlState::kPreOp), "PREOP");
  EXPECT_EQ(toString(AlState::kBootstrap), "BOOT");
  EXPECT_EQ(toString(AlState::kSafeOp), "SAFEOP");
  EXPECT_EQ(toString(AlState::kOp), "OP");
  EXPECT_EQ(toString(static_cast<AlState>(5)), "unknown");
  // ethercat-facts.md §C.9: Init 1, Pre-Op 2, Bootstrap 3, Safe-Op 4, Op 8.
  EXPECT_EQ(static_cast<int>(AlState::kBootstrap), 3);
  EXPECT_EQ(static_cast<int>(AlState::kOp), 8);
}

TEST(AlState, FromRawMasksErrorFlagAndRejectsUnknownStates) {
  // AL status 0x14 = SAFEOP with the error indication (SOEM acks with 0x14 as well).
  EXPECT_EQ(alStateFromRaw(0x0014), AlState::kSafeOp);
  EXPECT_EQ(alStateFromRaw(0x0008), AlState::kOp);
  EXPECT_EQ(alStateFromRaw(0x0011), AlState::kInit);
  EXPECT_FALSE(alStateFromRaw(0x0000).has_value());
  EXPECT_FALSE(alStateFromRaw(0x0005).has_value());
  EXPECT_FALSE(alStateFromRaw(0x000F).has_value());
}

// Every code listed in ../shared/notes/ethercat-facts.md §C.8.
constexpr std::uint16_t kListedCodes[] = {
    0x0000, 0x0001, 0x0002, 0x0003, 0x0004, 0x0006, 0x0007, 0x000E, 0x0011, 0x0012, 0x0013, 0x0014,
    0x0015, 0x0016, 0x0017, 0x0018, 0x0019, 0x001A, 0x001B, 0x001C, 0x001D, 0x001E, 0x001F, 0x0020,
    0x0021, 0x0022, 0x0023, 0x0024, 0x0025, 0x0026, 0x0027, 0x0028, 0x0029, 0x002A, 0x002B, 0x002C,
    0x002D, 0x002E, 0x0030, 0x0031, 0x0032, 0x0033, 0x0034, 0x0035, 0x0036, 0x0037, 0x0041, 0x0042,
    0x0043, 0x0044, 0x0045, 0x004F, 0x0050, 0x0051, 0x0052, 0x0060, 0x0061, 0x0070, 0x0080, 0x0081};

TEST(AlStatusCode, EveryListedCodeHasADistinctText) {
  std::set<std::string_view> texts;
  for (std::uint16_t code : kListedCodes) {
    EXPECT_TRUE(isKnownAlStatusCode(code)) << std::hex << code;
    auto text = alStatusCodeText(code);
    EXPECT_FALSE(text.empty());
    EXPECT_TRUE(texts.insert(text).second) << "duplicate text for 0x" << std::hex << code;
  }
}

TEST(AlStatusCode, UnlistedCodesAreUnknown) {
  for (unsigned code : {0x0005u, 0x000Fu, 0x002Fu, 0x0040u, 0x0053u, 0x00FFu, 0x8000u, 0xFFFFu}) {
    EXPECT_FALSE(isKnownAlStatusCode(static_cast<std::uint16_t>(code))) << std::hex << code;
    EXPECT_EQ(alStatusCodeText(static_cast<std::uint16_t>(code)), "unknown AL status code");
  }
}

TEST(AlStatusCode, TextsOfCodesTheSimulatorRaises) {
  EXPECT_NE(alStatusCodeText(AlStatusCode::kInvalidRequestedStateChange).find("state change"),
            std::string_view::npos);
  EXPECT_NE(alStatusCodeText(0x001B).find("watchdog"), std::string_view::npos);
  EXPECT_NE(alStatusCodeText(0x0016).find("PREOP"), std::string_view::npos);
  EXPECT_NE(alStatusCodeText(0x0030).find("SYNC"), std::string_view::npos);
  EXPECT_EQ(alStatusCodeText(AlStatusCode::kNoError), "no error");
}

}  // namespace
}  // namespace ecsim
