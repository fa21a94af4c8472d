// BOOT state and FoE (ETG.1000.6 §5.7, issue #20) on the SOES demo slave of
// ../shared/esi/SOES_lan9252demo_slave.xml (Mailbox/FoE, BootStrap 0010800080108000 at line
// 686: bootstrap mailbox 0x1000/128 out, 0x1080/128 in), reached only through frames: the SII
// bootstrap words read as SOEM's firm_update reads them, the SMs written from them, INIT->BOOT,
// FoE write / read with the packet numbering of SOEM's ecx_FOEwrite / ecx_FOEread, and a power
// cycle that boots the image written in BOOT (its software version 0x100A).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "config/esi.hpp"
#include "protocol/foe.hpp"
#include "slavesim/esi_slave.hpp"
#include "slavesim/foe/foe_server.hpp"
#include "tests/slavesim/foe_test_support.hpp"

namespace ecsim::testing {
namespace {

TEST(FoeServer, BootNeedsTheBootstrapMailboxLayout) {
  FoeSlave s;
  ECSIM_REQUIRE_SHARED(sharedDir() / "esi" / "SOES_lan9252demo_slave.xml");
  ASSERT_TRUE(s.ready());
  EXPECT_EQ(s.bootOut, 0x1000);
  EXPECT_EQ(s.bootOutSize, 128);
  EXPECT_EQ(s.bootIn, 0x1080);
  EXPECT_EQ(s.bootInSize, 128);
  // SM1 too large for the bootstrap mailbox: refused with 0x0015 (invalid mailbox
  // configuration, BOOT; ETG.1000.6 Table 11), INIT kept with the error flag.
  one(s.seg, Command::kFpwr, phys(kStation, reg::smChannel(0)),
      smRegisterBytes(s.bootOut, s.bootOutSize, 0x26));
  one(s.seg, Command::kFpwr, phys(kStation, reg::smChannel(1)),
      smRegisterBytes(s.bootIn, 256, 0x22));
  requestState(s.seg, kStation, kBoot);
  EXPECT_EQ(alStatus(s.seg, kStation), 0x0011);
  EXPECT_EQ(alStatusCode(s.seg, kStation), 0x0015);
  requestState(s.seg, kStation, kInit | 0x10);  // acknowledge
  EXPECT_EQ(alStatus(s.seg, kStation), kInit);
  // An enabled SM keeps its configuration: switched off first, then written as SOEM does.
  one(s.seg, Command::kFpwr, phys(kStation, reg::smChannel(1)), std::vector<std::uint8_t>(8, 0));
  s.toBoot();
  EXPECT_EQ(alStatus(s.seg, kStation), kBoot);
  // BOOT -> PREOP is not a transition (only BOOT -> INIT): 0x0011.
  requestState(s.seg, kStation, 0x0002);
  EXPECT_EQ(alStatusCode(s.seg, kStation), 0x0011);
}

TEST(FoeServer, WriteInBootReadBackAndNewVersionAfterPowerCycle) {
  FoeSlave s;
  ECSIM_REQUIRE_SHARED(sharedDir() / "esi" / "SOES_lan9252demo_slave.xml");
  ASSERT_TRUE(s.ready());
  s.toBoot();
  ASSERT_EQ(alStatus(s.seg, kStation), kBoot);

  // CoE is not served in BOOT: mailbox error "unsupported protocol".
  auto sdo = s.master->transact([&] {
    std::vector<std::uint8_t> m{10, 0, 0, 0, 0, 0x03, 0x00, 0x20, 0x40, 0x0A, 0x10, 0, 0, 0, 0, 0};
    m[5] = static_cast<std::uint8_t>(m[5] | (s.master->nextCounter() << 4));
    return m;
  }());
  ASSERT_TRUE(sdo);
  EXPECT_EQ((*sdo)[5] & 0x0F, 0) << "mailbox error";
  EXPECT_EQ(readLe16(*sdo, 8), 0x0002);

  // 300 bytes through a 128-byte mailbox: DATA 1 and 2 of 116 bytes, DATA 3 of 68.
  const auto image = firmwareImage(300, "2.1.0");
  FoeReply w = s.write("app.bin", image);
  EXPECT_EQ(w.opcode, FoeOpcode::kAck);
  EXPECT_EQ(w.value, 3u);

  // Read back in BOOT: the same bytes in as many packets.
  FoeReply failure;
  EXPECT_EQ(s.read("app.bin", &failure), image);

  // A file of exactly two full packets ends with an empty third (SOEM's "dofinalzero").
  const std::vector<std::uint8_t> twoPackets(232, 0x5A);
  w = s.write("exact.bin", twoPackets);
  EXPECT_EQ(w.value, 3u);
  EXPECT_EQ(s.read("exact.bin"), twoPackets);

  // Before the power cycle the device still reports the version it was built with.
  requestState(s.seg, kStation, kInit);
  auto& slave = s.seg.slave(0);
  auto* files = &dynamic_cast<slavesim::foe::FoeServer*>(
                     slavesim::coeServerOf(slave)->protocol(MailboxType::kFoe))
                     ->files();
  ASSERT_TRUE(files->pendingFirmware());
  EXPECT_EQ(*files->pendingFirmware(), "exact.bin") << "the last file written in BOOT";
  // The firmware to boot is app.bin: write it again, last.
  s.toBoot();
  ASSERT_EQ(alStatus(s.seg, kStation), kBoot);
  EXPECT_EQ(s.write("app.bin", image).value, 3u);
  requestState(s.seg, kStation, kInit);

  MailboxMaster preop(s.seg, kStation, 0x1000, 128, 0x1080, 128);
  preop.configureSyncManagers();
  requestState(s.seg, kStation, 0x0002);
  ASSERT_EQ(alStatus(s.seg, kStation), 0x0002);
  const Upload before = preop.upload(0x100A, 0);
  EXPECT_NE(std::string(before.data.begin(), before.data.end()), "2.1.0");

  slave.powerOff();
  slave.powerOn(0);
  one(s.seg, Command::kApwr, phys(0, reg::kConfiguredStationAddress.address), le16(kStation));
  preop.configureSyncManagers();
  requestState(s.seg, kStation, 0x0002);
  ASSERT_EQ(alStatus(s.seg, kStation), 0x0002);
  const Upload after = preop.upload(0x100A, 0);
  EXPECT_EQ(after.abort, 0u);
  EXPECT_EQ(std::string(after.data.begin(), after.data.end()), "2.1.0");
  // The files outlive the power cycle (the device's flash).
  EXPECT_NE(files->find("app.bin"), nullptr);
}

TEST(FoeServer, ErrorCodes) {
  FoeSlave s;
  ECSIM_REQUIRE_SHARED(sharedDir() / "esi" / "SOES_lan9252demo_slave.xml");
  ASSERT_TRUE(s.ready());
  s.toBoot();
  ASSERT_EQ(alStatus(s.seg, kStation), kBoot);

  FoeReply r = s.transact(FoeOpcode::kRead, 0, std::string_view("missing.bin"));
  EXPECT_EQ(r.opcode, FoeOpcode::kError);
  EXPECT_EQ(r.value, 0x8001u);
  EXPECT_EQ(std::string(r.data.begin(), r.data.end()), "not found");

  // Packet number 2 where 1 is due: 0x8005, and the transfer is over.
  r = s.transact(FoeOpcode::kWrite, 0, std::string_view("f.bin"));
  EXPECT_EQ(r.opcode, FoeOpcode::kAck);
  const std::vector<std::uint8_t> bytes(10, 1);
  r = s.transact(FoeOpcode::kData, 2, bytes);
  EXPECT_EQ(r.opcode, FoeOpcode::kError);
  EXPECT_EQ(r.value, 0x8005u);
  r = s.transact(FoeOpcode::kData, 1, bytes);
  EXPECT_EQ(r.value, 0x8004u) << "DATA without a write in progress is illegal";

  // An ACK nobody asked for, and an unknown opcode.
  EXPECT_EQ(s.transact(FoeOpcode::kAck, 1).value, 0x8004u);
  EXPECT_EQ(s.transact(static_cast<FoeOpcode>(9), 0).value, 0x8004u);

  // A wrong packet number in the ACKs of a read.
  ASSERT_EQ(s.write("r.bin", std::vector<std::uint8_t>(200, 9)).value, 2u);
  r = s.transact(FoeOpcode::kRead, 0, std::string_view("r.bin"));
  EXPECT_EQ(r.opcode, FoeOpcode::kData);
  EXPECT_EQ(r.value, 1u);
  EXPECT_EQ(s.transact(FoeOpcode::kAck, 5).value, 0x8005u);
}

TEST(FoeServer, PasswordBusyAndBootOnlyDevices) {
  // The server alone, behind the CoE test slave's mailbox (PREOP): a bootloader-only FoE
  // (no Mailbox/FoE in the ESI) answers 0x8008 outside BOOT; a password protects both ways.
  CoeTestSlave t;
  slavesim::foe::FoeServerOptions options;
  options.outsideBoot = false;
  auto files = std::make_shared<slavesim::foe::FoeFiles>();
  t.server->addProtocol(std::make_unique<slavesim::foe::FoeServer>(files, options));
  auto ask = [&](FoeOpcode op, std::uint32_t value, std::string_view text) {
    auto m = encodeFoeMailbox(op, value, text);
    m[5] = static_cast<std::uint8_t>(m[5] | (t.master->nextCounter() << 4));
    auto r = t.master->transact(m);
    EXPECT_TRUE(r);
    return decodeFoe(decodeMailbox(*r)->payload).value().value;
  };
  EXPECT_EQ(ask(FoeOpcode::kWrite, 0, "a"), 0x8008u);

  options.outsideBoot = true;
  options.password = 0xC0FFEE;
  options.busyResponses = 2;
  t.server->addProtocol(std::make_unique<slavesim::foe::FoeServer>(files, options));
  EXPECT_EQ(ask(FoeOpcode::kWrite, 0x1234, "a"), 0x800Au) << "wrong password: no rights";
  EXPECT_EQ(ask(FoeOpcode::kWrite, 0xC0FFEE, "a"), 0u) << "ACK 0";
  // The first DATA packet is answered BUSY twice before it is taken.
  auto data = [&](std::uint32_t n) {
    auto m = encodeFoeMailbox(FoeOpcode::kData, n, std::string_view("xyz"));
    m[5] = static_cast<std::uint8_t>(m[5] | (t.master->nextCounter() << 4));
    auto r = t.master->transact(m);
    return decodeFoe(decodeMailbox(*r)->payload).value().opcode;
  };
  EXPECT_EQ(data(1), FoeOpcode::kBusy);
  EXPECT_EQ(data(1), FoeOpcode::kBusy);
  EXPECT_EQ(data(1), FoeOpcode::kAck);
  ASSERT_NE(files->find("a"), nullptr);
  EXPECT_EQ(files->find("a")->size(), 3u);
  EXPECT_FALSE(files->pendingFirmware()) << "written in PREOP: not a firmware image";
  EXPECT_EQ(ask(FoeOpcode::kRead, 0, "a"), 0x800Au);
}

}  // namespace
}  // namespace ecsim::testing
