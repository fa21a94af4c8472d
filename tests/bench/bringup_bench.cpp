// Bring-up time and memory per slave: a line of N generic slaves (what `ecmaster --sim-slaves N`
// builds) brought to OP by our master through the in-process simulator, for N = 1000, 4000,
// 16000 and 65535 (the addressing limit), or the N given on the command line. Each N runs in a
// child process so that its resident memory is its own. Prints, per N:
//   build_s     building the simulated network (wall time)
//   bringup_s   Master::start(): scan, SII, mailboxes, process data, INIT -> OP (wall time)
//   cpu_s       the same in CPU time of the process (the machine may be shared)
//   sim_share   the part of cpu_s spent in the simulator (Segment + NetworkServer)
//   frames, datagrams   what the master sent; virtual_ms: the bring-up on the bus clock
//   kb_per_slave        resident memory after bring-up minus before the network, per slave
//   wire_digest         FNV-1a over every frame the master sent, in order: on virtual time the
//                       bring-up is deterministic, so a change meant to leave the master's
//                       frames alone must leave this figure alone
// Figures, not a pass/fail test. Run: build/default/tests/bench/bringup_bench [N...]
#include <fmt/core.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "link/memory_link.hpp"
#include "master/master.hpp"
#include "slavesim/generic_slave.hpp"
#include "topology/network_server.hpp"
#include "topology/segment.hpp"

namespace ecsim {
namespace {

std::int64_t cpuNs(clockid_t id) {
  timespec ts{};
  clock_gettime(id, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

double wallS() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Passes frames through, folding every frame sent into an FNV-1a digest.
class DigestLink final : public Link {
 public:
  explicit DigestLink(Link& inner) : inner_(inner) {}
  Status send(ConstBytes frame) override {
    for (std::uint8_t b : frame) digest_ = (digest_ ^ b) * 0x100000001B3ull;
    return inner_.send(frame);
  }
  Result<std::size_t> receive(Bytes buffer, std::chrono::nanoseconds timeout) override {
    return inner_.receive(buffer, timeout);
  }
  std::string describe() const override { return inner_.describe(); }
  std::uint64_t digest() const { return digest_; }

 private:
  Link& inner_;
  std::uint64_t digest_{0xCBF29CE484222325ull};
};

// Resident set size now (kB), from /proc/self/status.
long rssKb() {
  std::ifstream status("/proc/self/status");
  std::string key;
  while (status >> key) {
    if (key == "VmRSS:") {
      long kb = 0;
      status >> kb;
      return kb;
    }
    status.ignore(4096, '\n');
  }
  return 0;
}

int runOne(unsigned n) {
  const long rss0 = rssKb();
  const double t0 = wallS();
  VirtualClock clock(kNsPerSecond);
  topology::Segment segment;
  for (unsigned i = 0; i < n; ++i) {
    segment.addSlave(slavesim::makeGenericSlave(fmt::format("Slave{}", i + 1), i + 1));
  }
  segment.wireLine();
  auto links = MemoryLink::makePair(256);
  topology::ServerOptions serverOptions;
  serverOptions.idleWait = std::chrono::nanoseconds(0);
  topology::NetworkServer server(links.second, segment, clock, serverOptions);
  std::int64_t simNs = 0;
  master::VirtualBus bus(clock, [&](SimTime) -> std::optional<SimTime> {
    const auto c0 = cpuNs(CLOCK_THREAD_CPUTIME_ID);
    const bool waiting = links.second.pending() > 0;
    const auto before = server.counters().framesAnswered;
    (void)server.step();
    simNs += cpuNs(CLOCK_THREAD_CPUTIME_ID) - c0;
    if (waiting && server.counters().framesAnswered != before) {
      return server.counters().lastRoundTrip;
    }
    return std::nullopt;
  });
  DigestLink wire(links.first);
  master::Master m(wire, bus);
  const double t1 = wallS();
  const auto cpu0 = cpuNs(CLOCK_PROCESS_CPUTIME_ID);
  const SimTime v0 = clock.now();
  const Status status = m.start();
  const double t2 = wallS();
  const auto cpu = cpuNs(CLOCK_PROCESS_CPUTIME_ID) - cpu0;
  const long rss1 = rssKb();
  if (!status.ok()) {
    fmt::print("{:>6}  bring-up failed: {}\n", n, status.error().message().substr(0, 300));
    return 1;
  }
  const auto& counters = m.transport().counters();
  fmt::print("{:>6} {:>9.3f} {:>10.3f} {:>8.3f} {:>9.2f} {:>8} {:>10} {:>11.1f} {:>13.1f} {:016x}  {}\n",
             n, t1 - t0, t2 - t1, static_cast<double>(cpu) * 1e-9,
             static_cast<double>(simNs) / static_cast<double>(cpu), counters.framesSent,
             counters.datagramsSent, static_cast<double>(clock.now() - v0) / kNsPerMs,
             static_cast<double>(rss1 - rss0) / n, wire.digest(),
             m.slaves().back().state() == AlState::kOp
                                                       ? "OP"
                                                       : "not OP");
  return 0;
}

}  // namespace
}  // namespace ecsim

int main(int argc, char** argv) {
  std::vector<unsigned> sizes;
  for (int i = 1; i < argc; ++i) sizes.push_back(static_cast<unsigned>(std::strtoul(argv[i], nullptr, 0)));
  if (sizes.empty()) sizes = {1000, 4000, 16000, 65535};
  fmt::print("{:>6} {:>9} {:>10} {:>8} {:>9} {:>8} {:>10} {:>11} {:>13} {:>16}\n", "slaves",
             "build_s", "bringup_s", "cpu_s", "sim_share", "frames", "datagrams", "virtual_ms",
             "kb_per_slave", "wire_digest");
  std::fflush(stdout);
  int failed = 0;
  for (unsigned n : sizes) {
    const pid_t child = fork();
    if (child == 0) {
      const int rc = ecsim::runOne(n);
      std::fflush(stdout);
      _exit(rc);
    }
    int status = 0;
    waitpid(child, &status, 0);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) ++failed;
  }
  return failed == 0 ? 0 : 1;
}
