// libFuzzer target for the simulator's frame path: arbitrary datagram chains go through a
// small network (a generic slave, a slave with mailbox SMs and a CoE server, a slave with
// process-data SMs and bit-granular FMMUs) and its firmware runs after each frame. Any crash,
// out-of-bounds access, leak or undefined behaviour is a finding.
//
// Input: a sequence of chunks [u16 little-endian length][bytes]; each chunk becomes the
// datagram area of one EtherCAT frame behind a fixed Ethernet + EtherCAT header.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "protocol/frame.hpp"
#include "protocol/registers.hpp"
#include "slavesim/coe/coe_server.hpp"
#include "slavesim/coe/standard_objects.hpp"
#include "slavesim/generic_slave.hpp"
#include "topology/segment.hpp"

namespace {

using namespace ecsim;

void sm(slavesim::Esc& esc, unsigned n, std::uint16_t start, std::uint16_t len, std::uint8_t ctrl) {
  const std::uint16_t base = reg::smChannel(n);
  esc.pdiWrite16(base + reg::sm::kPhysicalStart.address, start);
  esc.pdiWrite16(base + reg::sm::kLength.address, len);
  esc.pdiWrite8(base + reg::sm::kControl.address, ctrl);
  esc.pdiWrite8(base + reg::sm::kActivate.address, reg::sm::kActivateEnable);
}

void fmmu(slavesim::Esc& esc, unsigned n, std::uint32_t logical, std::uint16_t len,
          std::uint8_t startBit, std::uint8_t stopBit, std::uint16_t phys, std::uint8_t physBit,
          std::uint8_t type) {
  const std::uint16_t base = reg::fmmuChannel(n);
  esc.pdiWrite32(base + reg::fmmu::kLogicalStart.address, logical);
  esc.pdiWrite16(base + reg::fmmu::kLength.address, len);
  esc.pdiWrite8(base + reg::fmmu::kLogicalStartBit.address, startBit);
  esc.pdiWrite8(base + reg::fmmu::kLogicalStopBit.address, stopBit);
  esc.pdiWrite16(base + reg::fmmu::kPhysicalStart.address, phys);
  esc.pdiWrite8(base + reg::fmmu::kPhysicalStartBit.address, physBit);
  esc.pdiWrite8(base + reg::fmmu::kType.address, type);
  esc.pdiWrite8(base + reg::fmmu::kActivate.address, 1);
}

std::unique_ptr<topology::Segment> makeNetwork() {
  auto seg = std::make_unique<topology::Segment>();
  for (int i = 0; i < 3; ++i) {
    seg->addSlave(
        slavesim::makeGenericSlave("s" + std::to_string(i), static_cast<std::uint32_t>(i)));
    seg->slave(static_cast<std::size_t>(i))
        .esc()
        .pdiWrite16(reg::kConfiguredStationAddress.address, static_cast<std::uint16_t>(0x1001 + i));
  }
  seg->wireLine();
  // Slave 2 (0x1002): mailbox SMs and a CoE server with a small dictionary.
  auto& mbx = seg->slave(1);
  sm(mbx.esc(), 0, 0x1000, 128, 0x26);
  sm(mbx.esc(), 1, 0x1080, 128, 0x22);
  mbx.profile().mailbox = slavesim::SlaveProfile::Mailbox{0x1000, 128, 0x1080, 128};
  auto od = std::make_shared<slavesim::coe::ObjectDictionary>();
  slavesim::coe::addIdentityObject(*od, {0xE5C, 0x7201, 0x10000, 7});
  od->addString(0x1008, "Device name", "fuzz drive with a name longer than a mailbox segment");
  mbx.setMailboxServer(std::make_unique<slavesim::coe::CoeServer>(od));
  mbx.esc().pdiSetAlStatus(static_cast<std::uint16_t>(AlState::kPreOp), 0);
  // Slave 3 (0x1003): process data with byte and bit FMMUs.
  auto& pd = seg->slave(2).esc();
  sm(pd, 2, 0x1100, 4, 0x64);
  sm(pd, 3, 0x1180, 4, 0x20);
  fmmu(pd, 0, 0x0, 4, 0, 7, 0x1100, 0, 2);
  fmmu(pd, 1, 0x4, 4, 0, 7, 0x1180, 0, 1);
  fmmu(pd, 2, 0x8, 1, 3, 5, 0x1102, 1, 3);
  return seg;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static std::unique_ptr<topology::Segment> seg;  // rebuilt per input: no state carries over
  seg = makeNetwork();
  std::array<std::uint8_t, kMaxFrameSize> frame{};
  SimTime now = 1'000'000;
  std::size_t at = 0;
  while (at + 2 <= size) {
    const std::size_t len =
        std::min<std::size_t>(readLe16(ConstBytes(data, size), at), size - at - 2);
    at += 2;
    const std::size_t body = std::min<std::size_t>(len, kMaxFrameSize - 16);
    frame.fill(0);
    for (int i = 0; i < 6; ++i) frame[static_cast<std::size_t>(i)] = 0xFF;
    frame[12] = 0x88;
    frame[13] = 0xA4;
    writeLe16(Bytes(frame), 14, static_cast<std::uint16_t>(0x1000 | (body & 0x7FF)));
    for (std::size_t i = 0; i < body; ++i) frame[16 + i] = data[at + i];
    at += len;
    const std::size_t total = std::max<std::size_t>(16 + body, kMinFrameSize);
    seg->processFrame(Bytes(frame.data(), total), now);
    seg->pollSlaves(now);
    now += 100'000;
  }
  return 0;
}
