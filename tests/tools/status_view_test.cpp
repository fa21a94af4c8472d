// The status view of `ecsim serve --status` / `--status-json`: snapshot of a real (demo)
// network, the table and JSON formats, atomic file replacement, the periodic reporter.
#include "tools/ecsim/status_view.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include <unistd.h>

#include "config/topology_file.hpp"
#include "topology/network_builder.hpp"

namespace ecsim::tools {
namespace {

StatusSnapshot sample() {
  StatusSnapshot snap;
  snap.uptime = 2500 * kNsPerMs;
  snap.framesReceived = 1234;
  snap.framesAnswered = 1230;
  snap.framesDropped = 4;
  snap.framesLost = 2;
  snap.framesPerSecond = 1000.0;
  snap.lastRoundTrip = 12'340;
  SlaveStatus a;
  a.name = "DI\"1";
  a.state = AlState::kOp;
  a.frames = 1230;
  a.datagrams = 2460;
  a.dcDifferenceNs = -17;
  a.values.push_back({"DI\"1.Input 1", 0x6000, 1, false, 1});
  SlaveStatus b;
  b.name = "Drive1";
  b.state = AlState::kSafeOp;
  b.alError = true;
  b.alStatusCode = 0x001B;
  b.rxErrors = 3;
  b.lostLinks = 1;
  b.values.push_back({"Drive1.Controlword", 0x6040, 0, true, 15});
  snap.slaves = {a, b};
  return snap;
}

TEST(StatusView, DecodesSystemTimeDifferenceAsSignMagnitude) {
  // ET1100 datasheet, register 0x092C: bits 30:0 the magnitude, bit 31 set when the local
  // copy of the system time is smaller than the received one.
  EXPECT_EQ(decodeSystemTimeDifference(0x00000010u), 16);
  EXPECT_EQ(decodeSystemTimeDifference(0x80000010u), -16);
  EXPECT_EQ(decodeSystemTimeDifference(0x7FFFFFFFu), 0x7FFFFFFF);
  EXPECT_EQ(decodeSystemTimeDifference(0x80000000u), 0);
}

TEST(StatusView, TableHasAHeaderAndOneLinePerSlave) {
  const std::string table = formatStatusTable(sample());
  std::istringstream in(table);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_NE(lines[0].find("frames 1234 in / 1230 out (1000/s)"), std::string::npos) << lines[0];
  EXPECT_NE(lines[0].find("last round trip 12.34 us"), std::string::npos) << lines[0];
  EXPECT_NE(lines[0].find("malformed 4  lost 2"), std::string::npos) << lines[0];
  EXPECT_NE(lines[1].find("dc diff ns"), std::string::npos);
  EXPECT_NE(lines[2].find("OP"), std::string::npos) << lines[2];
  EXPECT_NE(lines[2].find("-17"), std::string::npos) << lines[2];
  EXPECT_NE(lines[2].find("<6000:01=1"), std::string::npos) << lines[2];
  EXPECT_NE(lines[3].find("SAFEOP+ERR"), std::string::npos) << lines[3];
  EXPECT_NE(lines[3].find("0x001b"), std::string::npos) << lines[3];
  EXPECT_NE(lines[3].find(">6040:00=15"), std::string::npos) << lines[3];
  EXPECT_EQ(table.find('\x1b'), std::string::npos);  // no terminal codes in the table itself
}

TEST(StatusView, JsonCarriesTheSameContentAndEscapesNames) {
  const std::string json = formatStatusJson(sample());
  EXPECT_EQ(json.front(), '{');
  EXPECT_NE(json.find("\"framesReceived\":1234"), std::string::npos);
  EXPECT_NE(json.find("\"framesPerSecond\":1000.0"), std::string::npos);
  EXPECT_NE(json.find("\"lastRoundTripNs\":12340"), std::string::npos);
  EXPECT_NE(json.find("\"name\":\"DI\\\"1\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"alStatusCode\":27,"), std::string::npos);
  EXPECT_NE(json.find("\"alError\":true"), std::string::npos);
  EXPECT_NE(json.find("\"dcDifferenceNs\":-17"), std::string::npos);
  EXPECT_NE(json.find("{\"name\":\"Drive1.Controlword\",\"entry\":\"6040:00\",\"output\":true,"
                      "\"value\":15}"),
            std::string::npos)
      << json;
  // Balanced braces and brackets (a cheap well-formedness check).
  int braces = 0;
  int brackets = 0;
  bool inString = false;
  for (std::size_t i = 0; i < json.size(); ++i) {
    const char c = json[i];
    if (c == '"' && (i == 0 || json[i - 1] != '\\')) inString = !inString;
    if (inString) continue;
    braces += c == '{' ? 1 : c == '}' ? -1 : 0;
    brackets += c == '[' ? 1 : c == ']' ? -1 : 0;
  }
  EXPECT_EQ(braces, 0);
  EXPECT_EQ(brackets, 0);
}

TEST(StatusView, SnapshotOfTheDemoNetwork) {
  auto config = loadTopologyFile(ECSIM_SOURCE_DIR "/examples/topologies/demo.xml");
  ASSERT_TRUE(config.ok()) << config.error().message();
  auto network = topology::buildNetwork(*config);
  ASSERT_TRUE(network.ok()) << network.error().message();
  topology::ServerCounters counters;
  counters.framesReceived = 7;
  counters.lastRoundTrip = 5000;
  const StatusSnapshot snap = takeStatusSnapshot(*network->segment, counters, kNsPerSecond, 7.0);
  ASSERT_EQ(snap.slaves.size(), 6u);  // demo.xml
  EXPECT_EQ(snap.slaves[0].name, "Coupler");
  EXPECT_EQ(snap.slaves[5].name, "Drive2");
  EXPECT_EQ(snap.slaves[1].state, AlState::kInit);
  EXPECT_EQ(snap.framesReceived, 7u);
  EXPECT_EQ(snap.lastRoundTrip, 5000);
  // DI1's first inputs as demo.xml sets them: BOOL 1, 0, 1 (a 1-bit value is not negative).
  ASSERT_GE(snap.slaves[1].values.size(), 3u);
  EXPECT_EQ(snap.slaves[1].values[0].index, 0x6000);
  EXPECT_FALSE(snap.slaves[1].values[0].output);
  EXPECT_EQ(snap.slaves[1].values[0].value, 1);
  EXPECT_EQ(snap.slaves[1].values[1].value, 0);
  EXPECT_EQ(snap.slaves[1].values[2].value, 1);
  // DO1's are outputs, every one of the 8 listed (not only the table's first 4), named as a
  // master names them (ecsim_devices.xml, ECS2008's RxPDO entries "Output 1".."Output 8").
  ASSERT_EQ(snap.slaves[2].values.size(), 8u);
  EXPECT_TRUE(snap.slaves[2].values[0].output);
  EXPECT_EQ(snap.slaves[2].values[0].name, "DO1.Output 1");
  EXPECT_EQ(snap.slaves[2].values[7].name, "DO1.Output 8");
  EXPECT_EQ(snap.slaves[1].values[0].name, "DI1.Input 1");
  // Drive1's Statusword, from its TxPDO, among its entries.
  bool statusword = false;
  for (const auto& v : snap.slaves[4].values) statusword |= v.name == "Drive1.Statusword";
  EXPECT_TRUE(statusword);
  const std::string json = formatStatusJson(snap);
  EXPECT_NE(json.find("\"name\":\"DO1.Output 8\""), std::string::npos) << json;
  // The table keeps its first kTableValues entries per slave.
  const std::string table = formatStatusTable(snap);
  EXPECT_NE(table.find(">7000:04="), std::string::npos) << table;
  EXPECT_EQ(table.find(">7000:05="), std::string::npos) << table;
}

TEST(StatusView, WritesJsonAtomicallyAndReportsPeriodically) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("ecsim-status-test-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto path = dir / "status.json";
  ASSERT_TRUE(writeFileAtomically(path, "{\"a\":1}\n").ok());
  EXPECT_FALSE(std::filesystem::exists(dir / "status.json.tmp"));

  topology::Segment segment;
  topology::ServerCounters counters;
  StatusReporter reporter(false, path, 500 * kNsPerMs);
  reporter.tick(0, segment, counters);  // starts
  counters.framesReceived = 100;
  reporter.tick(100 * kNsPerMs, segment, counters);  // too early: the old file stays
  {
    std::ifstream in(path);
    std::string text((std::istreambuf_iterator<char>(in)), {});
    EXPECT_EQ(text, "{\"a\":1}\n");
  }
  reporter.tick(1000 * kNsPerMs, segment, counters);  // 100 frames in 1 s
  ASSERT_TRUE(reporter.lastWrite().ok());
  std::ifstream in(path);
  std::string text((std::istreambuf_iterator<char>(in)), {});
  EXPECT_NE(text.find("\"framesPerSecond\":100.0"), std::string::npos) << text;
  EXPECT_NE(text.find("\"uptimeNs\":1000000000"), std::string::npos) << text;
  EXPECT_FALSE(writeFileAtomically(dir / "missing" / "x.json", "{}").ok());
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace ecsim::tools
