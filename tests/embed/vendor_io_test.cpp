// Issue #17 item 1 (IO part): third-party DI, DO, AI and AO terminals served from their
// vendors' ESI files (../shared/esi, read in place) get ecsim's IO models bound to their own PDO
// entries (slavesim/devices/io_profile.hpp), chosen automatically. Our master (the in-process
// fixture) brings each to OP and:
//   - digital inputs follow a scripted square signal (signal.N params) as seen in the master's
//     process image, channel n delayed by n - 1 ms so a channel mixed up with another shows;
//   - digital outputs the master writes (one channel at a time) are the model's outputs;
//   - analog inputs follow a scripted square in volts (+/-10 V = +/-32767), 12 V sets the
//     overrange and error bits of the old layout's status byte;
//   - analog output values the master writes are the model's.
// A DO looped to a DI (model="loopback", or signal.N = "output slave=... channel=...") shows
// the pattern the master wrote one cycle later.
//
// kCases (support/vendor_io_devices.hpp) lists every DI/DO/AI/AO device of the shared ESI files.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <sstream>

#include "embed/testing/network_fixture.hpp"
#include "slavesim/devices/device_models.hpp"
#include "support/test_network.hpp"
#include "support/vendor_io_devices.hpp"

namespace ecsim::testing {
namespace {

namespace dev = slavesim::devices;
using dev::DeviceModelKind;
constexpr bool kIo = false;  // VendorIoDevice::analog

using IoCase = VendorIoDevice;

const auto& kCases = kVendorIoDevices;

constexpr int kSquareCycles = 64;  // square period in 1 ms cycles
constexpr double kFullScale = 10.0;

std::int64_t rawOf(double volts) { return std::lround(volts / kFullScale * 32767.0); }

class IoFixture : public NetworkFixture {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("ecsim-vendor-io-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    stopNetwork();
    std::filesystem::remove_all(dir_);
  }
  static std::string slaveXml(const std::string& name, const IoCase& c,
                              const std::string& extra = {}, const std::string& children = {}) {
    std::ostringstream s;
    s << "  <Slave name=\"" << name << "\" esi=\"" << (sharedDir() / "esi" / c.file).string()
      << "\" product=\"" << c.product << "\" revision=\"" << c.revision << "\"" << extra << ">\n"
      << children << "  </Slave>\n";
    return s.str();
  }
  std::filesystem::path write(const std::string& slaves) {
    const auto path = dir_ / "net.xml";
    std::ofstream(path) << "<Topology name=\"vendor-io\">\n" << slaves << "</Topology>\n";
    return path;
  }
  Status toOp() {
    ECSIM_TRY(master().scan());
    return master().bringTo(AlState::kOp);
  }
  // One exchange per millisecond of simulated time, on an exact 1 ms grid (the exchange
  // itself takes virtual time).
  Status cycle() {
    ECSIM_TRY(master().exchange());
    const SimTime now = network().now();
    return advance((now / kNsPerMs + 1) * kNsPerMs - now);
  }
  // The master's variables of slave `position` in one direction, in process-image order.
  std::vector<master::VariableInfo> vars(std::size_t position, bool output) {
    std::vector<master::VariableInfo> out;
    for (const auto& v : master().variables()) {
      if (v.position == position && v.output == output && v.index >= 0x2000 && v.index <= 0x9FFF)
        out.push_back(v);
    }
    std::sort(out.begin(), out.end(),
              [](const auto& a, const auto& b) { return a.bitOffset < b.bitOffset; });
    return out;
  }
  // Digital channels as the master sees them: its 1-bit variables, else 8 per byte-wide
  // variable not named like "Status" (bit 0 first). Each: variable, bit.
  std::vector<std::pair<master::PdoVariable, unsigned>> digital(std::size_t position, bool output) {
    std::vector<std::pair<master::PdoVariable, unsigned>> out;
    const auto all = vars(position, output);
    for (const auto& v : all) {
      if (v.bitLength == 1) out.emplace_back(*master().variable(v.name), 0);
    }
    if (!out.empty()) return out;
    for (const auto& v : all) {
      if (v.bitLength != 8 || v.entry.find("Status") != std::string::npos) continue;
      for (unsigned b = 0; b < 8; ++b) out.emplace_back(*master().variable(v.name), b);
    }
    return out;
  }
  static bool bit(const std::pair<master::PdoVariable, unsigned>& c) {
    return ((c.first.raw() >> c.second) & 1u) != 0;
  }
  static void setBits(std::vector<std::pair<master::PdoVariable, unsigned>>& channels,
                      std::uint64_t pattern) {
    for (auto& c : channels) c.first.setRaw(0);
    for (std::size_t n = 0; n < channels.size(); ++n) {
      if (((pattern >> n) & 1u) != 0) {
        channels[n].first.setRaw(channels[n].first.raw() | (std::uint64_t{1} << channels[n].second));
      }
    }
  }
  std::filesystem::path dir_;
};

class VendorIo : public IoFixture, public ::testing::WithParamInterface<IoCase> {};

TEST_P(VendorIo, InputsFollowTheScriptOutputsReachTheModel) {
  const IoCase& c = GetParam();
  ECSIM_REQUIRE_SHARED(sharedDir() / "esi" / c.file);
  std::ostringstream params;
  for (unsigned n = 1; n <= c.digitalInputs; ++n) {
    params << "    <Param name=\"signal." << n << "\" value=\"square period="
           << kSquareCycles / 1000.0 << " phase=" << (n - 1) / 1000.0 + 0.0005 << "\"/>\n";
  }
  for (unsigned n = 1; n <= c.analogInputs; ++n) {
    params << "    <Param name=\"signal." << n << "\" value=\"square period=0.016 low=-2.5 high="
           << n + 1 << "\"/>\n";
  }
  auto started = startInProcess(write(slaveXml("T", c, {}, params.str())));
  ASSERT_TRUE(started.ok()) << started.error().message();
  slavesim::Slave& slave = network().segment().slave(0);
  auto* di = dev::digitalInputsOf(slave);
  auto* dout = dev::digitalOutputsOf(slave);
  auto* ai = dev::analogInputsOf(slave);
  auto* ao = dev::analogOutputsOf(slave);
  EXPECT_EQ(di ? di->channels() : 0, c.digitalInputs);
  EXPECT_EQ(dout ? dout->channels() : 0, c.digitalOutputs);
  EXPECT_EQ(ai ? ai->channels() : 0, c.analogInputs);
  EXPECT_EQ(ao ? ao->channels() : 0, c.analogOutputs);
  auto op = toOp();
  ASSERT_TRUE(op.ok()) << op.error().message();

  if (c.digitalInputs > 0) {
    auto inputs = digital(0, false);
    ASSERT_EQ(inputs.size(), c.digitalInputs) << "digital inputs in the master's image";
    constexpr int kCycles = 3 * kSquareCycles;
    std::vector<std::vector<bool>> seen(inputs.size());
    for (int k = 0; k < kCycles; ++k) {
      ASSERT_TRUE(cycle().ok());
      for (std::size_t n = 0; n < inputs.size(); ++n) seen[n].push_back(bit(inputs[n]));
    }
    // Channel 1: a square of period 64 cycles, half on.
    std::vector<int> edges;
    for (int k = 1; k < kCycles; ++k) {
      if (seen[0][k] != seen[0][k - 1]) edges.push_back(k);
    }
    ASSERT_GE(edges.size(), 4u) << "channel 1 does not follow its square signal";
    for (std::size_t e = 1; e < edges.size(); ++e) {
      EXPECT_EQ(edges[e] - edges[e - 1], kSquareCycles / 2) << "edge " << e;
    }
    // Channel n: channel 1 delayed by n - 1 cycles.
    for (std::size_t n = 1; n < inputs.size(); ++n) {
      for (int k = static_cast<int>(n) + 2; k < kCycles; ++k) {
        ASSERT_EQ(seen[n][k], seen[0][k - static_cast<int>(n)]) << "channel " << n + 1 << " cycle " << k;
      }
    }
  }
  if (c.digitalOutputs > 0) {
    auto outputs = digital(0, true);
    ASSERT_EQ(outputs.size(), c.digitalOutputs) << "digital outputs in the master's image";
    for (std::size_t n = 0; n < outputs.size(); ++n) {
      setBits(outputs, std::uint64_t{1} << n);
      ASSERT_TRUE(cycle().ok());
      ASSERT_TRUE(cycle().ok());
      EXPECT_EQ(dout->outputs(), 1u << n) << "channel " << n + 1 << " var " << outputs[n].first.name() << " off " << outputs[n].first.info().bitOffset << " raw " << outputs[n].first.raw()
        << " od " << (network().slave(0)->read<std::uint8_t>(outputs[n].first.info().index, outputs[n].first.info().subindex).ok() ? (int)*network().slave(0)->read<std::uint8_t>(outputs[n].first.info().index, outputs[n].first.info().subindex) : -1)
        << " state " << (int)network().slave(0)->state();
    }
    setBits(outputs, 0);
    ASSERT_TRUE(cycle().ok());
    ASSERT_TRUE(cycle().ok());
    EXPECT_EQ(dout->outputs(), 0u);
  }
  if (c.analogInputs > 0) {
    std::vector<master::PdoVariable> values;
    std::vector<std::optional<master::PdoVariable>> status;
    const auto in = vars(0, false);
    for (std::size_t i = 0; i < in.size(); ++i) {
      if (in[i].bitLength != 16 || in[i].entry.find("Value") == std::string::npos) continue;
      values.push_back(*master().variable(in[i].name));
      status.emplace_back();
      if (i > 0 && in[i - 1].entry.find("Status") != std::string::npos)
        status.back() = *master().variable(in[i - 1].name);
    }
    ASSERT_EQ(values.size(), c.analogInputs);
    for (std::size_t n = 0; n < values.size(); ++n) {
      bool low = false, high = false;
      for (int k = 0; k < 32; ++k) {
        ASSERT_TRUE(cycle().ok());
        const auto v = values[n].get<std::int16_t>();
        low = low || v == rawOf(-2.5);
        high = high || v == rawOf(static_cast<double>(n) + 2.0);
        ASSERT_TRUE(v == rawOf(-2.5) || v == rawOf(static_cast<double>(n) + 2.0))
            << "channel " << n + 1 << " reads " << v;
      }
      EXPECT_TRUE(low && high) << "channel " << n + 1 << " does not follow its square";
    }
    // Over the range: the value stays at full scale, the status shows overrange and error
    // (status bits 1 and 6 of the old Beckhoff layout's status byte).
    ai->setScript(1, dev::Signal::constant(12.0));
    ASSERT_TRUE(cycle().ok());
    ASSERT_TRUE(cycle().ok());
    EXPECT_EQ(values[0].get<std::int16_t>(), 32767);
    if (status[0]) {
      EXPECT_EQ(status[0]->raw() & 0x43u, 0x42u) << "status 0x" << std::hex << status[0]->raw();
    }
  }
  if (c.analogOutputs > 0) {
    std::vector<master::PdoVariable> values;
    for (const auto& v : vars(0, true)) {
      if (v.bitLength == 16 && (v.entry.find("Value") != std::string::npos ||
                                v.entry.find("Output") != std::string::npos))
        values.push_back(*master().variable(v.name));
    }
    ASSERT_EQ(values.size(), c.analogOutputs);
    for (std::size_t n = 0; n < values.size(); ++n) values[n].set<std::int16_t>(static_cast<std::int16_t>(1000 * (n + 1)));
    ASSERT_TRUE(cycle().ok());
    ASSERT_TRUE(cycle().ok());
    for (unsigned n = 1; n <= ao->channels(); ++n) {
      EXPECT_EQ(ao->raw(n), 1000 * n) << "channel " << n;
      EXPECT_NEAR(ao->volts(n), 1000.0 * n / 32767.0 * kFullScale, 1e-9);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(SharedEsi, VendorIo, ::testing::ValuesIn(kCases),
                         [](const ::testing::TestParamInfo<IoCase>& param) {
                           std::string name = std::string(param.param.file).substr(0, 12) + "_" +
                                              param.param.type + "_" + std::to_string(param.index);
                           for (char& ch : name) {
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           }
                           return name;
                         });

// ---- loopback: a DO terminal wired to a DI terminal -------------------------------------------

class Loopback : public IoFixture {
 protected:
  // The master writes a pseudo-random pattern to the outputs of slave `out` each cycle; input
  // channel n of slave `in` must show output channel wiring[n] (-1: nothing, stays off) of the
  // pattern written one cycle before.
  void run(std::size_t out, std::size_t in, const std::vector<int>& wiring) {
    auto op = toOp();
    ASSERT_TRUE(op.ok()) << op.error().message();
    auto outputs = digital(out, true);
    auto inputs = digital(in, false);
    ASSERT_EQ(inputs.size(), wiring.size());
    std::uint64_t previous = 0;
    std::uint64_t state = 0x9E3779B97F4A7C15ull;
    for (int k = 0; k < 64; ++k) {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      const std::uint64_t pattern = (state >> 17) & ((std::uint64_t{1} << outputs.size()) - 1);
      setBits(outputs, pattern);
      ASSERT_TRUE(cycle().ok());
      for (std::size_t n = 0; n < inputs.size(); ++n) {
        const bool want = wiring[n] >= 0 && k > 0 && ((previous >> wiring[n]) & 1u) != 0;
        ASSERT_EQ(bit(inputs[n]), want) << "input " << n + 1 << ", cycle " << k << ", written 0x"
                                        << std::hex << previous << " then 0x" << pattern;
      }
      previous = pattern;
    }
  }
};

// Beckhoff_EtherCAT_Terminals.xml (2006 layout, 0x3001/0x3101): EL2004 looped to EL1004.
const IoCase kEl2004 = {"Beckhoff_EtherCAT_Terminals.xml", "EL2004", 0x07D43052, 0x270B0000, kIo, 0, 4, 0, 0};
const IoCase kEl1004 = {"Beckhoff_EtherCAT_Terminals.xml", "EL1004", 0x03EC3052, 0x270B0000, kIo, 4, 0, 0, 0};
// Beckhoff_EM2xxx.xml EM2042 (16 outputs 0x7000-0x70F0) to Beckhoff_EL1xxx_2011.xml EL1008
// rev 0x00100000 (8 inputs 0x6000-0x6070): inputs 1-8 follow outputs 1-8.
const IoCase kEm2042 = {"Beckhoff_EM2xxx.xml", "EM2042", 0x07FA3452, 0x00100000, kIo, 0, 16, 0, 0};
const IoCase kEl1008 = {"Beckhoff_EL1xxx_2011.xml", "EL1008", 0x03F03052, 0x00100000, kIo, 8, 0, 0, 0};
// SMC_EX250-SEN1-X156.xml: Byte0..3 outputs (0x7000) looped to its own Byte0..3 inputs (0x6000).
const IoCase kSmc = {"SMC_EX250-SEN1-X156.xml", "EX250-SEN1-X156", 0x00FA6053, 0, kIo, 32, 32, 0, 0};

const char* kLoopFrom = "    <Param name=\"loopback.from\" value=\"DO\"/>\n";

TEST_F(Loopback, El2004ToEl1004ShowsThePatternOneCycleLater) {
  ECSIM_REQUIRE_SHARED(sharedDir() / "esi" / kEl2004.file);
  ASSERT_TRUE(startInProcess(write(slaveXml("DO", kEl2004) +
                                   slaveXml("DI", kEl1004, " model=\"loopback\"", kLoopFrom)))
                  .ok());
  run(0, 1, {0, 1, 2, 3});
}

TEST_F(Loopback, Em2042ToEl1008) {
  ECSIM_REQUIRE_SHARED(sharedDir() / "esi" / kEm2042.file);
  ECSIM_REQUIRE_SHARED(sharedDir() / "esi" / kEl1008.file);
  ASSERT_TRUE(startInProcess(write(slaveXml("DO", kEm2042) +
                                   slaveXml("DI", kEl1008, " model=\"loopback\"", kLoopFrom)))
                  .ok());
  run(0, 1, {0, 1, 2, 3, 4, 5, 6, 7});
}

TEST_F(Loopback, SmcOutputsToItsOwnInputs) {
  ECSIM_REQUIRE_SHARED(sharedDir() / "esi" / kSmc.file);
  auto started = startInProcess(write(slaveXml(
      "DO", kSmc, " model=\"loopback\"", kLoopFrom)));
  ASSERT_TRUE(started.ok()) << started.error().message();
  std::vector<int> wiring;
  for (int n = 0; n < 32; ++n) wiring.push_back(n);
  run(0, 0, wiring);
}

TEST_F(Loopback, OneInputFollowsAChosenOutputChannel) {
  ECSIM_REQUIRE_SHARED(sharedDir() / "esi" / kEl2004.file);
  // EL1004 input 2 wired to EL2004 output 4; inputs 1, 3, 4 unwired.
  ASSERT_TRUE(startInProcess(write(slaveXml("DO", kEl2004) +
                                   slaveXml("DI", kEl1004, {},
                                            "    <Param name=\"signal.2\" value=\"output "
                                            "slave=DO channel=4\"/>\n")))
                  .ok());
  run(0, 1, {-1, 3, -1, -1});
}

// Weidmueller_UR20_FBC.xml UR20-FBC-EC with modules of Weidmueller_UR20_IO.xml: a UR20-4DO-P in
// slot 0 and a UR20-4DI-P in slot 1; the station's inputs follow its own outputs.
TEST_F(Loopback, Ur20StationOutputsToItsInputs) {
  ECSIM_REQUIRE_SHARED(sharedDir() / "esi" / "Weidmueller_UR20_IO.xml");
  const auto esi = sharedDir() / "esi";
  std::ostringstream s;
  s << "  <Slave name=\"DO\" esi=\"" << (esi / "Weidmueller_UR20_FBC.xml").string()
    << "\" product=\"#x4F911C30\" modules=\"" << (esi / "Weidmueller_UR20_IO.xml").string()
    << "\" model=\"loopback\">\n    <Module type=\"UR20-4DO-P\"/>\n"
    << "    <Module type=\"UR20-4DI-P\"/>\n" << kLoopFrom << "  </Slave>\n";
  auto started = startInProcess(write(s.str()));
  ASSERT_TRUE(started.ok()) << started.error().message();
  ASSERT_NE(dev::digitalInputsOf(network().segment().slave(0)), nullptr);
  EXPECT_EQ(dev::digitalInputsOf(network().segment().slave(0))->channels(), 4u);
  EXPECT_EQ(dev::digitalOutputsOf(network().segment().slave(0))->channels(), 4u);
  run(0, 0, {0, 1, 2, 3});
}

}  // namespace
}  // namespace ecsim::testing
