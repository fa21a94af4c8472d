// `ecmaster cyclic` against its in-process simulator (--sim, virtual time): the histogram
// figures, events and variables in its JSON and text, --show, and --rt refused on --sim.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "link/netns.hpp"

namespace ecsim::testing {
namespace {

const std::string kEcmaster = std::string(ECSIM_BINARY_DIR) + "/tools/ecmaster/ecmaster";
const std::string kDemo = std::string(ECSIM_SOURCE_DIR) + "/examples/topologies/demo.xml";

CommandOutput run(std::vector<std::string> args) {
  args.insert(args.begin(), kEcmaster);
  auto out = runCommand(args);
  EXPECT_TRUE(out.ok());
  return out.ok() ? *out : CommandOutput{-1, ""};
}

TEST(EcmasterCyclic, JsonHasPercentilesEventsAndShownVariables) {
  auto out = run({"--sim", kDemo, "--json", "cyclic", "--seconds", "0.3", "--quiet", "--show",
                  "ECS1008.Input 3", "--show", "ECS7201_4.Statusword"});
  ASSERT_EQ(out.exitCode, 0) << out.output;
  auto j = nlohmann::json::parse(out.output, nullptr, false);
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
  EXPECT_EQ(j["variables"]["ECS1008.Input 3"], "1");
  EXPECT_TRUE(j["variables"].contains("ECS7201_4.Statusword"));
}

TEST(EcmasterCyclic, TextSummaryAndErrors) {
  auto out = run({"--sim", kDemo, "cyclic", "--seconds", "1.5", "--show", "1.Input 2"});
  ASSERT_EQ(out.exitCode, 0) << out.output;
  EXPECT_NE(out.output.find("[   1.0 s] cycles"), std::string::npos) << out.output;  // live
  EXPECT_NE(out.output.find("cycle jitter us: min"), std::string::npos) << out.output;
  EXPECT_NE(out.output.find("p99.9"), std::string::npos) << out.output;
  EXPECT_NE(out.output.find("slaves lost 0, recovered 0"), std::string::npos) << out.output;
  EXPECT_NE(out.output.find("variables:  ECS1008.Input 2 = 0"), std::string::npos) << out.output;
  auto missing = run({"--sim", kDemo, "cyclic", "--seconds", "0.1", "--show", "DI9.Nothing"});
  EXPECT_EQ(missing.exitCode, 1);
  EXPECT_NE(missing.output.find("no process variable 'DI9.Nothing'"), std::string::npos)
      << missing.output;
  auto rt = run({"--sim", kDemo, "cyclic", "--seconds", "0.1", "--rt"});
  EXPECT_EQ(rt.exitCode, 1);
  EXPECT_NE(rt.output.find("--rt needs --iface"), std::string::npos) << rt.output;
}

}  // namespace
}  // namespace ecsim::testing
