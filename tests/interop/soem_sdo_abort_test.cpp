// SOEM's own SDO calls (v1.4.0 ec_SDOwrite/ec_SDOread, v2.0.0 ecx_SDOwrite/ecx_SDOread)
// against `ecsim serve`: a refused access must reach SOEM as an SDO abort with its code.
// SOEM takes a CoE service-3 answer whose index matches as the normal answer (v1.4
// ethercatcoe.c and v2 ec_coe.c: `(etohs(aSDOp->CANOpen) >> 12) == ECT_COES_SDORES` and the
// index/subindex), so a write answered by a service-3 abort returns success and a read takes
// the abort code for a length ("data container too small", packet error 3). Only an answer
// that fails that test reaches `aSDOp->Command == ECT_SDO_ABORT` and ecx_SDOerror(): the
// abort as real slaves send it, a CoE SDO request (service 2; ETG.1000.6 table of CoE
// services; SOES esc_coe.c SDO_abort()).
//
// The client (sdo_abort_client.c) is built against each SOEM's libsoem.a by the soem_build
// fixture. Slave 5 of the default demo network is the first ECS7201 drive (CoE).
#include <gtest/gtest.h>

#include <regex>

#include "interop/soem_support.hpp"

namespace ecsim::testing {
namespace {

constexpr const char* kDrive = "5";
constexpr std::chrono::seconds kClientTimeout{60};

struct ClientResult {
  int result{-1};                                  // SOEM's return value (wkc; 0 = failed)
  std::vector<std::pair<int, std::uint32_t>> errors;  // (SOEM error type, code)
  std::string data;                                // "0x........" after a successful read
  std::string out;
};

ClientResult parse(const std::string& out) {
  ClientResult r;
  r.out = out;
  std::smatch m;
  if (std::regex_search(out, m, std::regex("\nresult (-?[0-9]+)\n"))) r.result = std::stoi(m[1]);
  if (std::regex_search(out, m, std::regex("\ndata (0x[0-9a-f]{8}) "))) r.data = m[1];
  const std::regex error("error type ([0-9]+) index 0x[0-9a-f]{4}:[0-9a-f]{2} code 0x([0-9a-f]{8})");
  for (auto it = std::sregex_iterator(out.begin(), out.end(), error); it != std::sregex_iterator();
       ++it) {
    r.errors.emplace_back(std::stoi((*it)[1]),
                          static_cast<std::uint32_t>(std::stoul((*it)[2], nullptr, 16)));
  }
  return r;
}

ClientResult runClient(const std::string& version, std::vector<std::string> args) {
  SoemRun run({});
  args.insert(args.begin(), kDrive);
  return parse(run.run("bin-" + version + "/sdo_abort_client", args, kClientTimeout));
}

// SOEM's EC_ERR_TYPE_SDO_ERROR: an abort received from the slave, with its code.
constexpr int kSoemSdoError = 0;
using Errors = std::vector<std::pair<int, std::uint32_t>>;

class SoemSdoAbort : public ::testing::TestWithParam<std::string> {};

#define ECSIM_REQUIRE_SDO_CLIENT()                                                          \
  do {                                                                                      \
    ECSIM_REQUIRE_SOEM();                                                                   \
    if (!std::filesystem::exists(kSoem / ("bin-" + GetParam()) / "sdo_abort_client")) {    \
      if (ciMode()) FAIL() << "sdo_abort_client not built in " << kSoem;                    \
      GTEST_SKIP() << "sdo_abort_client not built (soem_build fixture)";                    \
    }                                                                                       \
  } while (false)

TEST_P(SoemSdoAbort, WriteToAReadOnlyEntryReportsTheAbortCode) {
  ECSIM_REQUIRE_SDO_CLIENT();
  auto r = runClient(GetParam(), {"write", "0x1018", "1", "5"});
  EXPECT_EQ(r.result, 0) << "SOEM must not report the refused write as done\n" << r.out;
  EXPECT_EQ(r.errors, (Errors{{kSoemSdoError, 0x06010002}})) << r.out;
}

TEST_P(SoemSdoAbort, ReadOfAMissingObjectReportsTheAbortCode) {
  ECSIM_REQUIRE_SDO_CLIENT();
  auto r = runClient(GetParam(), {"read", "0x6FFF", "0"});
  EXPECT_EQ(r.result, 0) << r.out;
  EXPECT_EQ(r.errors, (Errors{{kSoemSdoError, 0x06020000}})) << r.out;
}

TEST_P(SoemSdoAbort, ReadOfAnExistingEntryStillSucceeds) {
  ECSIM_REQUIRE_SDO_CLIENT();
  auto r = runClient(GetParam(), {"read", "0x1018", "1"});
  EXPECT_EQ(r.result, 1) << r.out;
  EXPECT_EQ(r.data, "0x00000e5c") << "vendor ID\n" << r.out;
  EXPECT_TRUE(r.errors.empty()) << r.out;
}

INSTANTIATE_TEST_SUITE_P(Soem, SoemSdoAbort, ::testing::Values("v1", "v2"),
                         [](const auto& p) { return p.param; });

}  // namespace
}  // namespace ecsim::testing
