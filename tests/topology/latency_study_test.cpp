// The latency study against the closed-form wire calculation (docs/timing.md): with no delay
// parameter involved the round trip is the frame's wire time to the nanosecond, and with
// delays it follows N processing + (N-1) forwarding delays and each cable twice.
#include "topology/latency_study.hpp"

#include <gtest/gtest.h>

namespace ecsim::topology {
namespace {

TEST(LatencyStudy, WithoutDelaysTheRoundTripIsTheWireTime) {
  VirtualClock cpu;
  for (std::size_t n : {1u, 7u, 64u}) {
    StudyParameters p;
    p.slaves = n;
    p.bytesPerSlave = 2;
    p.processingDelayNs = 0;
    p.forwardingDelayNs = 0;
    p.cableMetres = 0;
    p.masterCableMetres = 0;
    p.repetitions = 2;
    auto point = runLatencyPoint(p, cpu);
    ASSERT_TRUE(point.ok()) << point.error().message();
    ASSERT_EQ(point->framesPerCycle, 1u);
    // 14 Ethernet + 2 EtherCAT + (12 + 2n) LRW + (12 + 8) FRMW, at least 60; +8 +4 on the wire.
    const std::size_t frame = std::max<std::size_t>(14 + 2 + 12 + 2 * n + 20, 60);
    EXPECT_EQ(point->frameBytes, frame);
    EXPECT_EQ(point->roundTripNs, static_cast<SimTime>((8 + frame + 4) * 80)) << n << " slaves";
    EXPECT_EQ(point->wkcErrors, 0u);
  }
}

TEST(LatencyStudy, LineMatchesTheClosedFormToTheNanosecond) {
  VirtualClock cpu;
  for (std::size_t n : {1u, 2u, 10u, 100u, 180u}) {
    StudyParameters p;
    p.slaves = n;
    p.bytesPerSlave = 8;
    p.cableMetres = 3.0;
    p.masterCableMetres = 2.0;
    p.processingDelayNs = 870;
    p.forwardingDelayNs = 640;
    p.repetitions = 2;
    auto point = runLatencyPoint(p, cpu);
    ASSERT_TRUE(point.ok()) << point.error().message();
    ASSERT_EQ(point->framesPerCycle, 1u) << n;
    EXPECT_EQ(point->roundTripNs, closedFormLineRoundTrip(p, point->frameBytes)) << n;
    EXPECT_EQ(point->wkcErrors, 0u);
  }
}

TEST(LatencyStudy, LargeImagesSplitIntoFramesWithCorrectWorkingCounters) {
  VirtualClock cpu;
  StudyParameters p;
  p.slaves = 1024;
  p.bytesPerSlave = 8;
  p.repetitions = 2;
  auto point = runLatencyPoint(p, cpu);
  ASSERT_TRUE(point.ok());
  EXPECT_EQ(point->framesPerCycle, 6u) << "8192 bytes at up to 1486 per frame";
  EXPECT_EQ(point->wkcErrors, 0u);
  EXPECT_GE(point->minCycleNs, point->roundTripNs);
}

// Every cable is still crossed twice and every slave adds one processing delay; a junction's
// extra forwarding passage replaces the one a branch's last slave does not make. So a tree of
// identical slaves has the round trip of a line of the same size.
TEST(LatencyStudy, TreeHasTheRoundTripOfALineOfTheSameSize) {
  VirtualClock cpu;
  StudyParameters p;
  p.slaves = 64;
  p.repetitions = 2;
  auto line = runLatencyPoint(p, cpu);
  p.topology = StudyTopology::kTree;
  auto tree = runLatencyPoint(p, cpu);
  ASSERT_TRUE(line.ok() && tree.ok());
  EXPECT_EQ(tree->wkcErrors, 0u);
  EXPECT_EQ(tree->roundTripNs, line->roundTripNs);
}

}  // namespace
}  // namespace ecsim::topology
