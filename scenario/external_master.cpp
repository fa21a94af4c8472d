// An external command as the master under test (scenario/master_under_test.hpp,
// docs/scenarios.md "External masters"): a private network namespace with a veth pair, the
// scenario's network served on the simulator's end in real time (paced, as
// `ecsim serve --paced`), the command started in the namespace with {iface} naming the
// master's end. A tick is one step of the simulator (a frame answered, or kIdleWait without
// one); a cycle is a process-data frame (LRW, LRD, LWR) the simulator saw. Time zero is the
// moment every slave is in OP as the simulator sees it (or the command's start with
// timeZero="start"). The command is stopped (SIGTERM, then SIGKILL after stopGraceMs) when the
// duration after time zero has passed, or when the network has not reached OP within
// startTimeoutMs. Everything runs in the engine's thread: the simulator, the timeline, the
// checks, and every kPollInterval a look at the command and its output.
#include <fmt/core.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>

#include "link/netns.hpp"
#include "link/raw_socket_link.hpp"
#include "link/realtime.hpp"
#include "link/signal_flag.hpp"
#include "protocol/frame.hpp"
#include "scenario/command_output.hpp"
#include "scenario/master_under_test.hpp"
#include "topology/network_builder.hpp"
#include "topology/network_server.hpp"

namespace ecsim::scenario {
namespace {

constexpr auto kIdleWait = std::chrono::microseconds(500);  // timeline resolution when idle
constexpr SimTime kPollInterval = 5 * kNsPerMs;             // the command and its output
// Where permitted, the engine's thread (the simulator) runs at SCHED_FIFO as `ecsim serve --rt`
// does, and the command at SCHED_FIFO below it, as the study runs its master: a loaded host
// then does not make either late. Under the ASan build with two CPU hogs, simple_test reported
// "ERROR : slave 1 lost" 11 times with both at normal priority, twice with only the command at
// SCHED_FIFO, never with both (soem_simple_test.xml, 10,013 lines of output).
constexpr int kEnginePriority = 80;
constexpr int kCommandPriority = 50;

std::string number(double v) {
  if (v == static_cast<double>(static_cast<std::int64_t>(v))) {
    return std::to_string(static_cast<std::int64_t>(v));
  }
  return fmt::format("{:.6g}", v);
}

// Counts the frames that carry process data (LRW, LRD or LWR) on their way in: an external
// master's cycles as the simulator sees them.
class CountingLink final : public Link {
 public:
  explicit CountingLink(Link& inner) : inner_(inner) {}
  Status send(ConstBytes frame) override { return inner_.send(frame); }
  Result<std::size_t> receive(Bytes buffer, std::chrono::nanoseconds timeout) override {
    auto n = inner_.receive(buffer, timeout);
    if (n.ok() && *n > 0) {
      if (auto frame = ConstEtherCatFrame::parse(ConstBytes(buffer.data(), *n)); frame.ok()) {
        for (auto d : *frame) {
          const auto c = d.command();
          if (c == Command::kLrw || c == Command::kLrd || c == Command::kLwr) {
            ++frames_;
            break;
          }
        }
      }
    }
    return n;
  }
  int pollFd() const override { return inner_.pollFd(); }
  std::string describe() const override { return inner_.describe(); }
  std::uint64_t frames() const { return frames_; }

 private:
  Link& inner_;
  std::uint64_t frames_{0};
};

class ExternalMaster final : public MasterUnderTest {
 public:
  explicit ExternalMaster(RunContext& c) : c_(c), s_(c.scenario), e_(c.options.external) {}
  ~ExternalMaster() override {
    std::error_code ignored;
    if (!outputFile_.empty() && e_.outputDir.empty()) std::filesystem::remove(outputFile_, ignored);
  }
  const Clock& clock() const override { return clock_; }
  bool virtualTime() const override { return false; }
  std::optional<SimTime> zero() const override { return zero_; }
  Status start() override;
  std::optional<Tick> next() override;
  Exchange exchange(const Tick& tick, bool paused) override;
  RunEnd stop() override;
  std::uint64_t cycles() const override { return zeroSeen_ ? link_->frames() - framesAtZero_ : 0; }
  const CommandFacts* command() const override { return &facts_; }
  std::vector<std::string> trailer() const override;
  std::string error() const override { return error_; }

 private:
  std::optional<Tick> end(std::string text, bool ranToEnd = false) {
    endText_ = std::move(text);
    ranToEnd_ = ranToEnd;
    return std::nullopt;
  }

  RunContext& c_;
  const Scenario& s_;
  const ExternalRunOptions& e_;
  std::optional<RealTimeThread> realtime_;  // first made, last restored
  RealClock clock_;
  std::optional<VethNamespace> ns_;
  std::optional<RawSocketLink> raw_;
  std::optional<CountingLink> link_;
  std::optional<topology::NetworkServer> server_;
  std::filesystem::path outputFile_;
  std::optional<CommandOutput> output_;
  std::optional<ChildProcess> child_;
  CommandFacts facts_;
  std::optional<SimTime> zero_;
  bool zeroSeen_{false};
  std::uint64_t framesAtZero_{0};
  std::uint64_t framesAtLastTick_{0};
  SimTime nextPoll_{0};
  std::string endText_;
  bool ranToEnd_{false};
  bool interrupted_{false};
  std::string error_;
};

Status ExternalMaster::start() {
  auto ns = VethNamespace::create();
  if (!ns.ok()) {
    return makeError(ns.error().code,
                     "cannot make the veth pair for the external master: " + ns.error().message());
  }
  ns_.emplace(std::move(*ns));
  Environment environment = e_.environment;
  if (!environment) {
    environment = [](const std::string& name) -> std::optional<std::string> {
      const char* v = std::getenv(name.c_str());
      return v == nullptr ? std::nullopt : std::optional<std::string>(v);
    };
  }
  ECSIM_ASSIGN_OR_RETURN(auto command, expandCommand(s_, ns_->masterInterface(), environment));
  auto raw = RawSocketLink::open(ns_->simulatorInterface(), RawSocketOptions{ns_->name(), true});
  if (!raw.ok()) return raw.error();
  raw_.emplace(std::move(*raw));
  link_.emplace(*raw_);
  topology::ServerOptions serverOptions;
  serverOptions.paced = true;
  serverOptions.idleWait = kIdleWait;
  server_.emplace(*link_, *c_.network.segment, clock_, serverOptions);

  const bool keepOutput = !e_.outputDir.empty();
  outputFile_ = keepOutput ? e_.outputDir / (s_.name + ".output.txt")
                           : std::filesystem::temp_directory_path() /
                                 fmt::format("ecsim-{}-{}.output.txt", s_.name, ::getpid());
  std::error_code ignored;
  std::filesystem::remove(outputFile_, ignored);  // no line of an earlier run is read
  auto output = CommandOutput::open(outputFile_, s_.expectations, e_.tailLines);
  if (!output.ok()) {
    return makeError(output.error().code,
                     fmt::format("{}: {}", s_.file.string(), output.error().message()));
  }
  output_.emplace(std::move(*output));
  facts_.output = &*output_;
  facts_.start = clock_.now();
  if (s_.timeFromStart) zero_ = facts_.start;
  realtime_.emplace(kEnginePriority);
  auto child = ns_->spawn({"/bin/sh", "-c", command},
                          SpawnOptions{outputFile_.string(), outputFile_.string(),
                                       realtime_->ok() ? kCommandPriority : 0});
  if (!child.ok()) {
    return makeError(child.error().code,
                     fmt::format("{}, line {}: cannot start the command: {}", s_.file.string(),
                                 s_.masterLine, child.error().message()));
  }
  child_.emplace(std::move(*child));
  c_.log.add(facts_.start,
             "command started: " + s_.masterCommand +
                 (realtime_->ok() ? fmt::format(" (SCHED_FIFO {}, the simulator {})",
                                                kCommandPriority, kEnginePriority)
                                  : " (simulator and command " + realtime_->note() + ")"));
  nextPoll_ = facts_.start;
  return okStatus();
}

std::optional<Tick> ExternalMaster::next() {
  for (;;) {
    if (c_.signals != nullptr && c_.signals->raised()) {
      interrupted_ = true;
      error_ = fmt::format("interrupted by signal {} ({}): the command was stopped",
                           c_.signals->signal(), strsignal(c_.signals->signal()));
      return end("interrupted by a signal");
    }
    if (auto st = server_->step(); !st.ok()) {
      error_ = "the simulator stopped: " + st.error().message();
      return end("the simulator stopped");
    }
    const SimTime now = clock_.now();
    if (now >= nextPoll_) {
      nextPoll_ = now + kPollInterval;
      if (auto code = child_->wait(std::chrono::nanoseconds(0)); code.ok()) {
        facts_.exitStatus = *code;
        return end(fmt::format("the command exited with status {}", *code));
      }
      output_->poll(now, zero_.value_or(kNoTimeZero));
    }
    if (!zero_) {
      if (c_.judge.allOp()) {
        zero_ = now;
        c_.log.add(now, fmt::format("all {} slaves in OP: time zero", c_.network.segment->size()));
      } else if (now >= facts_.start + s_.startTimeout) {
        return end(fmt::format("not all slaves in OP within startTimeoutMs {}",
                               number(static_cast<double>(s_.startTimeout) / kNsPerMs)));
      } else {
        continue;
      }
    }
    if (!zeroSeen_) {  // the first tick from time zero
      zeroSeen_ = true;
      framesAtZero_ = link_->frames();
      framesAtLastTick_ = framesAtZero_;
    }
    if (now >= *zero_ + s_.duration) return end("the scenario's duration passed", true);
    return Tick{link_->frames() - framesAtZero_, now, 0, false};
  }
}

// Back in OP for an external master: every slave in OP while it exchanges process data.
Exchange ExternalMaster::exchange(const Tick&, bool) {
  const bool frameSinceLastTick = link_->frames() != framesAtLastTick_;
  framesAtLastTick_ = link_->frames();
  return Exchange{std::nullopt, frameSinceLastTick && c_.judge.allOp()};
}

RunEnd ExternalMaster::stop() {
  std::string text = endText_;
  if (!facts_.exitStatus) {
    const SimTime stopping = clock_.now();
    auto code = child_->stop(std::chrono::nanoseconds(s_.stopGrace));
    if (code.ok()) facts_.exitStatus = *code;
    facts_.exitHow = code.ok() && *code == 128 + SIGKILL ? " (killed with SIGKILL after SIGTERM)"
                                                         : " (stopped with SIGTERM)";
    c_.log.add(stopping, text + ": command stopped" + facts_.exitHow);
    if (!interrupted_) text += ", the command was stopped";
  } else {
    c_.log.add(clock_.now(), text);
  }
  const SimTime endAt = clock_.now();
  output_->finish(endAt, zero_.value_or(kNoTimeZero));
  return RunEnd{endAt, zero_, ranToEnd_, text};
}

std::vector<std::string> ExternalMaster::trailer() const {
  std::vector<std::string> out;
  if (!output_) return out;
  const auto& tail = output_->tail();
  out.push_back(fmt::format("  output: last {} of {} lines{}", tail.size(), output_->lineCount(),
                            e_.outputDir.empty() ? "" : ", all in " + outputFile_.string()));
  if (output_->cutLines() > 0) {
    out.push_back(
        fmt::format("  output: {} lines longer than {} bytes, judged in pieces of "
                    "that size",
                    output_->cutLines(), kMaxOutputLine));
  }
  constexpr std::size_t kShownLine = 1000;  // bytes of a tail line in the report
  for (const auto& line : tail) {
    out.push_back("    | " +
                  (line.size() <= kShownLine
                       ? line
                       : line.substr(0, kShownLine) + fmt::format("... ({} bytes)", line.size())));
  }
  return out;
}

}  // namespace

std::unique_ptr<MasterUnderTest> makeExternalMaster(RunContext& context) {
  return std::make_unique<ExternalMaster>(context);
}

Result<std::string> expandCommand(const Scenario& s, std::string_view iface,
                                  const Environment& environment) {
  const std::string& in = s.masterCommand;
  auto error = [&](const std::string& what) {
    return makeError(ErrorCode::kInvalidArgument,
                     fmt::format("{}, line {}: {}", s.file.string(), s.masterLine, what));
  };
  constexpr std::string_view kIface = "{iface}";
  std::string out;
  for (std::size_t i = 0; i < in.size();) {
    if (in.compare(i, kIface.size(), kIface) == 0) {
      out += iface;
      i += kIface.size();
    } else if (in.compare(i, 2, "${") == 0) {
      const auto close = in.find('}', i + 2);
      if (close == std::string::npos) return error("unterminated ${ in the command");
      const std::string name = in.substr(i + 2, close - i - 2);
      auto value = environment ? environment(name) : std::nullopt;
      if (!value) return error("${" + name + "} in the command is not set in the environment");
      out += *value;
      i = close + 1;
    } else {
      out += in[i++];
    }
  }
  return out;
}

}  // namespace ecsim::scenario
