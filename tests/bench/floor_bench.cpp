// How far `ecsim serve` is above the floor (issue 18). In a private network namespace with one
// veth pair (VethNamespace), this program talks on the master end as a ping-pong
// client: one frame in flight (tests/bench/floor_workload.hpp: a 64-byte BRD, or with
// --frame cycle sim_bench's cyclic LRW frames in turn after their set-up frames), the next
// sent when the answer is back, on SCHED_FIFO where permitted. On the simulator's end it
// starts, one after the other and alternating, the floor responder (tests/bench/
// floor_responder.cpp: receive, bump the working counter, send back; no simulation) and
// `ecsim serve --rt --slaves N`, for each slave count. It prints the median and 99th
// percentile round trip of each, the difference to the floor, and the cost per slave seen
// from outside ((difference at N - difference at 1) / (N - 1), and between the two largest
// counts) beside the same frames' cost per slave measured in this process
// (Segment::processFrame with warm caches and with cold ones, and Segment::pollSlaves, the
// firmware the server runs between frames; measured in every round beside the served runs,
// the median taken). A figure, never a pass/fail on timing: the exit status is 1 only when a
// responder did not answer, or answered with a wrong working counter.
//
//   floor_bench [--round-trips N] [--rounds R] [--slaves 1,10,60,250,1000] [--cpu C]
//               [--frame brd|cycle] [--serve 'NAME=PATH [ARG...]']...
//
// --cpu: the responders run on CPU C (through taskset) and the in-process figures are
// measured there too, the client on the other CPUs; default the last CPU when there are two
// or more, -1: nothing pinned. The two vCPUs of this project's machines do not run alike: the
// same in-process frame cost 51-61 ns per slave on CPU 0 and 34-36 ns on CPU 1 (1000 slaves,
// 2026-11-30), so a served figure from one and an in-process one from the other compared the
// CPUs, not the paths.
//
// --serve adds an `ecsim` binary to compare (several: e.g. before and after a change, measured
// in one run); ARGs are added to its `serve` command line. Default: the ecsim of this build.
// Without network privileges: exit status 77 (a skip for ctest), 1 when CI=true.
#include <fmt/core.h>

#include <sched.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "link/netns.hpp"
#include "link/raw_socket_link.hpp"
#include "link/signal_flag.hpp"
#include "protocol/frame.hpp"
#include "tests/bench/floor_workload.hpp"
#include "tests/support/ci_mode.hpp"

namespace ecsim {
namespace {

using Clock = std::chrono::steady_clock;

constexpr std::size_t kSourceMacAt = 6;
constexpr std::uint8_t kProcessedBit = 0x02;  // an ESC sets the locally administered bit
constexpr int kClientPriority = 70;           // below the responders' 80 (`serve --rt`)
constexpr auto kAnswerWait = std::chrono::milliseconds(200);
constexpr unsigned kMaxLostInARow = 20;
constexpr unsigned kWarmUp = 500;
constexpr int kSkip = 77;

struct Options {
  unsigned roundTrips{20000};
  unsigned rounds{3};
  std::vector<unsigned> slaves{1, 10, 60, 250, 1000};
  struct Serve {
    std::string name;
    std::string path;
    std::vector<std::string> args;
  };
  std::vector<Serve> serves;
  int cpu{-2};               // -2: the default (the last CPU when there are two or more), -1: none
  std::string frame{"brd"};  // tests/bench/floor_workload.hpp
};

// Pins the calling thread to `cpu` (>= 0) or to every CPU but it (`others`).
void pinTo(int cpu, bool others) {
  cpu_set_t set;
  CPU_ZERO(&set);
  const long count = ::sysconf(_SC_NPROCESSORS_ONLN);
  for (long c = 0; c < count; ++c) {
    if ((c == cpu) != others) CPU_SET(static_cast<int>(c), &set);
  }
  (void)::sched_setaffinity(0, sizeof set, &set);
}

struct Figures {
  double medianUs{0};
  double p99Us{0};
  unsigned lost{0};
};

using bench::median;

std::string loadAverage() {
  std::ifstream in("/proc/loadavg");
  std::string one, five, fifteen;
  in >> one >> five >> fifteen;
  return one + " " + five + " " + fifteen;
}

// The ping-pong client on the master's end of the pair.
class Client {
 public:
  explicit Client(RawSocketLink link) : link_(std::move(link)) { samples_.reserve(1 << 16); }

  // What to send from now on, and the working counters to expect of its cycle frames (of the
  // set-up frames: 1); `floor`: 1 everywhere, as the floor responder adds 1 to every WKC.
  void use(const bench::Workload& w, bool floor) {
    workload_ = &w;
    floor_ = floor;
    next_ = 0;
  }

  // Sends the workload's set-up frames, each answered with WKC 1.
  Status setup() {
    for (const auto& f : workload_->setup) {
      frame_ = f;
      ECSIM_ASSIGN_OR_RETURN(const double us, exchange(1));
      if (us < 0) return makeError(ErrorCode::kTimeout, "a set-up frame was not answered");
    }
    return okStatus();
  }

  // One round trip of the next cycle frame; the time in µs, or a negative value when no
  // answer came in time. An answer with another working counter than expected is an error.
  Result<double> roundTrip() {
    const std::size_t k = next_++ % workload_->cycle.size();
    frame_ = workload_->cycle[k];
    return exchange(expectedWkc(k));
  }

  // Of cycle frame k: the floor responder adds 1 to every WKC.
  std::uint16_t expectedWkc(std::size_t k) const {
    return floor_ ? std::uint16_t{1} : workload_->servedWkc[k];
  }

  Result<double> exchange(std::uint16_t wkc) {
    frame_[bench::indexOffset()] = ++index_;
    const auto start = Clock::now();
    ECSIM_TRY(link_.send(frame_));
    for (;;) {
      ECSIM_ASSIGN_OR_RETURN(const std::size_t n, link_.receive(in_, kAnswerWait));
      const auto now = Clock::now();
      if (n == frame_.size() && (in_[kSourceMacAt] & kProcessedBit) != 0 &&
          in_[bench::indexOffset()] == index_) {
        const std::uint16_t got = bench::lastWkc(ConstBytes(in_.data(), n)).value_or(0);
        if (got != wkc) {
          return makeError(ErrorCode::kInvalidArgument,
                           fmt::format("answer with WKC {}, expected {}", got, wkc));
        }
        return std::chrono::duration<double, std::micro>(now - start).count();
      }
      if (now - start >= kAnswerWait) return -1.0;
    }
  }

  // Waits (up to `limit`) until the responder answers at all.
  // A wrong working counter ends the wait at once.
  Status waitReady(std::chrono::seconds limit, const SignalFlag& stop) {
    const auto deadline = Clock::now() + limit;
    while (Clock::now() < deadline && !stop.raised()) {
      frame_ = workload_->cycle.front();
      auto r = exchange(expectedWkc(0));
      if (!r.ok() && r.error().code == ErrorCode::kInvalidArgument) return r.error();
      if (r.ok() && *r >= 0) return okStatus();
    }
    return makeError(
        ErrorCode::kTimeout,
        stop.raised() ? "interrupted" : "no answer within " + std::to_string(limit.count()) + " s");
  }

  Result<Figures> measure(unsigned count, const SignalFlag& stop) {
    for (unsigned i = 0; i < kWarmUp && !stop.raised(); ++i) ECSIM_TRY(roundTrip());
    samples_.clear();
    Figures f;
    unsigned lostInARow = 0;
    while (samples_.size() < count && !stop.raised()) {
      ECSIM_ASSIGN_OR_RETURN(const double us, roundTrip());
      if (us < 0) {
        ++f.lost;
        if (++lostInARow > kMaxLostInARow) {
          return makeError(ErrorCode::kTimeout,
                           fmt::format("{} frames in a row unanswered", lostInARow));
        }
        continue;
      }
      lostInARow = 0;
      samples_.push_back(us);
    }
    std::sort(samples_.begin(), samples_.end());
    if (!samples_.empty()) {
      f.medianUs = samples_[samples_.size() / 2];
      f.p99Us = samples_[samples_.size() * 99 / 100];
    }
    return f;
  }

 private:
  RawSocketLink link_;
  const bench::Workload* workload_{nullptr};
  bool floor_{false};
  std::size_t next_{0};
  std::vector<std::uint8_t> frame_;
  std::array<std::uint8_t, kMaxFrameSize> in_{};
  std::vector<double> samples_;
  std::uint8_t index_{0};
};

// Starts a responder in the namespace, measures it, stops it.
Result<Figures> measureResponder(const VethNamespace& ns, Client& client,
                                 const std::vector<std::string>& argv, unsigned count,
                                 const SignalFlag& stop) {
  const std::string log =
      (std::filesystem::temp_directory_path() / fmt::format("ecsim-floor-bench-{}.log", ::getpid()))
          .string();
  ECSIM_ASSIGN_OR_RETURN(auto child, ns.spawn(argv, SpawnOptions{log, log}));
  auto failed = [&](const std::string& what) {
    (void)child.stop();
    std::ifstream in(log);
    std::stringstream s;
    s << in.rdbuf();
    std::filesystem::remove(log);
    return makeError(ErrorCode::kIo,
                     fmt::format("{}: {}; its output:\n{}", argv.front(), what, s.str()));
  };
  if (auto ready = client.waitReady(std::chrono::seconds(30), stop); !ready.ok()) {
    return failed(ready.error().message());
  }
  if (auto set = client.setup(); !set.ok()) return failed(set.error().message());
  auto figures = client.measure(count, stop);
  if (!figures.ok()) return failed(figures.error().message());
  (void)child.stop();
  std::filesystem::remove(log);
  return figures;
}

Result<Options> parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc) {
      return makeError(ErrorCode::kInvalidArgument, "option '" + a + "' wants a value");
    }
    const std::string v = argv[++i];
    if (a == "--round-trips") {
      o.roundTrips = static_cast<unsigned>(std::max(1, std::atoi(v.c_str())));
    } else if (a == "--rounds") {
      o.rounds = static_cast<unsigned>(std::max(1, std::atoi(v.c_str())));
    } else if (a == "--slaves") {
      o.slaves.clear();
      std::stringstream s(v);
      std::string item;
      while (std::getline(s, item, ',')) {
        const int n = std::atoi(item.c_str());
        if (n < 1 || n > 65535) {
          return makeError(ErrorCode::kInvalidArgument, "--slaves: '" + item + "' not 1..65535");
        }
        o.slaves.push_back(static_cast<unsigned>(n));
      }
    } else if (a == "--cpu") {
      const auto [end, error] = std::from_chars(v.data(), v.data() + v.size(), o.cpu);
      if (error != std::errc() || end != v.data() + v.size() || o.cpu < -1 ||
          o.cpu >= ::sysconf(_SC_NPROCESSORS_ONLN)) {
        return makeError(ErrorCode::kInvalidArgument, "--cpu: '" + v + "' is no CPU here");
      }
    } else if (a == "--frame") {
      if (v != "brd" && v != "cycle") {
        return makeError(ErrorCode::kInvalidArgument, "--frame: '" + v + "' (brd or cycle)");
      }
      o.frame = v;
    } else if (a == "--serve") {
      std::stringstream s(v);
      std::string spec;
      s >> spec;
      const auto eq = spec.find('=');
      if (eq == std::string::npos || eq == 0) {
        return makeError(ErrorCode::kInvalidArgument, "--serve wants 'NAME=PATH [ARG...]'");
      }
      Options::Serve serve{spec.substr(0, eq), spec.substr(eq + 1), {}};
      for (std::string arg; s >> arg;) serve.args.push_back(arg);
      o.serves.push_back(serve);
    } else {
      return makeError(ErrorCode::kInvalidArgument,
                       "unknown option '" + a +
                           "' (--round-trips, --rounds, --slaves, --cpu, --frame, --serve)");
    }
  }
  if (o.serves.empty()) o.serves.push_back({"serve", ECSIM_BINARY, {}});
  if (o.cpu == -2) {
    const long count = ::sysconf(_SC_NPROCESSORS_ONLN);
    o.cpu = count >= 2 ? static_cast<int>(count - 1) : -1;
  }
  if (std::find(o.slaves.begin(), o.slaves.end(), 1u) == o.slaves.end()) {
    o.slaves.insert(o.slaves.begin(), 1);  // the per-slave cost is taken against 1 slave
  }
  return o;
}

int run(int argc, char** argv) {
  auto parsed = parse(argc, argv);
  if (!parsed.ok()) {
    fmt::print(stderr, "floor_bench: {}\n", parsed.error().message());
    return 2;
  }
  const Options& o = *parsed;
  if (auto caps = checkNetworkCapabilities(); !caps.ok()) {
    fmt::print(stderr, "floor_bench: needs network privileges: {}\n", caps.error().message());
    return ecsim::testing::ciMode() ? 1 : kSkip;
  }
  SignalFlag stop;
  auto ns = VethNamespace::create();
  if (!ns.ok()) {
    fmt::print(stderr, "floor_bench: {}\n", ns.error().message());
    return 1;
  }
  auto link = RawSocketLink::open(ns->masterInterface(), {ns->name(), true});
  if (!link.ok()) {
    fmt::print(stderr, "floor_bench: {}\n", link.error().message());
    return 1;
  }
  Client client(std::move(link).value());
  // Children start with normal scheduling: `serve --rt` and `floor_responder --rt` set theirs.
  sched_param param{};
  param.sched_priority = kClientPriority;
  const bool fifo = sched_setscheduler(0, SCHED_FIFO | SCHED_RESET_ON_FORK, &param) == 0;
  if (o.cpu >= 0) pinTo(o.cpu, true);  // the client off the responders' CPU
  fmt::print(
      "floor_bench: {} round trips per run, {} round(s), {}, client {}; {}; "
      "load average at start {}\n",
      o.roundTrips, o.rounds,
      o.frame == "brd" ? "64-byte BRD" : "BM_CyclicFrame's frames in turn (LRW, FRMW)",
      fifo ? "SCHED_FIFO" : "normal priority (FIFO refused)",
      o.cpu >= 0
          ? fmt::format("responders and in-process figures on CPU {}, the client off it", o.cpu)
          : std::string("no CPU pinned"),
      loadAverage());
  std::fflush(stdout);

  std::map<unsigned, bench::Workload> workloads;
  for (unsigned n : o.slaves) workloads[n] = bench::makeWorkload(o.frame, n);
  // results[responder][slaves] = one Figures per round; "floor" is the floor responder.
  // inside[slaves] = the in-process figures, one per round (1 slave always among them).
  std::map<unsigned, std::vector<bench::InProcess>> inside;
  std::map<std::string, std::map<unsigned, std::vector<Figures>>> results;
  for (unsigned round = 0; round < o.rounds && !stop.raised(); ++round) {
    for (unsigned n : o.slaves) {
      // Alternating: the floor, then each serve; the order turns round every other round.
      std::vector<std::string> order{"floor"};
      for (const auto& s : o.serves) order.push_back(s.name);
      if (round % 2 == 1) std::reverse(order.begin(), order.end());
      for (const auto& who : order) {
        if (stop.raised()) break;
        std::vector<std::string> command;
        if (o.cpu >= 0) command = {"taskset", "-c", std::to_string(o.cpu)};
        client.use(workloads.at(n), who == "floor");
        if (who == "floor") {
          command.insert(command.end(), {ECSIM_FLOOR_RESPONDER, ns->simulatorInterface(), "--rt",
                                         "--qdisc-bypass"});
        } else {
          const auto& s = *std::find_if(o.serves.begin(), o.serves.end(),
                                        [&](const auto& x) { return x.name == who; });
          command.insert(command.end(), {s.path, "serve", "--iface", ns->simulatorInterface(),
                                         "--slaves", std::to_string(n), "--rt", "--quiet"});
          command.insert(command.end(), s.args.begin(), s.args.end());
        }
        auto f = measureResponder(*ns, client, command, o.roundTrips, stop);
        if (!f.ok()) {
          if (stop.raised()) break;
          fmt::print(stderr, "floor_bench: {} ({} slaves): {}\n", who, n, f.error().message());
          return 1;
        }
        results[who][n].push_back(*f);
        fmt::print(stderr,
                   "round {} slaves {:>5} {:>12}: median {:7.2f} us  p99 {:7.2f} us  "
                   "lost {}\n",
                   round + 1, n, who, f->medianUs, f->p99Us, f->lost);
      }
      // The same frames in this process, in every round beside the served runs, so that a
      // slow or fast phase of the host weighs on both figures of a ratio alike.
      if (o.cpu >= 0) pinTo(o.cpu, false);  // where the responders run
      if (n == o.slaves.front() && n != 1) inside[1].push_back(bench::measureInProcess(o.frame, 1));
      inside[n].push_back(bench::measureInProcess(o.frame, n));
      if (o.cpu >= 0) pinTo(o.cpu, true);
    }
  }
  if (stop.raised()) {
    fmt::print(stderr, "floor_bench: interrupted\n");
    return 1;
  }

  auto med = [&](const std::string& who, unsigned n, auto field) {
    std::vector<double> v;
    for (const auto& f : results[who][n]) v.push_back(f.*field);
    return median(v);
  };
  // The difference to the floor, per round (the floor run beside it), median of rounds.
  auto overhead = [&](const std::string& who, unsigned n) {
    std::vector<double> v;
    const auto& floor = results["floor"][n];
    const auto& served = results[who][n];
    for (std::size_t r = 0; r < served.size() && r < floor.size(); ++r) {
      v.push_back(served[r].medianUs - floor[r].medianUs);
    }
    return median(v);
  };
  fmt::print("\nround trip, median of {} round(s) (load average now {}):\n", o.rounds,
             loadAverage());
  fmt::print("{:>6} {:>14} {:>10} {:>10}  {:>14}\n", "slaves", "responder", "median", "p99",
             "over floor");
  for (unsigned n : o.slaves) {
    fmt::print("{:>6} {:>14} {:>7.2f} us {:>7.2f} us\n", n, "floor",
               med("floor", n, &Figures::medianUs), med("floor", n, &Figures::p99Us));
    for (const auto& s : o.serves) {
      fmt::print("{:>6} {:>14} {:>7.2f} us {:>7.2f} us  {:>+11.2f} us\n", n, s.name,
                 med(s.name, n, &Figures::medianUs), med(s.name, n, &Figures::p99Us),
                 overhead(s.name, n));
    }
  }
  fmt::print("\ncost per slave (outside: (over floor at N - over floor at 1) / (N - 1)):\n");
  fmt::print("{:>6} {:>16} {:>16} {:>16}", "slaves", "in-process frame", "cold caches",
             "in-process poll");
  for (const auto& s : o.serves) fmt::print(" {:>14} {:>6}", s.name, "ratio");
  fmt::print("\n");
  // Each in-process figure: the median of the rounds.
  const auto inProcess = [&](unsigned n) {
    const auto& rounds = inside[n];
    auto of = [&](double bench::InProcess::*field) {
      std::vector<double> v;
      for (const auto& r : rounds) v.push_back(r.*field);
      return median(v);
    };
    bench::InProcess m;
    m.frameNs = of(&bench::InProcess::frameNs);
    m.coldFrameNs = of(&bench::InProcess::coldFrameNs);
    m.pollNs = of(&bench::InProcess::pollNs);
    m.frames = of(&bench::InProcess::frames);
    return m;
  };
  const bench::InProcess one = inProcess(1);
  fmt::print("{:>6} {:>13.1f} ns {:>13.1f} ns {:>13.1f} ns   (whole frame, 1 slave)\n", 1,
             one.frameNs, one.coldFrameNs, one.pollNs);
  std::map<unsigned, bench::InProcess> atCount;
  for (unsigned n : o.slaves) {
    if (n == 1) continue;
    const bench::InProcess at = atCount[n] = inProcess(n);
    const double frame = (at.frameNs - one.frameNs) / (n - 1);
    const double cold = (at.coldFrameNs - one.coldFrameNs) / (n - 1);
    const double poll = (at.pollNs - one.pollNs) / (n - 1);
    fmt::print("{:>6} {:>13.1f} ns {:>13.1f} ns {:>13.1f} ns", n, frame, cold, poll);
    for (const auto& s : o.serves) {
      const double outside = (overhead(s.name, n) - overhead(s.name, 1)) * 1000.0 / (n - 1);
      fmt::print(" {:>11.1f} ns {:>6.2f}", outside, outside / frame);
    }
    fmt::print("\n");
  }
  // The same between the two largest counts: whatever of a small frame's processing overlaps
  // with the rest of the round trip (a responder that answers while the client's CPU is still
  // in its send, for one) drops out, where it inflates the 1-slave figure above.
  if (atCount.size() >= 2) {
    const auto [big, atBig] = *atCount.rbegin();
    const auto [small, atSmall] = *std::next(atCount.rbegin());
    const double frame = (atBig.frameNs - atSmall.frameNs) / (big - small);
    fmt::print("{:>6} {:>13.1f} ns {:>16} {:>16}", fmt::format("{}-{}", small, big), frame, "", "");
    for (const auto& s : o.serves) {
      const double outside =
          (overhead(s.name, big) - overhead(s.name, small)) * 1000.0 / (big - small);
      fmt::print(" {:>11.1f} ns {:>6.2f}", outside, outside / frame);
    }
    fmt::print("\n");
  }
  return 0;
}

}  // namespace
}  // namespace ecsim

int main(int argc, char** argv) {
  return ecsim::run(argc, argv);
}
