// The EtherCAT state machine against ETG.1000.6 / ESC datasheet section I §10: allowed and
// refused transitions with their AL status codes, error acknowledge, and the configuration
// checks a real slave makes (mailbox SMs at INIT->PREOP, process-data SMs at PREOP->SAFEOP,
// valid outputs at SAFEOP->OP).
#include <gtest/gtest.h>

#include "protocol/al_status.hpp"
#include "support/test_network.hpp"

namespace ecsim::testing {
namespace {

class Esm : public ::testing::Test {
 protected:
  void SetUp() override {
    slavesim::SlaveProfile p;
    p.mailbox = slavesim::SlaveProfile::Mailbox{0x1000, 128, 0x1080, 128};
    p.processData = {{2, true, 2}, {3, false, 4}};
    seg_.addSlave(makeSlave("drive", 7, p, makeSii(0xABCD, 7, 0x1000, 128, 0x1080, 128)));
    one(seg_, Command::kApwr, phys(0, 0x0010), le16(0x1001));
  }
  void request(std::uint16_t control) {
    one(seg_, Command::kFpwr, phys(0x1001, 0x0120), le16(control));
  }
  std::uint16_t status() {
    return readLe16(one(seg_, Command::kFprd, phys(0x1001, 0x0130), {0, 0}).data, 0);
  }
  std::uint16_t code() {
    return readLe16(one(seg_, Command::kFprd, phys(0x1001, 0x0134), {0, 0}).data, 0);
  }
  void configureMailbox() {
    one(seg_, Command::kFpwr, phys(0x1001, 0x0800), smChannelBytes(0x1000, 128, 0x26));
    one(seg_, Command::kFpwr, phys(0x1001, 0x0808), smChannelBytes(0x1080, 128, 0x22));
  }
  void configureProcessData(std::uint16_t outLen = 2, std::uint16_t inLen = 4) {
    one(seg_, Command::kFpwr, phys(0x1001, 0x0810), smChannelBytes(0x1100, outLen, 0x64));
    one(seg_, Command::kFpwr, phys(0x1001, 0x0818), smChannelBytes(0x1180, inLen, 0x20));
  }
  topology::Segment seg_;
};

TEST_F(Esm, StartsInInit) {
  EXPECT_EQ(status(), 0x0001);
}

TEST_F(Esm, InitToPreOpNeedsTheMailboxConfigured) {
  request(0x0002);
  EXPECT_EQ(status(), 0x0011) << "INIT + error";
  EXPECT_EQ(code(), 0x0016) << "invalid mailbox configuration";
  configureMailbox();
  request(0x0012);  // PREOP with acknowledge
  EXPECT_EQ(status(), 0x0002);
  EXPECT_EQ(code(), 0x0000);
}

TEST_F(Esm, MailboxAtWrongAddressRefused) {
  one(seg_, Command::kFpwr, phys(0x1001, 0x0800), smChannelBytes(0x1200, 128, 0x26));
  one(seg_, Command::kFpwr, phys(0x1001, 0x0808), smChannelBytes(0x1080, 128, 0x22));
  request(0x0002);
  EXPECT_EQ(code(), 0x0016);
}

TEST_F(Esm, SkippingStatesIsInvalid) {
  request(0x0004);
  EXPECT_EQ(status(), 0x0011);
  EXPECT_EQ(code(), 0x0011) << "INIT->SAFEOP: invalid requested state change";
  configureMailbox();
  request(0x0012);
  request(0x0008);
  EXPECT_EQ(status(), 0x0012);
  EXPECT_EQ(code(), 0x0011) << "PREOP->OP";
}

TEST_F(Esm, UnknownStateCode) {
  request(0x0005);
  EXPECT_EQ(status(), 0x0011);
  EXPECT_EQ(code(), 0x0012);
}

// Explicit Device ID (ETG.1020 §22.2.2), as the Beckhoff slave stack's SetALStatus shows it:
// while AL control bit 5 requests it, AL status bit 5 ("ID loaded") and the ID in 0x0134, but
// only without an error indication; a request without bit 5 withdraws both.
TEST_F(Esm, ExplicitDeviceIdShownWhileRequested) {
  seg_.slave(0).profile().explicitDeviceId = 0x0105;
  request(0x0021);  // INIT + ID request
  EXPECT_EQ(status(), 0x0021);
  EXPECT_EQ(code(), 0x0105);
  request(0x0001);
  EXPECT_EQ(status(), 0x0001);
  EXPECT_EQ(code(), 0x0000);
  configureMailbox();
  request(0x0022);  // the request holds in any state outside BOOT
  EXPECT_EQ(status(), 0x0022);
  EXPECT_EQ(code(), 0x0105);
}

TEST_F(Esm, ExplicitDeviceIdGivesWayToAnError) {
  seg_.slave(0).profile().explicitDeviceId = 0x0105;
  request(0x0022);  // PREOP + ID request, mailbox not configured
  EXPECT_EQ(status(), 0x0011) << "INIT + error, no ID";
  EXPECT_EQ(code(), 0x0016);
  request(0x0021);  // still an error: the request is ignored until acknowledged
  EXPECT_EQ(code(), 0x0016);
  request(0x0031);  // acknowledged, ID requested
  EXPECT_EQ(status(), 0x0021);
  EXPECT_EQ(code(), 0x0105);
}

TEST_F(Esm, DeviceWithoutExplicitDeviceIdIgnoresTheRequest) {
  request(0x0021);
  EXPECT_EQ(status(), 0x0001);
  EXPECT_EQ(code(), 0x0000);
}

TEST_F(Esm, BootstrapNotSupportedWithoutBootMailbox) {
  request(0x0003);
  EXPECT_EQ(code(), 0x0013);
}

TEST_F(Esm, ErrorStaysUntilAcknowledged) {
  request(0x0004);
  ASSERT_EQ(status(), 0x0011);
  configureMailbox();
  request(0x0002);  // no ack: ignored
  EXPECT_EQ(status(), 0x0011);
  request(0x0012);
  EXPECT_EQ(status(), 0x0002);
}

TEST_F(Esm, PreOpToSafeOpChecksProcessDataSms) {
  configureMailbox();
  request(0x0012);
  configureProcessData(3, 4);  // outputs should be 2 bytes
  request(0x0004);
  EXPECT_EQ(status(), 0x0012);
  EXPECT_EQ(code(), 0x001D) << "invalid output configuration";
  one(seg_, Command::kFpwr, phys(0x1001, 0x0816), {0});
  one(seg_, Command::kFpwr, phys(0x1001, 0x081E), {0});
  configureProcessData(2, 5);
  request(0x0014);
  EXPECT_EQ(code(), 0x001E) << "invalid input configuration";
  one(seg_, Command::kFpwr, phys(0x1001, 0x081E), {0});
  configureProcessData(2, 4);
  request(0x0014);
  EXPECT_EQ(status(), 0x0004);
}

TEST_F(Esm, SafeOpToOpNeedsValidOutputs) {
  configureMailbox();
  request(0x0012);
  configureProcessData();
  request(0x0004);
  ASSERT_EQ(status(), 0x0004);
  request(0x0008);
  EXPECT_EQ(status(), 0x0014);
  EXPECT_EQ(code(), 0x0019) << "no valid outputs";
  one(seg_, Command::kFpwr, phys(0x1001, 0x1100), {1, 2});
  request(0x0018);
  EXPECT_EQ(status(), 0x0008);
}

TEST_F(Esm, DownwardTransitionsAlwaysAllowed) {
  configureMailbox();
  request(0x0012);
  configureProcessData();
  request(0x0004);
  one(seg_, Command::kFpwr, phys(0x1001, 0x1100), {1, 2});
  request(0x0008);
  ASSERT_EQ(status(), 0x0008);
  request(0x0002);  // OP -> PREOP
  EXPECT_EQ(status(), 0x0002);
  request(0x0001);
  EXPECT_EQ(status(), 0x0001);
}

TEST_F(Esm, BroadcastAlStatusOrsAllSlaves) {
  seg_.addSlave(makeSlave("io", 8));
  seg_.wireLine();
  configureMailbox();
  request(0x0012);
  auto r = one(seg_, Command::kBrd, phys(0, 0x0130), {0, 0});
  EXPECT_EQ(r.wkc, 2);
  EXPECT_EQ(r.data[0], 0x03) << "PREOP | INIT";
}

TEST_F(Esm, FirmwareErrorDropsToSafeOp) {
  configureMailbox();
  request(0x0012);
  configureProcessData();
  request(0x0004);
  one(seg_, Command::kFpwr, phys(0x1001, 0x1100), {1, 2});
  request(0x0008);
  ASSERT_EQ(status(), 0x0008);
  seg_.slave(0).stateMachine().raiseError(seg_.slave(0).esc(), AlState::kSafeOp, 0x001B);
  EXPECT_EQ(status(), 0x0014);
  EXPECT_EQ(code(), 0x001B);
}

// Device emulation (ESC configuration 0x0141 bit 0, loaded from SII word 0; the EL2004
// configuration area of makeSii has it): the ESC copies AL control into AL status as written,
// error-acknowledge bit included, and checks nothing (ESC datasheet section II 0x0120 note).
class DeviceEmulation : public ::testing::Test {
 protected:
  void SetUp() override {
    slavesim::SlaveProfile p;
    p.processData = {{2, true, 2}};  // a firmware would want its outputs SM for SAFEOP
    seg_.addSlave(makeSlave("io", 7, p));
    one(seg_, Command::kApwr, phys(0, 0x0010), le16(0x1001));
  }
  std::uint32_t statusAndCode() {  // AL status (low word) and AL status code (high word)
    const auto r = one(seg_, Command::kFprd, phys(0x1001, 0x0130), std::vector<std::uint8_t>(6));
    return readLe16(r.data, 0) | (static_cast<std::uint32_t>(readLe16(r.data, 4)) << 16);
  }
  topology::Segment seg_;
};

TEST_F(DeviceEmulation, AlControlCopiedAsWrittenErrorAcknowledgeIncluded) {
  ASSERT_TRUE(seg_.slave(0).esc().deviceEmulation());
  // replay-dc.pcapng frame 4 (BWR 0x0120 = 0x0011) and frame 96 (AL status 0x0011): a real
  // EK1100 shows INIT with the error bit, its acknowledge copied; soem-sdinfo frames 5/133.
  one(seg_, Command::kBwr, phys(0, 0x0120), le16(0x0011));
  EXPECT_EQ(statusAndCode(), 0x0011u);
  // soem-sdinfo-ek1100-el1004.pcapng frame 197 (FPWR 0x0012) and frame 291 (0x0012).
  one(seg_, Command::kFpwr, phys(0x1001, 0x0120), le16(0x0012));
  EXPECT_EQ(statusAndCode(), 0x0012u);
  // Frames 445/479: SAFEOP as written; replay-dc.pcapng frames 3064/3070: OP.
  one(seg_, Command::kFpwr, phys(0x1001, 0x0120), le16(0x0004));
  EXPECT_EQ(statusAndCode(), 0x0004u);
  one(seg_, Command::kFpwr, phys(0x1001, 0x0120), le16(0x0008));
  EXPECT_EQ(statusAndCode(), 0x0008u);
}

TEST_F(DeviceEmulation, NoStateChecks) {
  // INIT -> OP directly, without SyncManagers, as simple IO terminals allow.
  one(seg_, Command::kFpwr, phys(0x1001, 0x0120), le16(0x0008));
  EXPECT_EQ(statusAndCode(), 0x0008u) << "a firmware would refuse with 0x0011 (INIT + error)";
}

// Without device emulation AL control behaves like a mailbox: once written by ECAT it cannot
// be written again until the PDI has read it, and the PDI read clears AL event request 0x0220
// bit 0 (section II 0x0120 note). The firmware runs between frames, so two writes in one frame
// meet a full "mailbox". The datasheet does not say whether the refused write counts; as for a
// full SyncManager mailbox, it gets no working counter.
class AlControlMailbox : public ::testing::Test {
 protected:
  void SetUp() override {
    seg_.addSlave(makeSlave("fw", 7, {}, withoutDeviceEmulation(makeSii(0xABCD, 7))));
    one(seg_, Command::kApwr, phys(0, 0x0010), le16(0x1001));
  }
  topology::Segment seg_;
};

TEST_F(AlControlMailbox, SecondWriteBeforeTheFirmwareReadIsRefused) {
  ASSERT_FALSE(seg_.slave(0).esc().deviceEmulation());
  const auto r = exchange(seg_, {{Command::kFpwr, phys(0x1001, 0x0120), le16(0x0001)},
                                 {Command::kFpwr, phys(0x1001, 0x0120), le16(0x0002)},
                                 {Command::kFprd, phys(0x1001, 0x0120), {0, 0}}});
  EXPECT_EQ(r[0].wkc, 1);
  EXPECT_EQ(r[1].wkc, 0) << "AL control still unread by the firmware";
  EXPECT_EQ(readLe16(r[2].data, 0), 0x0001);
  // The firmware has read it after the frame: the master can write again.
  EXPECT_EQ(one(seg_, Command::kFpwr, phys(0x1001, 0x0120), le16(0x0001)).wkc, 1);
}

TEST_F(AlControlMailbox, FirmwareReadClearsTheAlEventRequest) {
  const auto r = exchange(seg_, {{Command::kFpwr, phys(0x1001, 0x0120), le16(0x0001)},
                                 {Command::kFprd, phys(0x1001, 0x0220), {0, 0, 0, 0}}});
  EXPECT_EQ(readLe32(r[1].data, 0) & 0x01u, 0x01u) << "AL control event pending";
  const auto after = one(seg_, Command::kFprd, phys(0x1001, 0x0220), {0, 0, 0, 0});
  EXPECT_EQ(readLe32(after.data, 0) & 0x01u, 0x00u) << "cleared by the firmware's PDI read";
}

}  // namespace
}  // namespace ecsim::testing
