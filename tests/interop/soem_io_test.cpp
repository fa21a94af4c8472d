// Issue #17 acceptance, IO part, seen by SOEM: every DI/DO/AI/AO device of the shared ESI
// files (support/vendor_io_devices.hpp, 69 devices, read in place) in one line served by
// `ecsim serve` on a veth pair in a private namespace, with an EL2004 looped to an EL1004
// (model="loopback") at the end. io_client.c, built against SOEM's libsoem.a (v1.4.0 and
// v2.0.0), brings them to OP with the PDO mapping SOEM reads from each slave, writes a pattern
// that changes every cycle into every output and prints its process image every cycle:
//   - digital inputs follow their script (a 100 ms square on every channel): each device's
//     input bits alternate between two values that differ in exactly its channel count of bits,
//     and each change comes 50 ms after the one before, by SOEM's own clock (the client
//     prints when each cycle's frame left and came back; how many cycles fit in 50 ms is the
//     host's business, not the simulator's);
//   - analog inputs follow theirs (a 100 ms square between 2.5 V and -5 V: raw 0x2000 and
//     0xC000 at +/-10 V full scale, docs/devices.md);
//   - the EL1004's inputs show what SOEM wrote to the EL2004's outputs one cycle later.
// The in-process counterpart with our master is tests/embed/vendor_io_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <fstream>
#include <map>
#include <ostream>
#include <regex>
#include <set>
#include <sstream>

#include "interop/soem_support.hpp"
#include "support/vendor_io_devices.hpp"

namespace ecsim::testing {
namespace {

constexpr int kCycles = 400;
constexpr std::chrono::seconds kClientTimeout{90};
constexpr int kSkip = 5;  // first cycles: the scripts' first edge and OP's first exchange
constexpr long long kHalfPeriodUs = 50'000;  // the scripts' squares: period=0.1
// Microsecond timestamps, rounded down: a few microseconds either way.
constexpr long long kSlackUs = 4;

struct Image {
  std::map<int, std::vector<std::string>> in, out;  // per SOEM slave (1-based), per cycle
  std::vector<long long> sent, received;            // per cycle, CLOCK_MONOTONIC in us
};

Image parse(const std::string& text) {
  Image image;
  std::istringstream lines(text);
  std::string line;
  const std::regex row("^c ([0-9]+) s ([0-9]+) out ([-0-9a-f]+) in ([-0-9a-f]+)$");
  const std::regex times("^t ([0-9]+) ([0-9]+) ([0-9]+)$");
  std::smatch m;
  while (std::getline(lines, line)) {
    if (std::regex_match(line, m, times)) {
      image.sent.push_back(std::stoll(m[2]));
      image.received.push_back(std::stoll(m[3]));
      continue;
    }
    if (!std::regex_match(line, m, row)) continue;
    const int slave = std::stoi(m[2]);
    image.out[slave].push_back(m[3]);
    image.in[slave].push_back(m[4]);
  }
  return image;
}

unsigned bitsDiffering(const std::string& a, const std::string& b) {
  unsigned n = 0;
  for (std::size_t i = 0; i + 1 < a.size() && i + 1 < b.size(); i += 2) {
    const auto x =
        std::stoul(a.substr(i, 2), nullptr, 16) ^ std::stoul(b.substr(i, 2), nullptr, 16);
    n += static_cast<unsigned>(std::popcount(x));
  }
  return n;
}

// Byte-aligned occurrences of the 16-bit little-endian value `le` ("0020" for 0x2000).
unsigned wordsEqual(const std::string& hex, const std::string& le) {
  unsigned n = 0;
  for (std::size_t i = 0; i + 4 <= hex.size(); i += 2) n += hex.compare(i, 4, le) == 0 ? 1 : 0;
  return n;
}

// The cycles after kSkip whose inputs differ from the cycle's before: the square's edges.
std::vector<std::size_t> edges(const std::vector<std::string>& values) {
  std::vector<std::size_t> at;
  for (std::size_t c = kSkip + 1; c < values.size(); ++c) {
    if (values[c] != values[c - 1]) at.push_back(c);
  }
  return at;
}

// `ecsim serve` runs its firmware (which sets the inputs from their scripts) after answering
// each frame, so the inputs a frame reads were set after the frame before it was answered. An
// edge first seen in cycle k therefore happened after the firmware run behind cycle k-1 (which
// was after cycle k-2's frame left) and before cycle k's answer came back: in (sent[k-2],
// received[k]). The time between the edges seen in cycles j < k lies in (sent[k-2] -
// received[j], received[k] - sent[j-2]). How far outside that interval `us` lies (0: inside).
long long outside(const Image& image, std::size_t j, std::size_t k, long long us) {
  const long long least = image.sent[k - 2] - image.received[j];
  const long long most = image.received[k] - image.sent[j - 2];
  return us < least ? least - us : us > most ? us - most : 0;
}

std::string topology() {
  std::ostringstream s;
  s << "<Topology name=\"soem-io\">\n";
  auto slave = [&](const std::string& name, const VendorIoDevice& d, const std::string& extra,
                   const std::string& children) {
    s << "  <Slave name=\"" << name << "\" esi=\"" << (sharedDir() / "esi" / d.file).string()
      << "\" product=\"" << d.product << "\" revision=\"" << d.revision << "\"" << extra << ">\n"
      << children << "  </Slave>\n";
  };
  int n = 0;
  for (const VendorIoDevice& d : kVendorIoDevices) {
    std::string params;
    for (unsigned c = 1; c <= d.digitalInputs; ++c) {
      params +=
          "    <Param name=\"signal." + std::to_string(c) + "\" value=\"square period=0.1\"/>\n";
    }
    for (unsigned c = 1; c <= d.analogInputs; ++c) {
      params += "    <Param name=\"signal." + std::to_string(c) +
                "\" value=\"square period=0.1 low=-5 high=2.5\"/>\n";
    }
    slave("D" + std::to_string(++n), d, "", params);
  }
  const VendorIoDevice el2004{
      "Beckhoff_EtherCAT_Terminals.xml", "EL2004", 0x07D43052, 0x270B0000, false, 0, 4, 0, 0};
  const VendorIoDevice el1004{
      "Beckhoff_EtherCAT_Terminals.xml", "EL1004", 0x03EC3052, 0x270B0000, false, 4, 0, 0, 0};
  slave("LoopDO", el2004, "", "");
  slave("LoopDI", el1004, " model=\"loopback\"",
        "    <Param name=\"loopback.from\" value=\"LoopDO\"/>\n");
  s << "</Topology>\n";
  return s.str();
}

class SoemIo : public ::testing::TestWithParam<const char*> {};

TEST_P(SoemIo, InputsFollowTheirScriptsAndALoopbackShowsTheOutputsOneCycleLater) {
  ECSIM_REQUIRE_SOEM();
  ECSIM_REQUIRE_SHARED(sharedDir() / "esi" / "Beckhoff_EtherCAT_Terminals.xml");
  const std::string client = std::string(GetParam()) + "/io_client";
  if (!std::filesystem::exists(kSoem / client)) {
    if (ciMode()) FAIL() << client << " not built in " << kSoem;
    GTEST_SKIP() << client << " not built (soem_build fixture)";
  }
  const std::string file = ::testing::TempDir() + "soem_io_" + std::to_string(::getpid()) + ".xml";
  std::ofstream(file) << topology();
  SoemRun run({file});
  const std::string out = run.run(client, {std::to_string(kCycles)}, kClientTimeout);
  std::filesystem::remove(file);
  const std::size_t devices = std::size(kVendorIoDevices);
  ASSERT_NE(out.find("slaves " + std::to_string(devices + 2) + "\n"), std::string::npos)
      << out.substr(0, 4000) << run.serveLog();
  ASSERT_NE(out.find("\nop\n"), std::string::npos) << out.substr(0, 8000) << run.serveLog();
  ASSERT_NE(out.find("\ndone cycles"), std::string::npos)
      << out.substr(out.size() > 3000 ? out.size() - 3000 : 0);
  const Image image = parse(out);
  ASSERT_EQ(image.sent.size(), static_cast<std::size_t>(kCycles));
  long long worst = 0;

  for (std::size_t i = 0; i < devices; ++i) {
    const VendorIoDevice& d = kVendorIoDevices[i];
    const int s = static_cast<int>(i) + 1;
    SCOPED_TRACE(::testing::PrintToString(d) + ", SOEM slave " + std::to_string(s));
    if (d.digitalInputs == 0 && d.analogInputs == 0) continue;
    const auto& values = image.in.at(s);
    ASSERT_EQ(values.size(), static_cast<std::size_t>(kCycles));
    const std::set<std::string> distinct(values.begin() + kSkip, values.end());
    ASSERT_EQ(distinct.size(), 2u) << "the inputs take the square's two values";
    const std::string a = *distinct.begin();
    const std::string b = *distinct.rbegin();
    if (d.analogInputs > 0) {
      const bool aHigh = wordsEqual(a, "0020") >= d.analogInputs;
      const std::string& high = aHigh ? a : b;
      const std::string& low = aHigh ? b : a;
      EXPECT_GE(wordsEqual(high, "0020"), d.analogInputs) << high << " holds 2.5 V (0x2000)";
      EXPECT_GE(wordsEqual(low, "00c0"), d.analogInputs) << low << " holds -5 V (0xC000)";
    } else {
      EXPECT_EQ(bitsDiffering(a, b), d.digitalInputs) << a << " / " << b;
    }
    // 50 ms half periods, on SOEM's clock: the simulator's time is the host's monotonic clock.
    const std::vector<std::size_t> at = edges(values);
    EXPECT_GE(at.size(), 6u) << "400 cycles of at least 1 ms hold 7 edges of a 50 ms square";
    for (std::size_t e = 1; e < at.size(); ++e) {
      const long long off = outside(image, at[e - 1], at[e], kHalfPeriodUs);
      worst = std::max(worst, off);
      EXPECT_LE(off, kSlackUs) << "edges in cycles " << at[e - 1] << " and " << at[e] << ": "
                               << image.received[at[e]] - image.received[at[e - 1]]
                               << " us apart by their answers";
    }
  }
  std::printf("%s: the edges of the inputs' squares lay at most %lld us outside their cycles\n",
              GetParam(), worst);

  const int loopDo = static_cast<int>(devices) + 1;
  const int loopDi = loopDo + 1;
  const auto& written = image.out.at(loopDo);
  const auto& read = image.in.at(loopDi);
  int oneLater = 0, same = 0;
  for (int c = kSkip; c + 1 < kCycles; ++c) {
    oneLater +=
        read[static_cast<std::size_t>(c + 1)] == written[static_cast<std::size_t>(c)] ? 1 : 0;
    same += read[static_cast<std::size_t>(c)] == written[static_cast<std::size_t>(c)] ? 1 : 0;
  }
  const int compared = kCycles - 1 - kSkip;
  std::printf(
      "%s: the looped EL1004 read what SOEM wrote to the EL2004 one cycle before in %d of %d "
      "cycles\n",
      GetParam(), oneLater, compared);
  // A cycle SOEM lost (its 2 ms receive timeout on a loaded host) shifts one comparison.
  EXPECT_GE(oneLater, compared * 95 / 100);
  EXPECT_LE(same, compared / 20) << "not in the same cycle: the DI latches after the DO applied";
}

INSTANTIATE_TEST_SUITE_P(Soem, SoemIo, ::testing::Values("bin-v1", "bin-v2"),
                         [](const auto& param) {
                           return std::string(param.param) == "bin-v1" ? std::string("V1")
                                                                       : std::string("V2");
                         });

}  // namespace
}  // namespace ecsim::testing
