// `ecmaster cyclic` against its in-process simulator (--sim, virtual time): the histogram
// figures, events and variables in its JSON and text, --show, and --rt refused on --sim.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <fstream>

#include "link/netns.hpp"
#include "support/readiness.hpp"

namespace ecsim::testing {
namespace {

const std::string kEcmaster = std::string(ECSIM_BINARY_DIR) + "/tools/ecmaster/ecmaster";
const std::string kDemo = std::string(ECSIM_SOURCE_DIR) + "/examples/topologies/demo.xml";

CommandOutput run(std::vector<std::string> args) {
  args.insert(args.begin(), kEcmaster);
  auto out = runCommand(args);
  EXPECT_TRUE(out.ok());
  return out.ok() ? *out : CommandOutput{-1, "", ""};
}

// --sim TOPOLOGY names the slaves as the topology does (issue #16 item 3): DI1, Drive1.
TEST(EcmasterCyclic, JsonHasPercentilesEventsAndShownVariables) {
  auto out = run({"--sim", kDemo, "--json", "cyclic", "--seconds", "0.3", "--quiet", "--show",
                  "DI1.Input 3", "--show", "Drive1.Statusword"});
  ASSERT_EQ(out.exitCode, 0) << out.output;
  auto j = nlohmann::json::parse(out.standardOutput, nullptr, false);
  ASSERT_FALSE(j.is_discarded()) << out.output;
  EXPECT_EQ(j["cycles"], 300);
  const auto& rtt = j["roundTripUs"];
  EXPECT_EQ(rtt["samples"], 300);
  EXPECT_GT(rtt["min"].get<double>(), 0.0);
  EXPECT_LE(rtt["min"].get<double>(), rtt["p99"].get<double>());
  EXPECT_LE(rtt["p99"].get<double>(), rtt["p999"].get<double>());
  EXPECT_LE(rtt["p999"].get<double>(), rtt["max"].get<double>());
  EXPECT_EQ(j["jitterUs"]["samples"], 299);
  EXPECT_TRUE(j["events"].is_array());
  EXPECT_EQ(j["events"].size(), 0u);
  EXPECT_EQ(j["slavesLost"], 0);
  // DI1's inputs 1 and 3 are set in examples/topologies/demo.xml.
  EXPECT_EQ(j["variables"]["DI1.Input 3"], "1");
  EXPECT_TRUE(j["variables"].contains("Drive1.Statusword"));
}

TEST(EcmasterCyclic, TextSummaryAndErrors) {
  auto out = run({"--sim", kDemo, "cyclic", "--seconds", "1.5", "--show", "1.Input 2"});
  ASSERT_EQ(out.exitCode, 0) << out.output;
  EXPECT_NE(out.output.find("[   1.0 s] cycles"), std::string::npos) << out.output;  // live
  EXPECT_NE(out.output.find("cycle jitter us: min"), std::string::npos) << out.output;
  EXPECT_NE(out.output.find("p99.9"), std::string::npos) << out.output;
  EXPECT_NE(out.output.find("slaves lost 0, recovered 0"), std::string::npos) << out.output;
  EXPECT_NE(out.output.find("variables:  DI1.Input 2 = 0"), std::string::npos) << out.output;
  auto missing = run({"--sim", kDemo, "cyclic", "--seconds", "0.1", "--show", "DI9.Nothing"});
  EXPECT_EQ(missing.exitCode, 1);
  EXPECT_NE(missing.output.find("no process variable 'DI9.Nothing'; closest: "), std::string::npos)
      << missing.output;
  auto misspelt =
      run({"--sim", kDemo, "cyclic", "--seconds", "0.1", "--show", "Drive1.StatusWord"});
  EXPECT_EQ(misspelt.exitCode, 1);
  EXPECT_NE(misspelt.output.find("no process variable 'Drive1.StatusWord'; closest: "
                                 "Drive1.Statusword, Drive2.Statusword"),
            std::string::npos)
      << misspelt.output;
  auto rt = run({"--sim", kDemo, "cyclic", "--seconds", "0.1", "--rt"});
  EXPECT_EQ(rt.exitCode, 1);
  EXPECT_NE(rt.output.find("--rt needs --iface"), std::string::npos) << rt.output;
}

// The slaves' JSON and table name them as the topology does; --config's names win over --sim's,
// and --names FILE names them by bus position from a topology or ENI.
TEST(EcmasterCyclic, SlavesAreNamedByTheTopologyTheConfigOrNames) {
  auto out = run({"--sim", kDemo, "--json", "slaves"});
  ASSERT_EQ(out.exitCode, 0) << out.output;
  auto list = nlohmann::json::parse(out.standardOutput, nullptr, false);
  ASSERT_TRUE(list.is_array()) << out.output;
  ASSERT_EQ(list.size(), 6u);
  EXPECT_EQ(list[4]["name"], "Drive1");
  EXPECT_EQ(list[4]["siiName"], "ECS7201 CiA 402 servo drive");
  auto named = run({"--sim-slaves", "2", "--names", kDemo, "slaves"});
  ASSERT_EQ(named.exitCode, 0) << named.output;
  EXPECT_NE(named.output.find("Coupler"), std::string::npos) << named.output;
  EXPECT_NE(named.output.find("DI1"), std::string::npos) << named.output;
  EXPECT_NE(named.output.find("warning: " + kDemo + " names 6 slaves, the bus has 2"),
            std::string::npos)
      << named.output;
  auto bad = run({"--sim", kDemo, "--names", "/nonexistent/names.xml", "slaves"});
  EXPECT_EQ(bad.exitCode, 1);
  EXPECT_NE(bad.output.find("/nonexistent/names.xml"), std::string::npos) << bad.output;
}

// --config checks vendor, product and configured revision; serial numbers only with
// --check-serial (issue #16 item 5). The demo's slaves have serial numbers of their own (their
// topology line), none of them 1.
TEST(EcmasterCyclic, SerialNumbersAreCheckedOnlyWithCheckSerial) {
  const std::string config = uniqueTempPath("ecmaster_serial_config.xml");
  std::ofstream(config) << R"(<EcsimMaster>
  <Slave name="Bus coupler" vendor="#x00000E5C" product="#x00001100" serial="1"/>
  <Slave name="DI1" vendor="#x00000E5C" product="#x00001008"/>
  <Slave name="DO1" vendor="#x00000E5C" product="#x00002008"/>
  <Slave name="AI1" vendor="#x00000E5C" product="#x00003102"/>
  <Slave name="Drive1" vendor="#x00000E5C" product="#x00007201"/>
  <Slave name="Drive2" vendor="#x00000E5C" product="#x00007201"/>
</EcsimMaster>
)";
  auto lenient = run({"--sim", kDemo, "--config", config, "slaves"});
  EXPECT_EQ(lenient.exitCode, 0) << lenient.output;
  EXPECT_NE(lenient.output.find("Bus coupler"), std::string::npos) << lenient.output;  // --config's
  auto strict = run({"--sim", kDemo, "--config", config, "--check-serial", "slaves"});
  EXPECT_EQ(strict.exitCode, 1) << strict.output;
  EXPECT_NE(strict.output.find("configured as 'Bus coupler'"), std::string::npos) << strict.output;
  EXPECT_NE(strict.output.find("serial"), std::string::npos) << strict.output;
  std::filesystem::remove(config);
}

}  // namespace
}  // namespace ecsim::testing
