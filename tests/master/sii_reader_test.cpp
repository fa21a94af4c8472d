// The master's SII reader against an ESC whose EEPROM interface is busy for the time a real
// EEPROM takes (0.53-0.80 ms per read on a real EK1100, ../shared/pcap/replay-dc.pcapng frames
// 104-110): it waits on the bus's clock between status reads, so in virtual time the time
// passes and the read costs a few frames, as SOEM's 200 us polling does on real hardware.
#include "master/sii_reader.hpp"

#include <gtest/gtest.h>

#include "slavesim/generic_slave.hpp"
#include "tests/master/sim_network.hpp"

namespace ecsim::testing {
namespace {

TEST(SiiReaderTest, WaitsOutTheEepromBusyTimeInVirtualTime) {
  SimNetwork net;
  net.segment().addSlave(slavesim::makeGenericSlave("S1", 1));
  net.segment().wireLine();
  net.start();
  master::Transport transport(net.masterLink());
  // Station address first (APWR 0x0010), as the scan does.
  master::Datagram assign;
  std::array<std::uint8_t, 2> station{0x01, 0x10};
  assign.prepare(Command::kApwr, DatagramHeader::physical(0, reg::kConfiguredStationAddress.address),
                 station, 1);
  transport.queue(assign);
  WaitTask wait({&assign});
  ASSERT_TRUE(master::runTask(wait, transport, net.bus(), kNsPerSecond, "assign").ok());

  const std::uint64_t framesBefore = net.fault().sentCount();
  const SimTime start = net.clock().now();
  master::SiiReader reader(transport, 0x1001, true);
  reader.start(start);
  ASSERT_TRUE(master::runTask(reader, transport, net.bus(), 10 * kNsPerSecond, "sii").ok());
  ASSERT_TRUE(reader.status().ok()) << reader.status().error().message();

  const auto& eeprom = net.segment().slave(0).esc().sii();
  ASSERT_LE(reader.image().size(), eeprom.size());
  EXPECT_TRUE(std::equal(reader.image().begin(), reader.image().end(), eeprom.begin()));
  const std::uint64_t reads = reader.reads();
  const SimTime busy = slavesim::kEt1100.siiBusyNs;
  EXPECT_GE(net.clock().now() - start, static_cast<SimTime>(reads) * busy)
      << "virtual time passed for every read's busy time";
  // Command, then a status read every 200 us until busy clears (0.66 ms: 4 reads).
  const std::uint64_t frames = net.fault().sentCount() - framesBefore;
  EXPECT_LE(frames, reads * 5) << reads << " reads took " << frames << " frames";
}

}  // namespace
}  // namespace ecsim::testing
