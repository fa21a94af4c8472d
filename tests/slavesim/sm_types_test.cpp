// 0x1C00 Sync Manager Communication Type (ETG.1000.6) holds every SM's type on a device: an ESI
// whose dictionary has the object but gives it no values (Copley's XE2 ESI: <Info/> under each
// SubItem) must not make a device that reports no process-data SMs, and so assigns no PDOs to
// them (0x1C12/0x1C13 empty, SOEM then maps nothing): the types come from its <Sm> elements.
// STMBL_ECAT.xml (../shared/esi), whose 0x1C00 says 4 SMs of types 1, 2, 3, 4, with the values
// taken out, must give the same device as the file as it is.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>

#include "config/esi.hpp"
#include "slavesim/esi_slave.hpp"
#include "support/test_network.hpp"

namespace ecsim::testing {
namespace {

struct Lists {
  std::vector<std::uint8_t> types;
  std::vector<std::uint16_t> rx, tx;
};

Lists listsOf(std::string_view xml) {
  Lists out;
  auto file = parseEsi(xml, "stmbl.xml");
  EXPECT_TRUE(file.ok()) << (file.ok() ? "" : file.error().message());
  if (!file.ok()) return out;
  auto slave = slavesim::makeSlaveFromEsi(*file, file->devices.at(0), "Axis");
  EXPECT_TRUE(slave.ok()) << (slave.ok() ? "" : slave.error().message());
  if (!slave.ok()) return out;
  slavesim::coe::ObjectDictionary* od = slavesim::objectDictionaryOf(**slave);
  const auto n = od->get<std::uint8_t>(0x1C00, 0);
  for (std::uint8_t s = 1; n.ok() && s <= *n; ++s)
    out.types.push_back(*od->get<std::uint8_t>(0x1C00, s));
  for (auto [index, list] : {std::pair{0x1C12, &out.rx}, std::pair{0x1C13, &out.tx}}) {
    const auto count = od->get<std::uint8_t>(static_cast<std::uint16_t>(index), 0);
    for (std::uint8_t s = 1; count.ok() && s <= *count; ++s) {
      list->push_back(*od->get<std::uint16_t>(static_cast<std::uint16_t>(index), s));
    }
  }
  return out;
}

TEST(SmTypes, ADictionaryWithoutSmTypeValuesTakesThemFromTheSmElements) {
  const auto path = sharedDir() / "esi" / "STMBL_ECAT.xml";
  ECSIM_REQUIRE_SHARED(path);
  std::stringstream text;
  text << std::ifstream(path).rdbuf();
  const std::string original = text.str();
  // The 0x1C00 object without its values: every <Info><DefaultValue>..</DefaultValue></Info>
  // in it becomes <Info/>.
  const std::size_t begin = original.find("<Index>#x1C00</Index>");
  ASSERT_NE(begin, std::string::npos);
  const std::size_t end = original.find("</Object>", begin);
  const std::string object = original.substr(begin, end - begin);
  const std::string emptied = std::regex_replace(
      object, std::regex("<Info>\\s*<DefaultValue>[0-9]+</DefaultValue>\\s*</Info>"), "<Info/>");
  ASSERT_NE(emptied, object);
  const std::string changed = original.substr(0, begin) + emptied + original.substr(end);

  const Lists asIs = listsOf(original);
  const Lists without = listsOf(changed);
  EXPECT_EQ(asIs.types, (std::vector<std::uint8_t>{1, 2, 3, 4}));
  EXPECT_EQ(without.types, asIs.types);
  EXPECT_FALSE(asIs.rx.empty());
  EXPECT_EQ(without.rx, asIs.rx);
  EXPECT_EQ(without.tx, asIs.tx);
}

}  // namespace
}  // namespace ecsim::testing
