// `ecmaster soe read | write` against its in-process simulator (--sim, virtual time): an
// AX5000-class drive reached over SoE only (examples/topologies/soe_drive.xml, ECS5101 with
// its dictionary), and the same device serving Beckhoff's AX5021 dictionary
// (../shared/esi/Beckhoff_AX5021-xxxx-0001_Dict.xml): our master's SoE client
// (master/soe_client.hpp) through the slave's mailbox, fragments and error responses included.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

#include "support/readiness.hpp"
#include "support/test_network.hpp"

namespace ecsim::testing {
namespace {

const std::string kEcmaster = std::string(ECSIM_BINARY_DIR) + "/tools/ecmaster/ecmaster";
const std::string kSoeDrive = std::string(ECSIM_SOURCE_DIR) + "/examples/topologies/soe_drive.xml";

CommandOutput run(std::vector<std::string> args) {
  args.insert(args.begin(), kEcmaster);
  auto out = runCommand(args);
  EXPECT_TRUE(out.ok());
  return out.ok() ? *out : CommandOutput{-1, "", ""};
}

TEST(EcmasterSoe, ReadWithoutIdnListsEveryIdnOfTheDrive) {
  auto out = run({"--sim", kSoeDrive, "soe", "read", "-p", "1"});
  ASSERT_EQ(out.exitCode, 0) << out.output;
  // S-0-0017 lists 20 IDNs (examples/esi/soe/ecs5101_dict.xml): one line each.
  for (const char* line :
       {"S-0-0001  u16       Control unit cycle time (TNcyc)", "1000 us",
        "S-0-0016  IDN list  Configuration list of AT", "[S-0-0011, S-0-0040, S-0-0051]",
        "S-0-0024  IDN list  Configuration list of MDT", "[S-0-0036, S-0-0047]",
        "S-0-0030  text      Manufacturer version", "\"ecsim ECS5101 simulated servo drive v1.0\"",
        "S-0-0047  i32       Position command value", "S-0-0099  command",
        "S-0-0188  IDN list  IDN-list of configurable data in the MDT"}) {
    EXPECT_NE(out.output.find(line), std::string::npos) << line << "\n" << out.output;
  }
  EXPECT_EQ(std::count(out.output.begin(), out.output.end(), '\n'), 20) << out.output;
}

TEST(EcmasterSoe, ReadsOneIdnWithItsElementsAndWritesItsValue) {
  auto out = run({"--sim", kSoeDrive, "--json", "soe", "read", "-p", "1", "S-0-0001"});
  ASSERT_EQ(out.exitCode, 0) << out.output;
  auto j = nlohmann::json::parse(out.standardOutput, nullptr, false);
  ASSERT_FALSE(j.is_discarded()) << out.output;
  EXPECT_EQ(j["name"], "Control unit cycle time (TNcyc)");
  EXPECT_EQ(j["attribute"], 0x60110001);
  EXPECT_EQ(j["unit"], "us");
  EXPECT_EQ(j["minimum"], "62");
  EXPECT_EQ(j["maximum"], "20000");
  EXPECT_EQ(j["default"], "1000");
  EXPECT_EQ(j["value"], "1000");

  // Writes: an AT configuration of configurable IDNs, a procedure command; refusals name the
  // SoE error.
  EXPECT_EQ(run({"--sim", kSoeDrive, "soe", "write", "-p", "1", "S-0-0016", "S-0-0051,S-0-0040"})
                .exitCode,
            0);
  EXPECT_EQ(run({"--sim", kSoeDrive, "soe", "write", "-p", "1", "S-0-0099", "3"}).exitCode, 0);
  auto refused = run({"--sim", kSoeDrive, "soe", "write", "-p", "1", "S-0-0016", "S-0-0001"});
  EXPECT_EQ(refused.exitCode, 1);
  EXPECT_NE(refused.output.find("error 0x7008"), std::string::npos) << refused.output;
  auto low = run({"--sim", kSoeDrive, "soe", "write", "-p", "1", "S-0-0001", "10"});
  EXPECT_NE(low.output.find("error 0x7006 (Operation data is smaller than the minimum"),
            std::string::npos)
      << low.output;
  auto none = run({"--sim", kSoeDrive, "soe", "read", "-p", "1", "S-0-0300"});
  EXPECT_EQ(none.exitCode, 1);
  EXPECT_NE(none.output.find("SoE read of S-0-0300 (drive 0) from slave 1"), std::string::npos)
      << none.output;
  EXPECT_NE(none.output.find("error 0x1001 (No IDN)"), std::string::npos) << none.output;
  auto drive = run({"--sim", kSoeDrive, "soe", "read", "-p", "1", "--drive", "1", "S-0-0001"});
  EXPECT_NE(drive.output.find("0x800A (Invalid drive number)"), std::string::npos) << drive.output;
  auto coupler = run({"--sim", kSoeDrive, "soe", "read", "-p", "0"});
  EXPECT_NE(coupler.output.find("has no mailbox"), std::string::npos) << coupler.output;
  auto badIdn = run({"--sim", kSoeDrive, "soe", "read", "-p", "1", "S-9-1"});
  EXPECT_NE(badIdn.output.find("parameter set must be 0-7"), std::string::npos) << badIdn.output;
}

TEST(EcmasterSoe, ListsTheIdnsOfTheAx5021DictionaryInFragments) {
  const auto dict = sharedDir() / "esi" / "Beckhoff_AX5021-xxxx-0001_Dict.xml";
  ECSIM_REQUIRE_SHARED(dict);
  const auto dir =
      std::filesystem::temp_directory_path() / ("ecsim-ecmaster-soe-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto topology = dir / "ax5021.xml";
  {
    std::ofstream f(topology);
    f << "<Topology name=\"ax\">\n  <Slave name=\"Drive\" esi=\"" << ECSIM_SOURCE_DIR
      << "/examples/esi/ecsim_soe_drive.xml\" product=\"#x00005101\" soeDictionary=\""
      << dict.string() << "\"/>\n</Topology>\n";
  }
  auto out = run({"--sim", topology.string(), "--json", "soe", "read", "-p", "0"});
  std::filesystem::remove_all(dir);
  ASSERT_EQ(out.exitCode, 0) << out.output;
  auto j = nlohmann::json::parse(out.standardOutput, nullptr, false);
  ASSERT_FALSE(j.is_discarded()) << out.output;
  // S-0-0017 (238 bytes, three 128-byte mailboxes) names the dictionary's 119 objects.
  ASSERT_EQ(j["idns"].size(), 119u);
  EXPECT_EQ(j["idns"][0]["idn"], "S-0-0001");
  EXPECT_EQ(j["idns"][0]["unit"], "us");
  EXPECT_EQ(j["idns"][118]["idn"], "P-0-1022");
  EXPECT_EQ(j["idns"][118]["name"], "Debug command");
  EXPECT_EQ(j["idns"][118]["type"], "command");
  bool voltage = false;
  for (const auto& row : j["idns"]) {
    if (row["idn"] == "P-0-0201") {
      EXPECT_EQ(row["name"], "Nominal main voltage");
      EXPECT_EQ(row["value"], "400.0") << "DefaultValue 4000, one decimal place (#x61110001)";
      voltage = true;
    }
  }
  EXPECT_TRUE(voltage);
}

}  // namespace
}  // namespace ecsim::testing
