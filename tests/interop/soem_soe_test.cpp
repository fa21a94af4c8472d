// SOEM v1.4 against an AX5000-class SoE drive served by `ecsim serve` over veth
// (examples/topologies/soe_drive.xml: a coupler and the ECS5101, whose mailbox has SoE and no
// CoE). SOEM's ecx_map_coe_soe finds no CoE and sizes the drive's process data through SoE
// (soem/ethercatconfig.c -> ecx_readIDNmap): S-0-0024 and S-0-0016 read for drives 0-7 (1-7
// answer "invalid drive number"), the attribute of each listed IDN read for its length, plus
// the control / status word (16 bits) that every MDT / AT carries outside the lists.
#include <gtest/gtest.h>

#include "interop/soem_support.hpp"

namespace ecsim::testing {
namespace {

TEST(SoemV1Soe, SlaveinfoMapSizesTheDriveFromItsAtAndMdt) {
  ECSIM_REQUIRE_SOEM();
  SoemRun run({std::string(ECSIM_SOURCE_DIR) + "/examples/topologies/soe_drive.xml"});
  std::string out = run.run("bin-v1/slaveinfo", {"-map"}, std::chrono::seconds(60));
  EXPECT_NE(out.find("2 slaves found and configured."), std::string::npos) << out;
  EXPECT_NE(out.find(" Name:ECS5101 SoE servo drive (AX5000-class)"), std::string::npos) << out;
  // MDT: control word 16 + S-0-0036 32 + S-0-0047 32; AT: status word 16 + S-0-0011 16 +
  // S-0-0040 32 + S-0-0051 32 (examples/esi/soe/ecs5101_dict.xml).
  EXPECT_NE(out.find(" Output size: 80bits\n Input size: 96bits\n State: 4\n"), std::string::npos)
      << out;
  EXPECT_NE(out.find("SM2 A:1100 L:  10"), std::string::npos) << out;
  EXPECT_NE(out.find("SM3 A:1180 L:  12"), std::string::npos) << out;
  EXPECT_EQ(out.find("Not all slaves"), std::string::npos) << out;
}

}  // namespace
}  // namespace ecsim::testing
