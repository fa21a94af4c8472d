// ecsim-soak: a long run of valid and malformed EtherCAT frames against `ecsim serve` (or any
// EtherCAT network) over a raw socket, each answer checked against the ESC datasheet:
//
//   ecsim serve --iface ecs0 --slaves 4 &
//   ecsim-soak --iface ecm0 --frames 10000000 --seed 7 --server-pid $!
//
// A separate program, so that it shares nothing with the server under test but the frame
// format. Exit status 0: every valid frame answered correctly, no malformed frame executed,
// the server still running; 1: any of these failed; 2: bad arguments or no network.
#include <fmt/core.h>

#include <CLI/CLI.hpp>

#include "link/raw_socket_link.hpp"
#include "tools/ecsim-soak/soak.hpp"
#include "tools/common/install_paths.hpp"

int main(int argc, char** argv) {
  using namespace ecsim::soak;
  CLI::App app{"ecsim-soak - valid and malformed EtherCAT frames, every answer checked"};
  app.set_version_flag("--version", ecsim::tools::versionText("ecsim-soak"));
  std::string iface;
  std::string netns;
  SoakOptions o;
  unsigned timeoutMs = 1000;
  unsigned waitReadyMs = 0;
  unsigned escType = o.escType;
  app.add_option("-i,--iface", iface, "Interface to send on (the master's end)")->required();
  app.add_option("--netns", netns, "Open the interface in this network namespace");
  app.add_option("--seed", o.seed, "Seed of the frame sequence (same seed, same frames)");
  app.add_option("--frames", o.frames, "Number of frames to send (valid and malformed)")
      ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{1} << 40));
  app.add_option("--window", o.window, "Valid frames in flight at most")
      ->check(CLI::Range(1u, 256u));
  app.add_option("--timeout-ms", timeoutMs, "Time a valid frame's answer may take")
      ->check(CLI::Range(1u, 60000u));
  app.add_option("--malformed-percent", o.malformedPercent, "Share of malformed frames")
      ->check(CLI::Range(0u, 100u));
  app.add_option("--slaves", o.expectedSlaves, "Expected number of slaves (default: counted)")
      ->check(CLI::Range(1u, 65535u));
  app.add_option("--esc-type", escType, "ESC type register (0x0000) of every slave, 0x11 ET1100")
      ->check(CLI::Range(0u, 255u));
  app.add_option("--server-pid", o.serverPid, "Process of the server: RSS, and a check it lives")
      ->check(CLI::PositiveNumber);
  app.add_option("--wait-ready-ms", waitReadyMs, "Probe this long for the server's first answer")
      ->check(CLI::Range(0u, 600000u));
  app.add_option("--errors-shown", o.errorsShown, "Print details of the first N errors");
  unsigned progressS = 0;
  app.add_option("--progress-s", progressS, "Print a progress line every N seconds (0: none)")
      ->check(CLI::Range(0u, 86400u));
  CLI11_PARSE(app, argc, argv);
  o.timeout = std::chrono::milliseconds(timeoutMs);
  o.waitReady = std::chrono::milliseconds(waitReadyMs);
  o.escType = static_cast<std::uint8_t>(escType);
  o.progress = std::chrono::seconds(progressS);

  auto link = ecsim::RawSocketLink::open(iface, ecsim::RawSocketOptions{netns, true});
  if (!link.ok()) {
    fmt::print(stderr, "ecsim-soak: {}\n", link.error().message());
    return 2;
  }
  const SoakReport report = runSoak(*link, o, stderr);
  printReport(report, o, stdout);
  std::fflush(stdout);
  if (!report.setupError.empty()) return 2;
  return report.failed() ? 1 : 0;
}
