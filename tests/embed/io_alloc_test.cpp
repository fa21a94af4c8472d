// No heap allocation in the simulator's cyclic path with the IO profiles of vendor devices
// (slavesim/devices/io_profile.hpp): global operator new is replaced in this test binary only
// (its own executable) and counts while the in-process network runs its firmware steps
// (SimulatedNetwork::runFor) between our master's exchanges, after a warm-up. The network:
// Beckhoff_EtherCAT_Terminals.xml EL2004 looped to an EL1004 (model="loopback") and to an
// EL1004 input through an "output" signal, an EL3102 with scripted square inputs, an EL4102,
// and SMC_EX250-SEN1-X156.xml looped to itself (byte-wide channels).
#include <gtest/gtest.h>

#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <new>

#include "embed/testing/network_fixture.hpp"
#include "slavesim/devices/device_models.hpp"
#include "support/test_network.hpp"

#include "support/allocation_counter.hpp"

namespace ecsim::testing {
namespace {

class IoAlloc : public NetworkFixture {
 protected:
  void TearDown() override {
    stopNetwork();
    std::filesystem::remove_all(dir_);
  }
  std::filesystem::path dir_ =
      std::filesystem::temp_directory_path() / ("ecsim-io-alloc-" + std::to_string(::getpid()));
};

TEST_F(IoAlloc, FirmwareStepsOfIoProfilesAllocateNothing) {
  const auto esi = sharedDir() / "esi";
  ECSIM_REQUIRE_SHARED(esi / "Beckhoff_EtherCAT_Terminals.xml");
  ECSIM_REQUIRE_SHARED(esi / "SMC_EX250-SEN1-X156.xml");
  const std::string old = (esi / "Beckhoff_EtherCAT_Terminals.xml").string();
  std::filesystem::create_directories(dir_);
  const auto path = dir_ / "net.xml";
  std::ofstream(path)
      << "<Topology name=\"io-alloc\">\n"
      << "  <Slave name=\"DO\" esi=\"" << old << "\" product=\"#x07D43052\"/>\n"
      << "  <Slave name=\"DI\" esi=\"" << old << "\" product=\"#x03EC3052\" model=\"loopback\">\n"
      << "    <Param name=\"loopback.from\" value=\"DO\"/>\n  </Slave>\n"
      << "  <Slave name=\"DI2\" esi=\"" << old << "\" product=\"#x03EC3052\">\n"
      << "    <Param name=\"signal.1\" value=\"output slave=DO channel=2\"/>\n"
      << "    <Param name=\"signal.2\" value=\"square period=0.01\"/>\n  </Slave>\n"
      << "  <Slave name=\"AI\" esi=\"" << old << "\" product=\"#x0C1E3052\">\n"
      << "    <Param name=\"signal.1\" value=\"square period=0.01 low=-12 high=12\"/>\n"
      << "    <Param name=\"signal.2\" value=\"sine amplitude=5 frequency=50\"/>\n  </Slave>\n"
      << "  <Slave name=\"AO\" esi=\"" << old << "\" product=\"#x10063052\"/>\n"
      << "  <Slave name=\"SMC\" esi=\"" << (esi / "SMC_EX250-SEN1-X156.xml").string()
      << "\" product=\"#x00FA6053\" model=\"loopback\">\n"
      << "    <Param name=\"loopback.from\" value=\"SMC\"/>\n  </Slave>\n"
      << "</Topology>\n";
  auto started = startInProcess(path);
  ASSERT_TRUE(started.ok()) << started.error().message();
  ASSERT_TRUE(master().scan().ok());
  auto op = master().bringTo(AlState::kOp);
  ASSERT_TRUE(op.ok()) << op.error().message();
  auto out = master().variable("DO.0x3001:02");
  ASSERT_TRUE(out.ok()) << out.error().message();
  std::uint64_t counted = 0;
  for (int k = 0; k < 2000; ++k) {
    out->set<bool>((k / 3) % 2 == 0);
    ASSERT_TRUE(master().exchange().ok());
    if (k >= 100) gCounting = true;  // after the warm-up
    const auto s = advance(kNsPerMs);
    gCounting = false;
    ASSERT_TRUE(s.ok());
  }
  counted = gAllocations.load();
  EXPECT_EQ(counted, 0u) << "allocations in 1900 ms of firmware steps";
  // The network did work: the looped input shows the output.
  EXPECT_TRUE(slavesim::devices::digitalInputsOf(network().segment().slave(2))->script(1));
}

}  // namespace
}  // namespace ecsim::testing
