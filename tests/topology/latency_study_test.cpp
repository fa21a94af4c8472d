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

// A coupler in front (an EK1100 with 100BASE-TX in and EBUS out) adds its two passages and one
// more cable; no DC datagram leaves the LRW alone in the frame.
TEST(LatencyStudy, CoupledLineWithoutDcMatchesTheClosedForm) {
  VirtualClock cpu;
  for (std::size_t n : {1u, 3u, 40u, 200u}) {
    StudyParameters p;
    p.slaves = n;
    p.bytesPerSlave = 2;
    p.cableMetres = 0.5;
    p.masterCableMetres = 7.0;
    p.processingDelayNs = 150;
    p.forwardingDelayNs = 140;
    p.distributedClock = false;
    p.coupler = true;
    p.couplerProcessingDelayNs = 390;
    p.couplerForwardingDelayNs = 320;
    p.repetitions = 2;
    auto point = runLatencyPoint(p, cpu);
    ASSERT_TRUE(point.ok()) << point.error().message();
    ASSERT_EQ(point->framesPerCycle, 1u);
    EXPECT_EQ(point->frameBytes, std::max<std::size_t>(14 + 2 + 12 + 2 * n, 60)) << n;
    EXPECT_EQ(point->roundTripNs, closedFormLineRoundTrip(p, point->frameBytes)) << n;
    // Written out for n slaves: coupler 390 + 320, n x 150, (n - 1) x 140, the master cable
    // (35 ns) and n cables of 0.5 m (3 ns each, rounded) twice, the frame's wire time.
    const auto sn = static_cast<SimTime>(n);
    const SimTime wire = static_cast<SimTime>(8 + point->frameBytes + 4) * 80;
    EXPECT_EQ(point->roundTripNs, 710 + sn * 150 + (sn - 1) * 140 + 2 * 35 + 2 * sn * 3 + wire)
        << n;
    EXPECT_EQ(point->wkcErrors, 0u);
  }
}

// The published EtherCAT figures (docs/timing.md, "Published figures"), each with the network
// documented there, are reproduced within 10 %.
TEST(LatencyStudy, PublishedFiguresAreReproducedWithinTenPercent) {
  VirtualClock cpu;
  const auto figures = publishedFigures();
  ASSERT_EQ(figures.size(), 5u);
  for (const auto& f : figures) {
    auto point = runLatencyPoint(f.parameters, cpu);
    ASSERT_TRUE(point.ok()) << f.name << ": " << point.error().message();
    EXPECT_EQ(point->framesPerCycle, 1u) << f.name;
    EXPECT_EQ(point->wkcErrors, 0u) << f.name;
    const double ratio =
        static_cast<double>(point->roundTripNs) / static_cast<double>(f.publishedNs);
    EXPECT_GT(ratio, 0.9) << f.name << ": " << point->roundTripNs << " ns";
    EXPECT_LT(ratio, 1.1) << f.name << ": " << point->roundTripNs << " ns";
    // And each is the closed form, to the nanosecond.
    EXPECT_EQ(point->roundTripNs, closedFormLineRoundTrip(f.parameters, point->frameBytes))
        << f.name;
  }
}

// The same 100 axes as 100BASE-TX drives (1000 ns per passage, 1 m cables) are far slower:
// the published 100 us holds only for EBUS-class delays (~0.3 us per axis), docs/timing.md.
TEST(LatencyStudy, HundredAxesOver100BaseTxTakeLongerThanThePublishedFigure) {
  VirtualClock cpu;
  StudyParameters p;
  p.slaves = 100;
  p.bytesPerSlave = 8;
  p.distributedClock = false;
  p.repetitions = 2;
  auto point = runLatencyPoint(p, cpu);
  ASSERT_TRUE(point.ok());
  // 67.2 us of wire (840 B) + 100 x 1000 + 99 x 1000 + 2 x 100 x 5 ns.
  EXPECT_EQ(point->roundTripNs, 67'200 + 199'000 + 1'000);
}

}  // namespace
}  // namespace ecsim::topology
