// Issue #17 item 1 (encoder part): a third-party counter terminal served from its vendor's ESI
// (../shared/esi, read in place) gets the encoder profile bound to the counter value its own
// TxPDOs carry (docs/devices.md, "How a device is matched"). Our master (the in-process
// fixture) brings it to OP and reads the counter, scripted by signal.1, from its process image.
//
//   EL5101, EL5151 (Beckhoff_EtherCAT_Terminals.xml, a 2006 file without a dictionary): fixed
//     TxPDO 0x1A00 "Inputs #1" = 0x3101:01 Status (BYTE), 0x3101:02 Value (UINT), :03 Latch;
//   EJ5101 (Beckhoff_EJ5xxx.xml, MDP 5001): default TxPDO 0x1A00 = 0x6000:01 Status,
//     0x6000:02 Value (UINT), :03 Latch; TxPDO 0x1A04 "ENC Status" = 0x6010:01-10 status bits,
//     0x6010:11 Counter value (UDINT), :12 Latch value.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <ostream>

#include "embed/testing/network_fixture.hpp"
#include "slavesim/devices/device_models.hpp"
#include "support/test_network.hpp"

namespace ecsim::testing {
namespace {

namespace dev = slavesim::devices;

struct VendorEncoderCase {
  const char* label;
  const char* file;
  std::uint32_t product;
  std::uint16_t txPdo;    // assigned to 0x1C13 in PREOP (0: the ESI's default)
  const char* counter;    // the master's variable of the counter entry the PDOs carry
  unsigned counterBits;   // its width: the count wraps there
  const char* model;      // model= of the topology ("": the automatic choice)
};
void PrintTo(const VendorEncoderCase& c, std::ostream* os) { *os << c.label; }

const VendorEncoderCase kCases[] = {
    {"EL5101", "Beckhoff_EtherCAT_Terminals.xml", 0x13ED3052, 0, "Enc.Inputs #1.Value", 16, ""},
    {"EL5151", "Beckhoff_EtherCAT_Terminals.xml", 0x141F3052, 0, "Enc.Inputs #1.Value", 16, ""},
    {"EJ5101", "Beckhoff_EJ5xxx.xml", 0x13ED2852, 0, "Enc.0x6000:02", 16, ""},
    {"EJ5101_EncStatus", "Beckhoff_EJ5xxx.xml", 0x13ED2852, 0x1A04, "Enc.0x6010:11", 32, ""},
    {"EL5101_model", "Beckhoff_EtherCAT_Terminals.xml", 0x13ED3052, 0, "Enc.Inputs #1.Value", 16,
     "encoder"},
};

class VendorEncoder : public NetworkFixture,
                      public ::testing::WithParamInterface<VendorEncoderCase> {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("ecsim-vendor-encoder-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    stopNetwork();
    std::filesystem::remove_all(dir_);
  }
  // 1000 counts per turn, the shaft turning 3 turns/s from 0.25 turns: 250 + 3000 counts/s.
  std::filesystem::path topology(const VendorEncoderCase& c) {
    const auto path = dir_ / "net.xml";
    std::ofstream(path) << "<Topology name=\"vendor-encoder\">\n  <Slave name=\"Enc\" esi=\""
                        << (sharedDir() / "esi" / c.file).string() << "\" product=\""
                        << c.product << "\""
                        << (*c.model != 0 ? std::string(" model=\"") + c.model + "\"" : "")
                        << ">\n"
                        << "    <Param name=\"encoder.resolution\" value=\"1000\"/>\n"
                        << "    <Param name=\"signal.1\" value=\"ramp start=0.25 slope=3\"/>\n"
                        << "  </Slave>\n</Topology>\n";
    return path;
  }
  Status assign(std::uint16_t sm, std::uint16_t pdo) {
    const std::uint8_t zero[] = {0};
    const std::uint8_t one[] = {1};
    const std::uint8_t index[] = {static_cast<std::uint8_t>(pdo),
                                  static_cast<std::uint8_t>(pdo >> 8)};
    ECSIM_TRY(master().sdoDownload(0, sm, 0, zero));
    ECSIM_TRY(master().sdoDownload(0, sm, 1, index));
    return master().sdoDownload(0, sm, 0, one);
  }
  std::filesystem::path dir_;
};

TEST_P(VendorEncoder, MasterReadsTheScriptedCounterInItsProcessImage) {
  const VendorEncoderCase& c = GetParam();
  ECSIM_REQUIRE_SHARED(sharedDir() / "esi" / c.file);
  auto started = startInProcess(topology(c));
  ASSERT_TRUE(started.ok()) << started.error().message();
  ASSERT_NE(dev::encoderTerminalOf(network().segment().slave(0)), nullptr)
      << c.label << ": no encoder model on the vendor's counter terminal";

  ASSERT_TRUE(master().scan().ok());
  ASSERT_TRUE(master().bringTo(AlState::kPreOp).ok());
  if (c.txPdo != 0) {
    ASSERT_TRUE(assign(0x1C13, c.txPdo).ok());
  }
  auto op = master().bringTo(AlState::kOp);
  ASSERT_TRUE(op.ok()) << op.error().message();
  // The 2006 files map 0x3101:02 in the RxPDO too ("Outputs #1.Value"): by name, not index.
  auto counter = master().variable(c.counter);
  ASSERT_TRUE(counter.ok()) << c.label << ": " << c.counter << " is not in the process image";

  // Every cycle, the counter the master received is the script's count at the terminal's
  // latest reading: 250 + 3000 counts/s * t, wrapped to the entry's width. The terminal latches
  // at its firmware step, in the cycle before the frame that carries it, so the reading is at
  // most one 1 ms cycle (3 counts) old.
  const std::uint64_t mask = c.counterBits >= 64 ? ~0ull : (1ull << c.counterBits) - 1;
  std::uint64_t previous = 0;
  int rising = 0;
  for (int i = 0; i < 400; ++i) {
    ASSERT_TRUE(master().exchange().ok());
    const std::uint64_t got = c.counterBits == 16 ? counter->get<std::uint16_t>()
                                                  : counter->get<std::uint32_t>();
    const double t = static_cast<double>(network().now()) / kNsPerSecond;
    const auto expected = static_cast<std::uint64_t>(250.0 + 3000.0 * t) & mask;
    EXPECT_LE(expected - got, 4u) << c.label << " cycle " << i << " t=" << t;
    if (got > previous) ++rising;
    previous = got;
    ASSERT_TRUE(advance(kNsPerMs).ok());
  }
  EXPECT_GT(rising, 390) << "the counter follows the script cycle by cycle";
}

// The rule's other side: the EL3102's "Value" (0x3101:02 of the same 2006 file) is an analog
// value, INT, and gets no encoder; a topology's Param on it is refused as before.
TEST_F(VendorEncoder, ASignedAnalogValueIsNoCounter) {
  ECSIM_REQUIRE_SHARED(sharedDir() / "esi" / "Beckhoff_EtherCAT_Terminals.xml");
  const auto path = dir_ / "analog.xml";
  std::ofstream(path) << "<Topology name=\"analog\">\n  <Slave name=\"AI\" esi=\""
                      << (sharedDir() / "esi" / "Beckhoff_EtherCAT_Terminals.xml").string()
                      << "\" product=\"#x0c1e3052\"/>\n</Topology>\n";
  ASSERT_TRUE(startInProcess(path).ok());
  EXPECT_EQ(dev::encoderTerminalOf(network().segment().slave(0)), nullptr);
}

INSTANTIATE_TEST_SUITE_P(SharedEsi, VendorEncoder, ::testing::ValuesIn(kCases),
                         [](const auto& param) { return std::string(param.param.label); });

}  // namespace
}  // namespace ecsim::testing
