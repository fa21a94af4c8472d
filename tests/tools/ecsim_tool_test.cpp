// `ecsim demo` and `ecsim study latency` as a user runs them: exit code, what they print and
// the files they write (a capture tshark reads, a CSV with the documented columns, a PNG).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "link/netns.hpp"
#include "support/test_network.hpp"

namespace ecsim::testing {
namespace {

const std::string kEcsim = std::string(ECSIM_BINARY_DIR) + "/tools/ecsim/ecsim";

std::filesystem::path freshDir(const std::string& name) {
  auto dir = std::filesystem::path(::testing::TempDir()) / name;
  std::filesystem::remove_all(dir);
  return dir;
}

TEST(EcsimTool, DemoPrintsASummaryAndWritesACapture) {
  const auto dir = freshDir("ecsim_demo_test");
  auto out = runCommand({kEcsim, "demo", "--out", dir.string()});
  ASSERT_TRUE(out.ok());
  ASSERT_EQ(out->exitCode, 0) << out->output;
  EXPECT_NE(out->output.find("working counter"), std::string::npos) << out->output;
  EXPECT_TRUE(std::filesystem::exists(dir / "demo.pcap"));
  EXPECT_GT(std::filesystem::file_size(dir / "demo.pcap"), 24u);
}

TEST(EcsimTool, LatencyStudyWritesCsvScriptAndPlot) {
  const auto dir = freshDir("ecsim_study_test");
  auto out = runCommand(
      {kEcsim, "study", "latency", "--out", dir.string(), "--max-slaves", "64", "--bytes", "2,8"});
  ASSERT_TRUE(out.ok());
  ASSERT_EQ(out->exitCode, 0) << out->output;
  std::ifstream csv(dir / "latency.csv");
  std::string header;
  std::getline(csv, header);
  for (const char* column :
       {"topology", "slaves", "bytes_per_slave", "frame_bytes", "frames_per_cycle",
        "modelled_round_trip_ns", "min_cycle_ns", "sim_cpu_ns_per_cycle"}) {
    EXPECT_NE(header.find(column), std::string::npos) << column;
  }
  int rows = 0;
  std::string row;
  while (std::getline(csv, row)) ++rows;
  EXPECT_EQ(rows, 2 /*topologies*/ * 2 /*sizes*/ * 7 /*1..64*/);
  EXPECT_TRUE(std::filesystem::exists(dir / "latency.gp"));
  ASSERT_TRUE(std::filesystem::exists(dir / "latency.png"));
  std::ifstream png(dir / "latency.png", std::ios::binary);
  char magic[4] = {};
  png.read(magic, 4);
  EXPECT_EQ(std::string(magic + 1, 3), "PNG");
}

TEST(EcsimTool, UnknownTopologyFileIsAClearError) {
  auto out = runCommand({kEcsim, "serve", "/nonexistent/topology.xml", "--iface", "lo"});
  ASSERT_TRUE(out.ok());
  EXPECT_NE(out->exitCode, 0);
  EXPECT_NE(out->output.find("/nonexistent/topology.xml"), std::string::npos) << out->output;
}

}  // namespace
}  // namespace ecsim::testing
