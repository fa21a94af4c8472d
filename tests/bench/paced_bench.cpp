// Frames per second the network server sustains over a real veth pair (issue #6): a private
// network namespace holds the pair (VethNamespace); a NetworkServer serves a line of generic
// slaves on one end in a thread of this process, and this program sends on the other end
// through a raw socket, one frame in flight (ping-pong) or several (window). Fast and paced
// mode. A figure, not a pass/fail test; without network privileges it says so and exits 0.
//
//   paced_bench [seconds per case]     (run as root; prints a table, docs/timing.md has one)
#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <thread>
#include <vector>

#include "link/netns.hpp"
#include "link/raw_socket_link.hpp"
#include "protocol/frame.hpp"
#include "slavesim/generic_slave.hpp"
#include "topology/network_server.hpp"
#include "topology/segment.hpp"

namespace ecsim {
namespace {

constexpr std::uint16_t kBytesPerSlave = 8;

struct CaseResult {
  double framesPerSecond{0};
  double meanRoundTripUs{0};  // as the sender sees it
  double p99RoundTripUs{0};
  double modelledRoundTripUs{0};
  std::uint64_t lost{0};
};

// One LRW over the whole image (8 bytes per slave); the index byte tells answers apart.
std::vector<std::uint8_t> cyclicFrame(std::size_t slaves) {
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  FrameBuilder b(
      buf, EthernetHeader{kBroadcastMac, {0x10, 0, 0, 0, 0, 1}, std::nullopt, kEtherTypeEtherCat});
  (void)b.add(Command::kLrw, 0, 0, static_cast<std::uint16_t>(slaves * kBytesPerSlave));
  auto len = b.finish();
  return {buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(len.ok() ? *len : 0)};
}

Result<CaseResult> runCase(const VethNamespace& ns, std::size_t slaves, bool paced, unsigned window,
                           std::chrono::milliseconds duration) {
  topology::Segment seg;
  for (std::size_t i = 0; i < slaves; ++i) {
    seg.addSlave(slavesim::makeGenericSlave("s", static_cast<std::uint32_t>(i)));
  }
  seg.wireLine();
  ECSIM_ASSIGN_OR_RETURN(auto serverLink,
                         RawSocketLink::open(ns.simulatorInterface(), {ns.name(), true}));
  ECSIM_ASSIGN_OR_RETURN(auto masterLink,
                         RawSocketLink::open(ns.masterInterface(), {ns.name(), true}));
  RealClock clock;
  topology::ServerOptions options;
  options.paced = paced;
  options.idleWait = std::chrono::microseconds(200);
  topology::NetworkServer server(serverLink, seg, clock, options);
  std::atomic<bool> stop{false};
  std::thread serving([&] { (void)server.run([&] { return stop.load(); }); });

  auto frame = cyclicFrame(slaves);
  std::array<std::uint8_t, kMaxFrameSize> in{};
  std::vector<std::chrono::steady_clock::time_point> sentAt(256);
  std::vector<double> roundTrips;
  std::uint64_t answered = 0;
  std::uint64_t sent = 0;
  unsigned inFlight = 0;
  std::uint8_t index = 0;
  const auto start = std::chrono::steady_clock::now();
  const auto end = start + duration;
  auto lastProgress = start;
  while (std::chrono::steady_clock::now() < end) {
    while (inFlight < window) {
      frame[17] = ++index;  // the first datagram's index (14 + 2 header + command)
      sentAt[index] = std::chrono::steady_clock::now();
      if (!masterLink.send(frame).ok()) break;
      ++sent;
      ++inFlight;
    }
    auto n = masterLink.receive(in, std::chrono::milliseconds(5));
    const auto now = std::chrono::steady_clock::now();
    // Our own frames come back to the sending socket too (promiscuous): only processed ones
    // (locally administered bit set by the first ESC) are answers.
    if (n.ok() && *n == frame.size() && in[6] == 0x12) {
      ++answered;
      --inFlight;
      lastProgress = now;
      roundTrips.push_back(std::chrono::duration<double, std::micro>(now - sentAt[in[17]]).count());
    } else if (now - lastProgress > std::chrono::milliseconds(50)) {
      inFlight = 0;  // a frame was lost: start the window again
      lastProgress = now;
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stop = true;
  serving.join();
  CaseResult r;
  r.framesPerSecond = static_cast<double>(answered) / seconds;
  r.lost = sent - answered - inFlight;
  if (!roundTrips.empty()) {
    double sum = 0;
    for (double v : roundTrips) sum += v;
    r.meanRoundTripUs = sum / static_cast<double>(roundTrips.size());
    std::sort(roundTrips.begin(), roundTrips.end());
    r.p99RoundTripUs = roundTrips[roundTrips.size() * 99 / 100];
  }
  r.modelledRoundTripUs = static_cast<double>(server.counters().lastRoundTrip) / 1000.0;
  return r;
}

int run(int argc, char** argv) {
  const int seconds = argc > 1 ? std::max(1, std::atoi(argv[1])) : 2;
  if (auto caps = checkNetworkCapabilities(); !caps.ok()) {
    fmt::print("paced_bench: skipped, needs network privileges: {}\n", caps.error().message());
    return 0;
  }
  auto ns = VethNamespace::create();
  if (!ns.ok()) {
    fmt::print(stderr, "paced_bench: {}\n", ns.error().message());
    return 1;
  }
  fmt::print("{:>6} {:>6} {:>6} {:>12} {:>14} {:>13} {:>13} {:>6}\n", "slaves", "mode", "window",
             "frames/s", "modelled rtt", "mean rtt", "p99 rtt", "lost");
  for (std::size_t slaves : {1u, 10u, 100u}) {
    for (bool paced : {false, true}) {
      for (unsigned window : {1u, 4u}) {
        auto r = runCase(*ns, slaves, paced, window, std::chrono::seconds(seconds));
        if (!r.ok()) {
          fmt::print(stderr, "paced_bench: {}\n", r.error().message());
          return 1;
        }
        fmt::print("{:>6} {:>6} {:>6} {:>12.0f} {:>11.1f} us {:>10.1f} us {:>10.1f} us {:>6}\n",
                   slaves, paced ? "paced" : "fast", window, r->framesPerSecond,
                   r->modelledRoundTripUs, r->meanRoundTripUs, r->p99RoundTripUs, r->lost);
      }
    }
  }
  return 0;
}

}  // namespace
}  // namespace ecsim

int main(int argc, char** argv) {
  return ecsim::run(argc, argv);
}
