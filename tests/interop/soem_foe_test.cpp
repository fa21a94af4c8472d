// Issue #20 acceptance (BOOT and FoE): SOEM's own firm_update sample (v1.4.0
// test/linux/firm_update, v2.0.0 samples/firm_update, unchanged) takes the SOES demo slave of
// ../shared/esi/SOES_lan9252demo_slave.xml from INIT to BOOT with the SII's bootstrap mailbox
// (words 0x14-0x17) and writes a file with ecx_FOEwrite (password 0); our master reads it back
// over FoE in BOOT (`ecmaster foe read --boot`) and gets the same bytes; after a power cycle
// (`ecsim ctl power-cycle`) the slave reports the version the image carries in 0x100A
// (`ecmaster upload 0x100A:00`), as docs/devices.md "Firmware update over FoE" describes; with
// the slave's stateFile the same holds across a restart of `ecsim serve`.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "interop/soem_support.hpp"

namespace ecsim::testing {
namespace {

const std::string kEcmaster = std::string(ECSIM_BINARY_DIR) + "/tools/ecmaster/ecmaster";
const std::filesystem::path kSoesEsi =
    std::filesystem::path(ECSIM_SHARED_DIR) / "esi" / "SOES_lan9252demo_slave.xml";

struct Ran {
  int status{-1};
  std::string out;
};

Ran runIn(VethNamespace& ns, std::vector<std::string> argv, const std::string& log,
          std::chrono::seconds limit) {
  Ran r;
  auto child = ns.spawn(argv, SpawnOptions{log, log});
  EXPECT_TRUE(child.ok()) << (child.ok() ? "" : child.error().message());
  if (!child.ok()) return r;
  auto rc = child->wait(limit);
  r.status = rc.ok() ? *rc : -1;
  r.out = readText(log);
  std::filesystem::remove(log);
  return r;
}

void writeFile(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
}

std::vector<std::uint8_t> readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// restart: the slave has a stateFile, and instead of the power cycle `ecsim serve` is stopped
// and started again on the same topology (the files kept beside the state file; docs/devices.md
// "Firmware update over FoE").
void firmwareUpdateThroughSoem(const std::string& program, const std::string& version,
                               bool restart = false) {
  ECSIM_REQUIRE_SOEM();
  ECSIM_REQUIRE_SHARED(kSoesEsi);
  ASSERT_TRUE(std::filesystem::exists(kSoem / program)) << kSoem / program;
  const std::string tag = std::to_string(::getpid()) + "_" + version;
  const std::string dir = ::testing::TempDir();
  const std::string topology = dir + "foe_topology_" + tag + ".xml";
  {
    std::ofstream t(topology);
    t << "<Topology name=\"foe\">\n  <Slave name=\"Soes\" esi=\"" << kSoesEsi.string()
      << "\" product=\"#x4D2\"";
    if (restart) t << " stateFile=\"foe_state_" << tag << "\"";
    t << "/>\n</Topology>\n";
  }
  // 1000 bytes (8 packets of 116 through the 128-byte bootstrap mailbox and one of 72) with
  // the version marker inside.
  std::vector<std::uint8_t> image(1000);
  for (std::size_t i = 0; i < image.size(); ++i) image[i] = static_cast<std::uint8_t>(i * 31 + 7);
  const std::string marker = "ECSIM-SW-VERSION=" + version + '\0';
  std::copy(marker.begin(), marker.end(), image.begin() + 400);
  const std::string imagePath = dir + "foe_image_" + tag + ".bin";
  writeFile(imagePath, image);

  auto ns = VethNamespace::create();
  ASSERT_TRUE(ns.ok()) << ns.error().message();
  const std::string socket = dir + "foe_ctl_" + tag + ".sock";
  const std::string serveLog = dir + "foe_serve_" + tag + ".log";
  auto serve = [&] {
    std::filesystem::remove(serveLog);
    auto server = ns->spawn({kEcsim, "serve", "--rt", "--iface", ns->simulatorInterface(),
                             "--control", socket, topology},
                            SpawnOptions{serveLog, serveLog});
    EXPECT_TRUE(server.ok()) << server.error().message();
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (server.ok() && readText(serveLog).find("ecsim: control socket") == std::string::npos &&
           server->running() && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    EXPECT_NE(readText(serveLog).find("ecsim: control socket"), std::string::npos)
        << readText(serveLog);
    return server;
  };
  auto server = serve();
  ASSERT_TRUE(server.ok());

  // SOEM: slave 1, the file by its path (firm_update sends argv[3] as the FoE file name).
  const Ran soem = runIn(*ns,
                         withRealtimePriority({"timeout", "60", (kSoem / program).string(),
                                               ns->masterInterface(), "1", imagePath}),
                         dir + "foe_soem_" + tag + ".log", std::chrono::seconds(70));
  EXPECT_NE(soem.out.find("Slave 1 state to BOOT."), std::string::npos) << soem.out;
  EXPECT_NE(soem.out.find("File read OK, 1000 bytes."), std::string::npos) << soem.out;
  EXPECT_NE(soem.out.find("result 1."), std::string::npos) << "ecx_FOEwrite's wkc:\n" << soem.out;

  // Our master reads it back in BOOT.
  const std::string readBack = dir + "foe_back_" + tag + ".bin";
  const Ran read = runIn(
      *ns,
      {kEcmaster, "-i", ns->masterInterface(), "foe", "read", "--boot", imagePath, "-o", readBack},
      dir + "foe_read_" + tag + ".log", std::chrono::seconds(60));
  EXPECT_EQ(read.status, 0) << read.out;
  EXPECT_EQ(readBytes(readBack), image);

  // Before the power cycle: the version the device was built with; after it: the image's.
  auto upload = [&] {
    return runIn(*ns,
                 {kEcmaster, "-i", ns->masterInterface(), "upload", "0x100A:00", "-t", "string"},
                 dir + "foe_upload_" + tag + ".log", std::chrono::seconds(60));
  };
  const Ran before = upload();  // the ESI's STRING(0): empty, or refused
  EXPECT_EQ(before.out.find(version), std::string::npos) << before.out;
  if (restart) {
    (void)server->kill(SIGINT);
    (void)server->wait(std::chrono::seconds(5));
    server = serve();
    ASSERT_TRUE(server.ok());
  } else {
    const Ran cycle = runIn(*ns, {kEcsim, "ctl", "--socket", socket, "power-cycle", "slave=Soes"},
                            dir + "foe_cycle_" + tag + ".log", std::chrono::seconds(20));
    EXPECT_EQ(cycle.status, 0) << cycle.out;
  }
  const Ran after = upload();
  EXPECT_EQ(after.status, 0) << after.out;
  // The value is the last line (ecmaster may say something about the frame timeout first, on
  // stderr into the same log, when the machine is loaded).
  const std::string tail = after.out.substr(after.out.rfind('\n', after.out.size() - 2) + 1);
  EXPECT_EQ(tail, version + "\n") << after.out;

  if (restart) {
    // The restarted simulator still has the file SOEM wrote.
    std::filesystem::remove(readBack);
    const Ran again = runIn(*ns,
                            {kEcmaster, "-i", ns->masterInterface(), "foe", "read", "--boot",
                             imagePath, "-o", readBack},
                            dir + "foe_read_" + tag + ".log", std::chrono::seconds(60));
    EXPECT_EQ(again.status, 0) << again.out;
    EXPECT_EQ(readBytes(readBack), image);
  }
  EXPECT_TRUE(server->running()) << "ecsim serve died:\n" << readText(serveLog);
  (void)server->kill(SIGINT);
  (void)server->wait(std::chrono::seconds(5));
  for (const auto& f : {topology, imagePath, readBack, serveLog}) std::filesystem::remove(f);
  std::filesystem::remove_all(dir + "foe_state_" + tag + ".foe");
}

TEST(SoemV1Foe, FirmUpdateWritesInBootOurMasterReadsItBackNewVersionAfterPowerCycle) {
  firmwareUpdateThroughSoem("bin-v1/firm_update", "1.4.0-fw");
}

TEST(SoemV2Foe, FirmUpdateWritesInBootOurMasterReadsItBackNewVersionAfterPowerCycle) {
  firmwareUpdateThroughSoem("bin-v2/firm_update", "2.0.0-fw");
}

// The firmware kept with the slave's state file: booted by the next `ecsim serve`.
TEST(SoemV1Foe, FirmwareKeptWithTheStateFileBootsAfterARestartOfTheSimulator) {
  firmwareUpdateThroughSoem("bin-v1/firm_update", "1.4.0-kept", true);
}

}  // namespace
}  // namespace ecsim::testing
