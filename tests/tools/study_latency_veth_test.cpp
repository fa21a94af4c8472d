// `ecsim study latency --topology robot6.xml` as a user runs it, with the measured curve: our
// master over a veth pair in a private namespace against `ecsim serve --paced`. Checks the
// files and their columns, never the speed (figures are printed, docs/timing.md).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "link/netns.hpp"
#include "support/privileges.hpp"

namespace ecsim::testing {
namespace {

const std::string kEcsim = std::string(ECSIM_BINARY_DIR) + "/tools/ecsim/ecsim";
const std::string kRobot6 = std::string(ECSIM_SOURCE_DIR) + "/examples/topologies/robot6.xml";

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream in(line);
  for (std::string cell; std::getline(in, cell, ',');) cells.push_back(cell);
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

TEST(StudyLatencyVeth, Robot6WritesModelledAndMeasuredCurves) {
  ECSIM_REQUIRE_NETWORK();
  const auto dir = std::filesystem::path(::testing::TempDir()) /
                   ("ecsim_study_veth_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  auto out = runCommand({kEcsim, "study", "latency", "--topology", kRobot6, "--out", dir.string(),
                         "--cycles-us", "1000,250", "--measure-seconds", "0.3"});
  ASSERT_TRUE(out.ok()) << out.error().message();
  ASSERT_EQ(out->exitCode, 0) << out->output;
  std::cout << out->output;  // the measured figures, for the log

  std::ifstream csv(dir / "latency.csv");
  std::string line;
  ASSERT_TRUE(std::getline(csv, line));
  const auto header = split(line);
  for (const char* column :
       {"cycle_us", "modelled_round_trip_us", "sync0_shift_us", "frames_per_cycle",
        "measured_cycles", "rtt_p50_us", "rtt_p99_us", "rtt_max_us", "jitter_p50_us",
        "jitter_p99_us", "jitter_max_us", "lost", "measured_fits"}) {
    EXPECT_NE(std::find(header.begin(), header.end(), column), header.end()) << column;
  }
  const auto at = [&](const std::vector<std::string>& row, const char* name) {
    const auto i = std::find(header.begin(), header.end(), name) - header.begin();
    return static_cast<std::size_t>(i) < row.size() ? row[i] : std::string();
  };
  int rows = 0;
  while (std::getline(csv, line)) {
    const auto row = split(line);
    ASSERT_EQ(row.size(), header.size()) << line;
    ++rows;
    // robot6: 7 devices, one frame (264 bytes with the DC FRMW), modelled and measured.
    EXPECT_EQ(at(row, "frames_per_cycle"), "1") << line;
    EXPECT_GT(std::stod(at(row, "modelled_round_trip_us")), 0.0) << line;
    EXPECT_GT(std::stoul(at(row, "measured_cycles")), 0u) << line;
    EXPECT_GT(std::stod(at(row, "rtt_p50_us")), 0.0) << line;
    EXPECT_LE(std::stod(at(row, "rtt_p50_us")), std::stod(at(row, "rtt_max_us"))) << line;
  }
  EXPECT_EQ(rows, 2);
  EXPECT_TRUE(std::filesystem::exists(dir / "devices.csv"));
  std::ifstream gp(dir / "latency.gp");
  const std::string script{std::istreambuf_iterator<char>(gp), {}};
  EXPECT_NE(script.find("measured round trip p99"), std::string::npos);
  std::ifstream png(dir / "latency.png", std::ios::binary);
  char magic[8] = {};
  png.read(magic, 8);
  EXPECT_EQ(std::string(magic, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  if (!HasFailure()) std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace ecsim::testing
