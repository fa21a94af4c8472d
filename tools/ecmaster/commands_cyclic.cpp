// ecmaster cyclic: bring the bus to OP, exchange process data at a fixed cycle, print
// statistics (round trip min/mean/max, lost frames, WKC errors).
#include <fmt/core.h>

#include "link/signal_flag.hpp"
#include "tools/ecmaster/commands.hpp"

namespace ecsim::tools::ecmaster {
namespace {

struct CyclicOptions {
  unsigned cycleUs{1000};
  double seconds{1.0};
  bool stopAtEnd{true};
};

int runCyclic(const GlobalOptions& g, const CyclicOptions& o) {
  auto c = connectAndScan(g, true);
  if (!c.ok()) return fail(c.error());
  master::Master& m = (*c)->master();
  master::Bus& bus = (*c)->bus();
  if (auto s = m.bringTo(AlState::kOp); !s.ok()) return fail(s.error());
  const SimTime cycle = static_cast<SimTime>(o.cycleUs) * kNsPerUs;
  const SimTime duration = static_cast<SimTime>(o.seconds * static_cast<double>(kNsPerSecond));
  SignalFlag stop;
  const auto startCounters = m.transport().counters();
  const std::uint64_t startCycles = m.statistics().cycles;
  std::uint64_t failedCycles = 0;
  std::uint64_t overruns = 0;
  std::string firstError;
  const SimTime start = bus.now();
  SimTime next = start;
  while (!stop.raised() && bus.now() - start < duration) {
    auto status = m.exchange();
    if (!status.ok()) {
      ++failedCycles;
      if (firstError.empty()) firstError = status.error().message();
    }
    next += cycle;
    if (bus.now() > next) {
      ++overruns;  // the cycle took longer than its period: start the next one now
      next = bus.now();
    }
    while (bus.now() < next && !stop.raised()) bus.wait(next);
  }
  const auto& st = m.statistics();
  const auto& tc = m.transport().counters();
  const std::uint64_t cycles = st.cycles - startCycles;
  (void)m.readStates();
  Status stopped = o.stopAtEnd ? m.stop() : okStatus();
  if (g.json) {
    nlohmann::json j{{"cycles", cycles},
                     {"cycleTimeUs", o.cycleUs},
                     {"roundTripUs",
                      {{"min", static_cast<double>(st.roundTripMin) / 1e3},
                       {"mean", static_cast<double>(st.roundTripMean()) / 1e3},
                       {"max", static_cast<double>(st.roundTripMax) / 1e3}}},
                     {"framesPerCycle", m.layout().frameCount},
                     {"framesLost", tc.framesLost - startCounters.framesLost},
                     {"framesLate", tc.framesLate - startCounters.framesLate},
                     {"wkcErrors", st.wkcErrors},
                     {"failedCycles", failedCycles},
                     {"overruns", overruns},
                     {"outputBytes", m.layout().outputBytes},
                     {"inputBytes", m.layout().inputBytes},
                     {"slaves", m.slaves().size()},
                     {"simulated", (*c)->simulated()}};
    if (!firstError.empty()) j["firstError"] = firstError;
    printJson(j);
  } else {
    fmt::print("{} slaves in OP, {} output + {} input bytes in {} frame(s) per cycle\n",
               m.slaves().size(), m.layout().outputBytes, m.layout().inputBytes,
               m.layout().frameCount);
    fmt::print("cycles {} at {} us{}\n", cycles, o.cycleUs,
               (*c)->simulated() ? " (virtual time)" : "");
    fmt::print("round trip us: min {:.1f} mean {:.1f} max {:.1f}\n",
               static_cast<double>(st.roundTripMin) / 1e3,
               static_cast<double>(st.roundTripMean()) / 1e3,
               static_cast<double>(st.roundTripMax) / 1e3);
    fmt::print("lost frames {}, late frames {}, WKC errors {}, failed cycles {}, overruns {}\n",
               tc.framesLost - startCounters.framesLost, tc.framesLate - startCounters.framesLate,
               st.wkcErrors, failedCycles, overruns);
    if (!firstError.empty()) fmt::print("first error: {}\n", firstError);
  }
  if (!stopped.ok()) return fail(stopped.error());
  return failedCycles == 0 ? 0 : 1;
}

}  // namespace

CommandRunner addCyclicCommand(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<CyclicOptions>();
  auto* cmd = app.add_subcommand("cyclic", "Bring the bus to OP and exchange process data");
  cmd->add_option("--cycle-us", o->cycleUs, "Cycle time in microseconds (default 1000)")
      ->check(CLI::Range(10u, 10'000'000u));
  cmd->add_option("--seconds", o->seconds, "How long to run (default 1)")
      ->check(CLI::Range(0.0, 86400.0));
  cmd->add_flag("!--no-stop", o->stopAtEnd, "Leave the slaves in OP at the end");
  return [&global, o] { return runCyclic(global, *o); };
}

}  // namespace ecsim::tools::ecmaster
