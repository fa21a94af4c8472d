// The passes that visit only the ESCs a frame concerns (segment_index.cpp, issue #18 item 3)
// must give the same frames and ESC state as visiting every ESC: two copies of one network,
// one with the index and one without, get the same random frames (configured-address and
// auto-increment reads and writes of the station address, alias, DL control, AL control and
// status, ECAT event mask and request, SII, SyncManagers, the receive-time latch and RAM,
// with broadcasts, NOPs and FRMW/ARMW among them) and their firmware is polled alike; every
// returned datagram, every register and every frame count must match.
#include <gtest/gtest.h>

#include <random>

#include "support/test_network.hpp"

namespace ecsim::testing {
namespace {

// 12 slaves: a line with a branch (slave 5 is a junction: its port 3 leads to 9-11), every
// other one with firmware (no device emulation: its state machine checks AL control).
void build(topology::Segment& seg) {
  for (std::uint32_t i = 0; i < 12; ++i) {
    std::vector<std::uint8_t> sii = makeSii(0x0000ABCD, 0x100 + i);
    if (i % 2 == 1) sii = withoutDeviceEmulation(std::move(sii));
    seg.addSlave(makeSlave("s" + std::to_string(i), 0x100 + i, {}, std::move(sii)));
  }
  for (std::size_t i = 0; i + 1 < 9; ++i) ASSERT_TRUE(seg.connect(i, 1, i + 1, 0).ok());
  ASSERT_TRUE(seg.connect(5, 3, 9, 0).ok());
  ASSERT_TRUE(seg.connect(9, 1, 10, 0).ok());
  ASSERT_TRUE(seg.connect(10, 1, 11, 0).ok());
  seg.refreshLinkStatus();
}

// A random datagram of the kinds a master sends during bring-up and cyclic operation.
DatagramSpec randomDatagram(std::mt19937& rng) {
  auto pick = [&](std::uint32_t n) {
    return std::uniform_int_distribution<std::uint32_t>(0, n - 1)(rng);
  };
  // Station addresses and aliases from a small set, so that duplicates come and go.
  const std::uint16_t addresses[] = {0x0000, 0x1001, 0x1002, 0x1003, 0x1004,
                                     0x1005, 0x1006, 0x2000, 0x2001};
  const auto address = addresses[pick(9)];
  const auto position = static_cast<std::uint16_t>(-static_cast<int>(pick(14)));  // 0, -1, ... -13
  struct Target {
    std::uint16_t ado;
    std::uint16_t length;
  };
  const Target targets[] = {
      {reg::kConfiguredStationAddress.address, 2},
      {reg::kConfiguredStationAlias.address, 2},
      {reg::kDlControl.address, 4},
      {reg::kAlControl.address, 2},
      {reg::kAlStatus.address, 6},
      {reg::kEcatEventMask.address, 2},
      {reg::kEcatEventRequest.address, 2},
      {reg::kSiiControlStatus.address, 6},
      {reg::smChannel(0), 8},
      {reg::kReceiveTimePort0.address, 4},
      {0x1000, 8},
  };
  const Target t = targets[pick(11)];
  std::vector<std::uint8_t> data(t.length);
  for (auto& b : data) b = static_cast<std::uint8_t>(pick(256));
  if (t.ado == reg::kConfiguredStationAddress.address ||
      t.ado == reg::kConfiguredStationAlias.address) {
    const auto a = addresses[pick(9)];
    data = {static_cast<std::uint8_t>(a), static_cast<std::uint8_t>(a >> 8)};
  }
  if (t.ado == reg::kAlControl.address) data = {static_cast<std::uint8_t>(1u << pick(4)), 0};
  if (t.ado == reg::kEcatEventMask.address) {
    const std::uint16_t masks[] = {0x0000, 0x0004, 0x0FF0, 0x0014};
    data = le16(masks[pick(4)]);
  }
  if (t.ado == reg::kDlControl.address)
    data = {0x01, 0x00, 0x00, static_cast<std::uint8_t>(pick(2))};
  const Command configured[] = {Command::kFprd, Command::kFpwr, Command::kFprw};
  const Command autoIncrement[] = {Command::kAprd, Command::kApwr, Command::kAprw};
  const Command everywhere[] = {Command::kBrd, Command::kBwr, Command::kFrmw, Command::kArmw,
                                Command::kNop};
  const std::uint32_t kind = pick(10);
  if (kind < 5) return {configured[pick(3)], phys(address, t.ado), data};
  if (kind < 9) return {autoIncrement[pick(3)], phys(position, t.ado), data};
  const Command c = everywhere[pick(5)];
  return {c, phys(c == Command::kFrmw ? address : (c == Command::kArmw ? position : 0), t.ado),
          data};
}

TEST(SegmentIndex, VisitingOnlyTheEscsConcernedChangesNothing) {
  topology::Segment indexed;
  topology::Segment everyEsc;
  build(indexed);
  build(everyEsc);
  everyEsc.setIndexedPasses(false);
  std::mt19937 rng(20261129);
  SimTime now = 0;
  std::size_t frames = 0;
  for (; frames < 6000; ++frames) {
    std::vector<DatagramSpec> specs;
    // Mostly frames without broadcasts (the ones the index serves), some with.
    const bool allowEverywhere = frames % 7 == 0;
    const std::size_t n = 1 + frames % 5;
    while (specs.size() < n) {
      DatagramSpec d = randomDatagram(rng);
      const AddressMode mode = addressMode(d.command);
      const bool everywhere = mode == AddressMode::kBroadcast || mode == AddressMode::kNone ||
                              d.command == Command::kFrmw || d.command == Command::kArmw;
      if (everywhere && !allowEverywhere) continue;
      specs.push_back(std::move(d));
    }
    now += 50 * kNsPerUs;
    const auto a = exchange(indexed, specs, now);
    const auto b = exchange(everyEsc, specs, now);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      ASSERT_EQ(a[i].adp, b[i].adp) << "frame " << frames << " datagram " << i;
      ASSERT_EQ(a[i].wkc, b[i].wkc) << "frame " << frames << " datagram " << i;
      ASSERT_EQ(a[i].irq, b[i].irq) << "frame " << frames << " datagram " << i;
      ASSERT_EQ(a[i].data, b[i].data) << "frame " << frames << " datagram " << i;
    }
  }
  for (std::size_t s = 0; s < indexed.size(); ++s) {
    for (std::uint16_t r = 0; r < 0x1000; ++r) {
      ASSERT_EQ(indexed.slave(s).esc().reg8(r), everyEsc.slave(s).esc().reg8(r))
          << "slave " << s << " register 0x" << std::hex << r;
    }
    EXPECT_EQ(indexed.framesSeen(s), everyEsc.framesSeen(s)) << "slave " << s;
    EXPECT_EQ(indexed.slave(s).state(), everyEsc.slave(s).state()) << "slave " << s;
  }
  // The index was used (the other frames changed the route, or held a broadcast).
  EXPECT_GT(indexed.counters().framesAddressedPass, frames / 3);
  EXPECT_EQ(everyEsc.counters().framesAddressedPass, 0u);
  std::printf("%llu of %zu frames passed by the index\n",
              static_cast<unsigned long long>(indexed.counters().framesAddressedPass), frames);
}

// A frame of single-slave datagrams touches only the ESCs they address, however long the line:
// the ESCs before and after see the frame pass (counted) without a visit.
TEST(SegmentIndex, AnAddressedFrameVisitsOnlyItsEsc) {
  topology::Segment seg;
  buildLine(seg, 200);
  for (std::uint16_t i = 0; i < 200; ++i) {
    const auto r = one(seg, Command::kApwr,
                       phys(static_cast<std::uint16_t>(-i), reg::kConfiguredStationAddress.address),
                       le16(static_cast<std::uint16_t>(0x1001 + i)));
    ASSERT_EQ(r.wkc, 1);
    EXPECT_EQ(r.adp, static_cast<std::uint16_t>(-i + 200)) << "every ESC counted the ADP on";
  }
  const std::uint64_t before = seg.slave(0).esc().counters().framesSeen;
  const auto r =
      one(seg, Command::kFprd, phys(0x1001 + 150, reg::kConfiguredStationAddress.address), {0, 0});
  EXPECT_EQ(r.wkc, 1);
  EXPECT_EQ(r.data, le16(0x1001 + 150));
  EXPECT_EQ(seg.slave(0).esc().counters().framesSeen, before) << "slave 0 was not visited";
  EXPECT_EQ(seg.framesSeen(0), 201u) << "but the frame passed it";
  EXPECT_EQ(seg.framesSeen(199), seg.framesSeen(0));
}

}  // namespace
}  // namespace ecsim::testing
