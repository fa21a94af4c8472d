// Our master's BOOT and FoE (master_foe.cpp, foe_client.hpp) against the SOES demo slave of
// ../shared/esi/SOES_lan9252demo_slave.xml (BootStrap 0x1000/128, 0x1080/128; Mailbox/FoE):
// INIT -> BOOT with the SII's bootstrap mailbox, a write of several packets, the same bytes
// read back, an ERR decoded to its code and text, BOOT -> INIT with the standard mailbox back,
// and FoE in PREOP as the ESI allows it.
#include "master/foe_client.hpp"

#include <gtest/gtest.h>

#include <filesystem>

#include "config/esi.hpp"
#include "master/master.hpp"
#include "slavesim/esi_slave.hpp"
#include "support/test_network.hpp"
#include "tests/master/sim_network.hpp"
#include "tests/master/test_slaves.hpp"

namespace ecsim::testing {
namespace {

const std::filesystem::path kSoes = sharedDir() / "esi" / "SOES_lan9252demo_slave.xml";

std::vector<std::uint8_t> pattern(std::size_t n) {
  std::vector<std::uint8_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<std::uint8_t>(i * 13 + 1);
  return v;
}

TEST(FoeClient, BootWriteReadBackAndErrors) {
  ECSIM_REQUIRE_SHARED(kSoes);
  auto file = loadEsiFile(kSoes);
  ASSERT_TRUE(file.ok());
  SimNetwork net;
  auto slave = slavesim::makeSlaveFromEsi(*file, file->devices.at(0), "soes");
  ASSERT_TRUE(slave.ok()) << slave.error().message();
  net.segment().addSlave(std::move(slave).value());
  net.segment().wireLine();
  net.start();
  master::Master m(net.masterLink(), net.bus());
  ASSERT_TRUE(m.scan().ok());
  ASSERT_TRUE(m.bringTo(AlState::kPreOp).ok());

  auto boot = m.enterBootstrap(0);
  ASSERT_TRUE(boot.ok()) << boot.error().message();
  EXPECT_EQ(net.segment().slave(0).state(), AlState::kBootstrap);
  EXPECT_EQ(m.slaves()[0].mailbox->outStart, 0x1000);
  EXPECT_EQ(m.slaves()[0].mailbox->outSize, 128);

  // 1000 bytes: 8 full packets of 116 and one of 72.
  const auto image = pattern(1000);
  auto w = m.foeWrite(0, "fw.bin", image);
  ASSERT_TRUE(w.ok()) << w.error().message();
  auto r = m.foeRead(0, "fw.bin");
  ASSERT_TRUE(r.ok()) << r.error().message();
  EXPECT_EQ(*r, image);
  // A size that is a multiple of 116: the empty last packet both ways.
  const auto exact = pattern(348);
  ASSERT_TRUE(m.foeWrite(0, "exact.bin", exact).ok());
  EXPECT_EQ(m.foeRead(0, "exact.bin").value(), exact);

  auto missing = m.foeRead(0, "nothing.bin");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().code, ErrorCode::kAborted);
  EXPECT_NE(missing.error().context.find("ERR 0x8001 (not found)"), std::string::npos)
      << missing.error().context;
  EXPECT_NE(missing.error().context.find("'nothing.bin'"), std::string::npos);
  auto sdo = m.sdoUpload(0, 0x1018, 1);
  EXPECT_FALSE(sdo.ok()) << "no CoE in BOOT";

  ASSERT_TRUE(m.leaveBootstrap(0).ok());
  EXPECT_EQ(net.segment().slave(0).state(), AlState::kInit);
  ASSERT_TRUE(m.bringTo(AlState::kPreOp).ok());
  // The ESI mailbox has <FoE/>: files are reachable in PREOP too.
  EXPECT_EQ(m.foeRead(0, "fw.bin").value(), image);
  EXPECT_TRUE(m.sdoUpload(0, 0x1018, 1).ok());
}

// A bootstrap mailbox laid out unlike the standard one (examples/esi/ecsim_foe_module.xml:
// BOOT 0x1000/512 and 0x1200/512, standard 0x1000/128 and 0x1080/128). Back in INIT the SMs
// still hold the bootstrap layout, enabled: the slave's firmware only deactivates them through
// the PDI, and an SM's start, length and control take an ECAT write only while its enable bit
// is off (ESC datasheet section II 0x0800-0x0805). So the standard mailbox goes in only after
// the master switches SM0/SM1 off first, as SOEM (ecx_set_slaves_to_default, 0x0800 zeroed)
// and IgH (fsm_slave_config "clear sync managers") do before configuring them. Also for a
// master started afresh that leaves the slaves as they are (no reset of the defaults, as
// `ecmaster upload` after `ecmaster foe write --boot`); otherwise PREOP is refused with 0x0016.
TEST(FoeClient, AfterBootTheStandardMailboxReplacesTheBootstrapLayout) {
  auto file =
      loadEsiFile(std::filesystem::path(ECSIM_SOURCE_DIR) / "examples/esi/ecsim_foe_module.xml");
  ASSERT_TRUE(file.ok()) << file.error().message();
  SimNetwork net;
  auto slave = slavesim::makeSlaveFromEsi(*file, file->devices.at(0), "module");
  ASSERT_TRUE(slave.ok()) << slave.error().message();
  net.segment().addSlave(std::move(slave).value());
  net.segment().wireLine();
  net.start();
  {
    master::Master m(net.masterLink(), net.bus());
    ASSERT_TRUE(m.scan().ok());
    ASSERT_TRUE(m.enterBootstrap(0).ok());
    EXPECT_EQ(m.slaves()[0].mailbox->outSize, 512);
    ASSERT_TRUE(m.foeWrite(0, "fw.bin", pattern(600)).ok());
    ASSERT_TRUE(m.leaveBootstrap(0).ok());
    auto preop = m.bringTo(AlState::kPreOp);
    ASSERT_TRUE(preop.ok()) << preop.error().message();
    EXPECT_EQ(net.segment().slave(0).esc().smConfig(0).length, 128);
    ASSERT_TRUE(m.enterBootstrap(0).ok());
    ASSERT_TRUE(m.leaveBootstrap(0).ok());
  }
  master::MasterOptions options;
  options.scan.resetToDefaults = false;
  master::Master again(net.masterLink(), net.bus(), options);
  ASSERT_TRUE(again.scan().ok());
  auto preop = again.bringTo(AlState::kPreOp);
  ASSERT_TRUE(preop.ok()) << preop.error().message();
  EXPECT_EQ(net.segment().slave(0).state(), AlState::kPreOp);
  EXPECT_TRUE(again.sdoUpload(0, 0x1018, 1).ok());
}

TEST(FoeClient, BootNeedsABootstrapMailbox) {
  SimNetwork net;
  auto od = std::make_shared<slavesim::coe::ObjectDictionary>();
  slavesim::coe::addIdentityObject(*od, {kTestVendor, 0xCA, 1, 2});
  net.segment().addSlave(makeCoeSlave("NoBoot", 0xCA, od));
  net.segment().wireLine();
  net.start();
  master::Master m(net.masterLink(), net.bus());
  ASSERT_TRUE(m.scan().ok());
  auto boot = m.enterBootstrap(0);
  ASSERT_FALSE(boot.ok());
  EXPECT_EQ(boot.error().code, ErrorCode::kUnsupported);
  EXPECT_NE(boot.error().context.find("no bootstrap mailbox"), std::string::npos);
  // Without FoE in the slave: the mailbox error, as text.
  ASSERT_TRUE(m.bringTo(AlState::kPreOp).ok());
  auto r = m.foeRead(0, "x");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message().find("FoE read of 'x'"), std::string::npos) << r.error().message();
}

}  // namespace
}  // namespace ecsim::testing
