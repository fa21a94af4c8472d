#include "scenario/external_runner.hpp"

#include <fcntl.h>
#include <fmt/core.h>
#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <thread>
#include <vector>

#include "config/topology_file.hpp"
#include "link/fd.hpp"
#include "link/netns.hpp"
#include "link/pcap.hpp"
#include "link/raw_socket_link.hpp"
#include "link/signal_flag.hpp"
#include "protocol/al_status.hpp"
#include "protocol/frame.hpp"
#include "protocol/registers.hpp"
#include "scenario/command_output.hpp"
#include "topology/faults.hpp"
#include "topology/network_builder.hpp"
#include "topology/network_server.hpp"
#include "topology/pcap_cable_tap.hpp"

namespace ecsim::scenario {
namespace {

constexpr SimTime kNoTime = kNoTimeZero;
constexpr auto kIdleWait = std::chrono::microseconds(500);  // timeline resolution when idle
constexpr auto kPollInterval = std::chrono::milliseconds(5);
constexpr auto kServingTimeout = std::chrono::seconds(30);  // the simulator's thread starting

std::string ms(SimTime t) {
  return fmt::format("{:.3f} ms", static_cast<double>(t) / static_cast<double>(kNsPerMs));
}

std::string number(double v) {
  if (v == static_cast<double>(static_cast<std::int64_t>(v))) {
    return std::to_string(static_cast<std::int64_t>(v));
  }
  return fmt::format("{:.6g}", v);
}

std::string stateText(std::uint16_t status, std::uint16_t code) {
  auto state = alStateFromRaw(static_cast<std::uint16_t>(status & kAlStateMask));
  std::string s = state ? std::string(toString(*state)) : fmt::format("{:#x}", status & 0xF);
  if ((status & 0x10) != 0) s += fmt::format("+ERR {:#06x} ({})", code, alStatusCodeText(code));
  return s;
}

// Counts the frames that carry process data (LRW, LRD or LWR) on their way in: an external
// master's cycles as the simulator sees them. Used by the server's thread only.
class CountingLink final : public Link {
 public:
  CountingLink(Link& inner, std::uint64_t& frames) : inner_(inner), frames_(frames) {}
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

 private:
  Link& inner_;
  std::uint64_t& frames_;
};

struct LogEntry {
  SimTime at{0};  // RealClock time
  std::string text;
};

class ExternalRun {
 public:
  ExternalRun(const Scenario& s, const RunOptions& o, const ExternalRunOptions& e)
      : s_(s), o_(o), e_(e) {}
  ScenarioResult execute();

 private:
  // Server thread.
  void serve(topology::NetworkServer& server);
  void tick();
  bool allOp() const;
  std::optional<std::size_t> slaveIndex(const std::string& name) const;
  ExpectationResult evaluatePoint(const Expectation& x, SimTime at) const;
  // Main thread, after the server thread has ended.
  void finish(SimTime end, const std::string& endText);
  ExpectationResult evaluateBackInOp(std::size_t i, SimTime end) const;
  ExpectationResult evaluateCommand(std::size_t index, SimTime end) const;
  void log(SimTime at, std::string text) { log_.push_back({at, std::move(text)}); }

  const Scenario& s_;
  const RunOptions& o_;
  const ExternalRunOptions& e_;
  ScenarioResult r_;
  RealClock clock_;
  topology::Network network_;
  std::optional<topology::FaultInjector> faults_;

  // Shared between the threads.
  std::atomic<bool> stop_{false};
  std::atomic<bool> serving_{false};
  std::atomic<bool> serverEnded_{false};
  std::atomic<SimTime> zero_{kNoTime};  // time zero (all slaves in OP, or the start)

  // Owned by the server thread while it runs.
  std::uint64_t lrwFrames_{0};
  std::uint64_t lrwAtZero_{0};
  bool zeroSeen_{false};
  std::uint64_t lastTickFrames_{0};
  std::vector<bool> applied_;
  std::vector<bool> checked_;
  std::vector<std::optional<SimTime>> afterAt_;  // BackInOp: when its "after" came
  std::vector<std::optional<SimTime>> backAt_;   // BackInOp: first moment back in OP
  std::vector<LogEntry> serverLog_;
  std::vector<ExpectationResult> timedResults_;
  std::string serverError_;
  std::string schedulingNote_;

  // Main thread.
  std::vector<LogEntry> log_;
  std::optional<int> exitStatus_;
  std::string exitHow_;
  SimTime commandStart_{0};
  std::optional<CommandOutput> output_;
};

bool ExternalRun::allOp() const {
  const auto& seg = *network_.segment;
  for (std::size_t i = 0; i < seg.size(); ++i) {
    if (seg.slave(i).esc().alStatus() != static_cast<std::uint16_t>(AlState::kOp)) return false;
  }
  return seg.size() > 0;
}

std::optional<std::size_t> ExternalRun::slaveIndex(const std::string& name) const {
  const auto& seg = *network_.segment;
  for (std::size_t i = 0; i < seg.size(); ++i) {
    if (seg.slave(i).name() == name) return i;
  }
  return std::nullopt;
}

void ExternalRun::serve(topology::NetworkServer& server) {
  if (e_.realtime) {
    // Answers must come within the master's timeout (SOEM: 2 ms) even on a busy host.
    sched_param param{};
    param.sched_priority = 80;
    if (const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param); rc != 0) {
      schedulingNote_ =
          fmt::format("SCHED_FIFO not permitted ({}): normal priority", errnoText(rc));
    }
  }
  serving_ = true;
  auto status = server.run([this] {
    tick();
    return stop_.load();
  });
  if (!status.ok()) serverError_ = "the simulator stopped: " + status.error().message();
  serverEnded_ = true;
}

// Between two frames (at least every kIdleWait): time zero, the timeline, the timed checks.
void ExternalRun::tick() {
  const SimTime now = clock_.now();
  SimTime zero = zero_.load();
  if (zero == kNoTime) {
    if (s_.timeFromStart || !allOp()) return;
    zero = now;
    zero_ = now;
    serverLog_.push_back(
        {now, fmt::format("all {} slaves in OP: time zero", network_.segment->size())});
  }
  if (!zeroSeen_) {
    zeroSeen_ = true;
    lrwAtZero_ = lrwFrames_;
    lastTickFrames_ = lrwFrames_;
  }
  const SimTime since = now - zero;
  const std::uint64_t cycle = lrwFrames_ - lrwAtZero_;
  for (std::size_t i = 0; i < s_.actions.size(); ++i) {
    const auto& a = s_.actions[i];
    if (applied_[i] || !((a.cycle && cycle >= *a.cycle) || (a.time && since >= *a.time))) continue;
    applied_[i] = true;
    auto done = faults_->apply(a.fault, now, a.action.where);
    serverLog_.push_back({now, fmt::format("cycle {:>6}  {}: {}", cycle, a.action.text(),
                                           done.ok() ? *done : "ERROR " + done.error().context)});
    if (!done.ok() && serverError_.empty()) serverError_ = done.error().context;
  }
  const bool frameSinceLastTick = lrwFrames_ != lastTickFrames_;
  lastTickFrames_ = lrwFrames_;
  for (std::size_t i = 0; i < s_.expectations.size(); ++i) {
    const auto& x = s_.expectations[i];
    if (x.kind == ExpectKind::kBackInOp) {
      if (!afterAt_[i] && (x.afterTime ? since >= *x.afterTime : cycle >= x.afterCycle)) {
        afterAt_[i] = now;
      }
      // Back: every slave in OP while the master exchanges process data.
      if (afterAt_[i] && !backAt_[i] && frameSinceLastTick && allOp()) backAt_[i] = now;
      continue;
    }
    if (checked_[i] || !(x.atCycle || x.atTime)) continue;
    if ((x.atCycle && cycle >= *x.atCycle) || (x.atTime && since >= *x.atTime)) {
      checked_[i] = true;
      timedResults_.push_back(evaluatePoint(x, since));
    }
  }
}

ExpectationResult ExternalRun::evaluatePoint(const Expectation& x, SimTime at) const {
  ExpectationResult res{x.line, x.describe(), false, at, {}, x.needsRecovery};
  auto slave = slaveIndex(x.slave);
  if (!slave) {
    res.observed = "no slave named '" + x.slave + "' in the topology";
    return res;
  }
  const auto& esc = network_.segment->slave(*slave).esc();
  if (x.kind == ExpectKind::kState) {
    const std::uint16_t status = esc.alStatus();
    const std::uint16_t code = esc.read(reg::kAlStatusCode);
    res.observed = stateText(status, code);
    auto state = alStateFromRaw(static_cast<std::uint16_t>(status & kAlStateMask));
    bool ok = state && toString(*state) == x.state;
    if (x.error) ok = ok && (((status & 0x10) != 0) == *x.error);
    if (x.code) ok = ok && code == *x.code;
    res.passed = ok;
  } else if (x.kind == ExpectKind::kRegister) {
    std::uint32_t raw = x.width == 1   ? esc.reg8(x.address)
                        : x.width == 2 ? esc.reg16(x.address)
                                       : esc.reg32(x.address);
    raw &= x.mask;
    const double v = static_cast<double>(raw);
    res.observed = fmt::format("{} ({:#x})", number(v), raw);
    res.passed = compareValues(v, x.compare, x.value, x.tolerance);
  } else {
    res.observed = "not judged for an external master";
  }
  return res;
}

ExpectationResult ExternalRun::evaluateBackInOp(std::size_t i, SimTime end) const {
  const auto& x = s_.expectations[i];
  const SimTime zero = zero_.load();
  ExpectationResult res{x.line, x.describe(), false, end - zero, {}, x.needsRecovery};
  const std::string after = x.afterTime ? ms(*x.afterTime) : fmt::format("cycle {}", x.afterCycle);
  if (!afterAt_[i]) {
    res.observed = "the run ended before " + after;
    return res;
  }
  if (backAt_[i]) {
    const SimTime took = *backAt_[i] - *afterAt_[i];
    res.at = *backAt_[i] - zero;
    res.passed = took <= x.within;
    res.observed = fmt::format("all slaves in OP with process data at {} ({} after {}){}",
                               ms(res.at), ms(took), after, res.passed ? "" : ", too late");
    return res;
  }
  std::string states;
  const auto& seg = *network_.segment;
  for (std::size_t k = 0; k < seg.size(); ++k) {
    const auto& esc = seg.slave(k).esc();
    states += fmt::format("{}{} {}", k == 0 ? "" : ", ", seg.slave(k).name(),
                          stateText(esc.alStatus(), esc.read(reg::kAlStatusCode)));
  }
  res.observed = "never back in OP after " + after + "; at the end: " + states;
  return res;
}

ExpectationResult ExternalRun::evaluateCommand(std::size_t index, SimTime at) const {
  const auto& x = s_.expectations[index];
  ExpectationResult res{x.line, x.describe(), false, at, {}, x.needsRecovery};
  if (x.kind == ExpectKind::kExitStatus) {
    if (!exitStatus_) {
      res.observed = "no exit status (" + exitHow_ + ")";
      return res;
    }
    res.passed = compareValues(*exitStatus_, x.compare, x.value, x.tolerance);
    res.observed = fmt::format("exit status {}{}", *exitStatus_, exitHow_);
    return res;
  }
  const SimTime zero = zero_.load();
  if (x.afterTime && zero == kNoTime) {
    res.observed = "the network never had all slaves in OP: no time zero to count afterMs from";
    return res;
  }
  const OutputTally& tally = output_->tallies()[index];
  const std::size_t found = tally.found;
  const std::optional<StampedLine>& first = tally.first;
  if (x.countLines) {
    res.passed = compareValues(static_cast<double>(found), x.compare, x.value, x.tolerance);
  } else {
    res.passed = found > 0;
  }
  const std::string window = x.afterTime ? fmt::format(" seen from {} to {}", ms(*x.afterTime),
                                                       ms(*x.afterTime + x.within))
                                         : std::string();
  if (!first) {
    res.observed =
        fmt::format("not found in the {} lines of output{}", output_->lineCount(), window);
  } else {
    const SimTime origin = zero == kNoTime ? commandStart_ : zero;
    res.observed = fmt::format("{} of {} lines{}, the first at {}: '{}'", found,
                               output_->lineCount(), window, ms(first->at - origin), first->text);
  }
  return res;
}

void ExternalRun::finish(SimTime end, const std::string& endText) {
  const SimTime zero = zero_.load();
  const SimTime origin = zero == kNoTime ? (log_.empty() ? end : log_.front().at) : zero;
  const SimTime since = end - origin;
  r_.cycles = zeroSeen_ ? lrwFrames_ - lrwAtZero_ : 0;
  r_.results = timedResults_;
  if (zero == kNoTime) {
    log(end, "the network never had all slaves in OP: no time zero, no timeline");
  }
  for (std::size_t i = 0; i < s_.actions.size(); ++i) {
    if (!applied_[i] && zero != kNoTime) {
      log(end, fmt::format("not applied, the run had ended: {} (line {})",
                           s_.actions[i].action.text(), s_.actions[i].line));
    }
  }
  for (std::size_t i = 0; i < s_.expectations.size(); ++i) {
    const auto& x = s_.expectations[i];
    if (x.kind == ExpectKind::kBackInOp) {
      if (zero == kNoTime) {
        r_.results.push_back({x.line, x.describe(), false, since,
                              "the network never had all slaves in OP", x.needsRecovery});
      } else {
        r_.results.push_back(evaluateBackInOp(i, end));
      }
    } else if (x.kind == ExpectKind::kExitStatus || x.kind == ExpectKind::kOutput) {
      r_.results.push_back(evaluateCommand(i, since));
    } else if (!checked_[i]) {
      if (!x.atCycle && !x.atTime) {
        r_.results.push_back(evaluatePoint(x, since));
      } else {
        r_.results.push_back(
            {x.line, x.describe(), false, since,
             zero == kNoTime ? "not reached: the network never had all slaves in OP"
                             : "not reached: the run ended at " + ms(since) + " (" + endText + ")",
             x.needsRecovery});
      }
    }
  }
  std::stable_sort(r_.results.begin(), r_.results.end(),
                   [](const auto& a, const auto& b) { return a.line < b.line; });
  log_.insert(log_.end(), serverLog_.begin(), serverLog_.end());
  std::stable_sort(log_.begin(), log_.end(),
                   [](const auto& a, const auto& b) { return a.at < b.at; });
  for (const auto& entry : log_) {
    r_.log.push_back(fmt::format("{:>12}  {}", ms(entry.at - origin), entry.text));
  }
}

ScenarioResult ExternalRun::execute() {
  r_ = startResult(s_, o_);
  if (s_.masterKind != "external") {
    r_.error = "not an external master (Master kind=\"" + s_.masterKind + "\")";
    return r_;
  }
  auto network = buildScenarioNetwork(s_);
  if (!network.ok()) {
    r_.error = network.error().message();
    return r_;
  }
  network_ = std::move(*network);
  // From here on SIGINT/SIGTERM end the run in order: the command stopped, the namespace
  // removed, the report saying so.
  SignalFlag signals;
  auto ns = VethNamespace::create();
  if (!ns.ok()) {
    r_.error = "cannot make the veth pair for the external master: " + ns.error().message();
    return r_;
  }
  Environment environment = e_.environment;
  if (!environment) {
    environment = [](const std::string& name) -> std::optional<std::string> {
      const char* v = std::getenv(name.c_str());
      return v == nullptr ? std::nullopt : std::optional<std::string>(v);
    };
  }
  auto command = expandCommand(s_, ns->masterInterface(), environment);
  if (!command.ok()) {
    r_.error = command.error().message();
    return r_;
  }
  auto raw = RawSocketLink::open(ns->simulatorInterface(), RawSocketOptions{ns->name(), true});
  if (!raw.ok()) {
    r_.error = raw.error().message();
    return r_;
  }
  CountingLink link(*raw, lrwFrames_);
  topology::Segment& segment = *network_.segment;
  faults_.emplace(network_, r_.seed);
  std::optional<PcapWriter> writer;
  std::optional<topology::PcapCableTap> tap;
  if (!o_.pcapDir.empty()) {
    auto w = PcapWriter::open((o_.pcapDir / (s_.name + ".pcap")).string());
    if (!w.ok()) {
      r_.error = w.error().message();
      return r_;
    }
    writer.emplace(std::move(*w));
    // Live capture: stamped with the Unix time, as `ecsim serve --pcap`.
    tap.emplace(*writer, WallClock().now() - clock_.now());
    segment.setCableObserver(0, 0, &*tap);
  }
  struct Detach {  // the capture ends before the writer does, on every return
    topology::Segment& segment;
    ~Detach() { segment.setCableObserver(0, 0, nullptr); }
  } detach{segment};
  applied_.assign(s_.actions.size(), false);
  checked_.assign(s_.expectations.size(), false);
  afterAt_.assign(s_.expectations.size(), std::nullopt);
  backAt_.assign(s_.expectations.size(), std::nullopt);

  topology::ServerOptions serverOptions;
  serverOptions.paced = true;
  serverOptions.idleWait = kIdleWait;
  topology::NetworkServer server(link, segment, clock_, serverOptions);
  std::thread thread([this, &server] { serve(server); });
  struct Join {  // the simulator's thread ends before anything it uses, on every return
    std::atomic<bool>& stop;
    std::thread& thread;
    ~Join() {
      stop = true;
      if (thread.joinable()) thread.join();
    }
  } join{stop_, thread};
  // The command starts once the simulator's thread serves. A count of 1 ms sleeps was no
  // bound in time (each sleep lasts longer on a busy machine) and gave up silently; the
  // deadline is generous (the thread only has to start) and only guards against a hang.
  const auto servingDeadline = std::chrono::steady_clock::now() + kServingTimeout;
  while (!serving_ && !serverEnded_ && std::chrono::steady_clock::now() < servingDeadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }

  std::filesystem::path outputFile;
  const bool keepOutput = !e_.outputDir.empty();
  if (keepOutput) {
    outputFile = e_.outputDir / (s_.name + ".output.txt");
  } else {
    outputFile = std::filesystem::temp_directory_path() /
                 fmt::format("ecsim-{}-{}.output.txt", s_.name, ::getpid());
  }
  std::error_code ignored;
  std::filesystem::remove(outputFile, ignored);  // no line of an earlier run is read
  auto output = CommandOutput::open(outputFile, s_.expectations, e_.tailLines);
  if (!output.ok()) {
    r_.error = fmt::format("{}: {}", s_.file.string(), output.error().message());
    return r_;
  }
  output_.emplace(std::move(*output));
  const SimTime start = clock_.now();
  commandStart_ = start;
  if (s_.timeFromStart) zero_ = start;
  auto child = ns->spawn({"/bin/sh", "-c", *command},
                         SpawnOptions{outputFile.string(), outputFile.string()});
  if (!child.ok()) {
    r_.error = fmt::format("{}, line {}: cannot start the command: {}", s_.file.string(),
                           s_.masterLine, child.error().message());
    return r_;
  }
  log(start, "command started: " + s_.masterCommand);
  bool interrupted = false;
  std::string endText;
  for (;;) {
    if (signals.raised()) {
      interrupted = true;
      break;
    }
    if (serverEnded_) {
      endText = "the simulator stopped";
      break;
    }
    if (auto code = child->wait(std::chrono::nanoseconds(0)); code.ok()) {
      exitStatus_ = *code;
      endText = fmt::format("the command exited with status {}", *code);
      break;
    }
    const SimTime now = clock_.now();
    const SimTime zero = zero_.load();
    if (zero != kNoTime && now >= zero + s_.duration) {
      endText = "the scenario's duration passed";
      break;
    }
    if (zero == kNoTime && now >= start + s_.startTimeout) {
      endText = fmt::format("not all slaves in OP within startTimeoutMs {}",
                            number(static_cast<double>(s_.startTimeout) / kNsPerMs));
      break;
    }
    output_->poll(now, zero_.load());
    std::this_thread::sleep_for(kPollInterval);
  }
  if (!exitStatus_) {
    const SimTime stopping = clock_.now();
    auto code = child->stop(std::chrono::nanoseconds(s_.stopGrace));
    if (code.ok()) exitStatus_ = *code;
    exitHow_ = code.ok() && *code == 128 + SIGKILL ? " (killed with SIGKILL after SIGTERM)"
                                                   : " (stopped with SIGTERM)";
    log(stopping, (interrupted ? std::string("interrupted by a signal") : endText) +
                      ": command stopped" + exitHow_);
    if (!interrupted) endText += ", the command was stopped";
  } else {
    log(clock_.now(), endText);
  }
  const SimTime end = clock_.now();
  stop_ = true;
  thread.join();
  if (writer) (void)writer->close();

  output_->finish(end, zero_.load());
  if (!keepOutput) std::filesystem::remove(outputFile, ignored);

  if (!schedulingNote_.empty()) log(start, "note: " + schedulingNote_);
  finish(end, endText);
  const auto& tail = output_->tail();
  r_.log.push_back(fmt::format("  output: last {} of {} lines{}", tail.size(),
                               output_->lineCount(),
                               keepOutput ? ", all in " + outputFile.string() : ""));
  if (output_->cutLines() > 0) {
    r_.log.push_back(fmt::format("  output: {} lines longer than {} bytes, judged in pieces of "
                                 "that size",
                                 output_->cutLines(), kMaxOutputLine));
  }
  constexpr std::size_t kShownLine = 1000;  // bytes of a tail line in the report
  for (const auto& line : tail) {
    r_.log.push_back("    | " + (line.size() <= kShownLine
                                     ? line
                                     : line.substr(0, kShownLine) +
                                           fmt::format("... ({} bytes)", line.size())));
  }
  if (interrupted) {
    r_.error = fmt::format("interrupted by signal {} ({}): the command was stopped",
                           signals.signal(), strsignal(signals.signal()));
  } else if (!serverError_.empty()) {
    r_.error = serverError_;
  }
  return r_;
}

}  // namespace

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

ScenarioResult runExternalScenario(const Scenario& scenario, const RunOptions& options,
                                   const ExternalRunOptions& external) {
  ExternalRun run(scenario, options, external);
  return run.execute();
}

ScenarioResult runAnyScenario(const Scenario& scenario, const RunOptions& options,
                              const ExternalRunOptions& external) {
  if (scenario.masterKind == "external") return runExternalScenario(scenario, options, external);
  return runScenario(scenario, options);
}

}  // namespace ecsim::scenario
