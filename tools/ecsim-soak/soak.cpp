#include "tools/ecsim-soak/soak.hpp"

#include <fmt/core.h>
#include <sys/socket.h>

#include <algorithm>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

namespace ecsim::soak {
namespace {

using Clock = std::chrono::steady_clock;
// Malformed frames kept for comparison with an answer (one that came back unprocessed).
constexpr std::size_t kMalformedKept = 256;
// After the last frame: how long stray answers (late ones, answers to malformed frames) are
// still collected.
constexpr std::chrono::milliseconds kLinger{100};
// How often the server process is looked at.
constexpr std::chrono::seconds kWatchInterval{1};
// Longest single wait for an answer, so that the server is still watched while waiting.
constexpr std::chrono::milliseconds kLongestWait{50};

struct Slot {
  bool used{false};
  Clock::time_point sentAt{};
  SoakFrame frame{};
};

class Run {
 public:
  Run(RawSocketLink& link, const SoakOptions& options, std::FILE* log)
      : link_(link), options_(options), log_(log), slots_(options.window),
        kept_(kMalformedKept) {}

  SoakReport run() {
    if (options_.serverPid > 0) report_.rssStartKb = residentKb(options_.serverPid);
    if (setUp()) {
      fmt::print(log_, "ecsim-soak: {} slaves set up; sending {} frames\n", report_.slaves,
                 options_.frames);
      std::fflush(log_);
      soak();
    }
    if (options_.serverPid > 0) {
      report_.rssEndKb = residentKb(options_.serverPid);
      report_.serverDied = report_.serverDied || !processAlive(options_.serverPid);
    }
    return report_;
  }

 private:
  void error(const std::string& text) {
    if (shown_++ < options_.errorsShown) fmt::print(log_, "ecsim-soak: {}\n", text);
  }

  // One frame, its answer waited for (set-up): the answer's length, or nullopt on timeout.
  std::optional<std::size_t> exchange(const SoakFrame& f, std::chrono::milliseconds wait) {
    if (!link_.send(ConstBytes(f.bytes.data(), f.length)).ok()) return std::nullopt;
    const auto deadline = Clock::now() + wait;
    while (Clock::now() < deadline) {
      auto n = link_.receive(buffer_, std::min<Clock::duration>(deadline - Clock::now(),
                                                                 kLongestWait));
      std::uint8_t marker = 0;
      std::uint32_t sequence = 0;
      if (n.ok() && *n > 0 && answerIdentity(ConstBytes(buffer_.data(), *n), marker, sequence) &&
          marker == kValidMarker && sequence == f.sequence) {
        return *n;
      }
    }
    return std::nullopt;
  }

  bool setUpStep(const SoakFrame& f, const Network& net, const char* what) {
    auto n = exchange(f, options_.timeout);
    if (!n) {
      report_.setupError = fmt::format("{}: no answer within {} ms", what, options_.timeout.count());
      return false;
    }
    auto check = checkAnswer(f, ConstBytes(buffer_.data(), *n), net);
    if (check.wkcError || check.dataError) {
      report_.setupError = fmt::format("{}: {}", what, check.what);
      return false;
    }
    return true;
  }

  // Counts the slaves (BRD of the type register, probed until the server answers), gives
  // each position its station address and maps its FMMUs.
  bool setUp() {
    SoakFrame f;
    const auto giveUp = Clock::now() + options_.waitReady;
    std::optional<std::size_t> n;
    do {
      probe_.single(f, OpKind::kTypeRead, 0);
      n = exchange(f, std::min(options_.timeout, std::chrono::milliseconds(200)));
    } while (!n && Clock::now() < giveUp &&
             (options_.serverPid <= 0 || processAlive(options_.serverPid)));
    if (!n) n = exchange(f, options_.timeout);
    if (!n) {
      report_.setupError = "no answer to a BRD of the ESC type register: is `ecsim serve` running "
                           "on the other end of " + link_.interfaceName() + "?";
      return false;
    }
    auto frame = ConstEtherCatFrame::parse(ConstBytes(buffer_.data(), *n));
    const std::uint16_t slaves = frame.ok() ? (*frame->begin()).wkc() : 0;
    if (slaves == 0) {
      report_.setupError = "BRD of the ESC type register came back with WKC 0: no slave";
      return false;
    }
    if (options_.expectedSlaves != 0 && slaves != options_.expectedSlaves) {
      report_.setupError = fmt::format("BRD of the ESC type register counts {} slaves, expected {}",
                                       slaves, options_.expectedSlaves);
      return false;
    }
    net_ = Network{slaves, options_.escType};
    report_.slaves = slaves;
    if (!setUpStep(f, net_, "BRD of the ESC type register")) return false;
    for (std::uint16_t p = 0; p < slaves; ++p) {
      stationAddressFrame(f, p);
      if (!setUpStep(f, net_, "APWR of a station address")) return false;
      fmmuFrame(f, p);
      if (!setUpStep(f, net_, "FPWR of FMMU0 and FMMU1")) return false;
    }
    return true;
  }

  void soak() {
    FrameSource source(options_.seed, net_, options_.malformedPercent);
    const auto start = Clock::now();
    auto nextWatch = start + kWatchInterval;
    auto nextProgress = start + options_.progress;
    SoakFrame next;
    bool pending = false;
    while (!report_.serverDied) {
      const auto now = Clock::now();
      expire(now);
      if (now >= nextWatch && options_.serverPid > 0) {
        nextWatch = now + kWatchInterval;
        if (!processAlive(options_.serverPid)) {
          report_.serverDied = true;
          error("the server process has ended");
          break;
        }
      }
      if (options_.progress.count() > 0 && now >= nextProgress) {
        nextProgress = now + options_.progress;
        fmt::print(log_, "ecsim-soak: {:.0f} s: {} frames sent, {} answered, {} timeouts, {} errors\n",
                   std::chrono::duration<double>(now - start).count(), report_.sent,
                   report_.answered, report_.timeouts,
                   report_.wkcErrors + report_.dataErrors + report_.malformedAnswered);
        std::fflush(log_);
      }
      if (report_.sent < options_.frames) {
        if (!pending) {
          source.next(next);
          pending = true;
        }
        if (next.malformation != Malformation::kNone) {
          sendMalformed(next);
          pending = false;
          drain(std::chrono::milliseconds(0));
          continue;
        }
        Slot& slot = slots_[next.sequence % slots_.size()];
        if (!slot.used) {
          sendValid(slot, next);
          pending = false;
          drain(std::chrono::milliseconds(0));
          continue;
        }
      } else if (inFlight_ == 0) {
        break;
      }
      drain(std::chrono::duration_cast<std::chrono::milliseconds>(
          std::clamp<Clock::duration>(earliestDeadline() - Clock::now(), Clock::duration::zero(),
                                      kLongestWait)));
    }
    const auto lingerEnd = Clock::now() + kLinger;
    while (Clock::now() < lingerEnd) drain(kLinger);
    report_.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  }

  void sendValid(Slot& slot, const SoakFrame& f) {
    ++report_.sent;
    ++report_.validSent;
    slot.frame = f;
    if (!link_.send(ConstBytes(f.bytes.data(), f.length)).ok()) {
      ++report_.sendErrors;
      error(fmt::format("valid frame {} of {} bytes: send failed", f.sequence, f.length));
      return;
    }
    slot.used = true;
    slot.sentAt = Clock::now();
    ++inFlight_;
  }

  void sendMalformed(const SoakFrame& f) {
    ++report_.sent;
    ++report_.malformedSent[static_cast<std::size_t>(f.malformation)];
    kept_[f.sequence % kept_.size()] = f;
    // Straight to the socket: RawSocketLink refuses frames past 1514 bytes itself, and the
    // point of an oversized frame is that the server's side sees it.
    if (::send(link_.pollFd(), f.bytes.data(), f.length, 0) != static_cast<ssize_t>(f.length)) {
      ++report_.malformedRefused;
    }
  }

  Clock::time_point earliestDeadline() const {
    auto earliest = Clock::time_point::max();
    for (const Slot& s : slots_) {
      if (s.used) earliest = std::min(earliest, s.sentAt + options_.timeout);
    }
    return earliest;
  }

  void expire(Clock::time_point now) {
    if (inFlight_ == 0 || now < earliestDeadline()) return;
    for (Slot& s : slots_) {
      if (!s.used || now < s.sentAt + options_.timeout) continue;
      s.used = false;
      --inFlight_;
      ++report_.timeouts;
      error(fmt::format("valid frame {} ({} bytes, {} operations): no answer within {} ms",
                        s.frame.sequence, s.frame.length, s.frame.opCount,
                        options_.timeout.count()));
    }
  }

  void drain(std::chrono::milliseconds wait) {
    for (;;) {
      auto n = link_.receive(buffer_, wait);
      if (!n.ok()) {
        ++report_.foreignFrames;  // e.g. larger than any EtherCAT frame
        continue;
      }
      if (*n == 0) return;
      handle(ConstBytes(buffer_.data(), *n));
      wait = std::chrono::milliseconds(0);
    }
  }

  void handle(ConstBytes answer) {
    std::uint8_t marker = 0;
    std::uint32_t sequence = 0;
    if (!answerIdentity(answer, marker, sequence)) {
      ++report_.foreignFrames;
      return;
    }
    if (marker == kMalformedMarker) {
      handleMalformed(answer, sequence);
      return;
    }
    Slot& slot = slots_[sequence % slots_.size()];
    if (!slot.used || slot.frame.sequence != sequence) {
      ++report_.lateAnswers;
      return;
    }
    slot.used = false;
    --inFlight_;
    ++report_.answered;
    const CheckResult check = checkAnswer(slot.frame, answer, net_);
    if (check.wkcError) ++report_.wkcErrors;
    if (check.dataError) ++report_.dataErrors;
    if (check.wkcError || check.dataError) {
      error(fmt::format("valid frame {}: {}", sequence, check.what));
    }
  }

  // An answer to a malformed frame is an error, except a frame of another EtherCAT type that
  // came back unprocessed (an ESC forwards what it does not process).
  void handleMalformed(ConstBytes answer, std::uint32_t sequence) {
    const SoakFrame& sent = kept_[sequence % kept_.size()];
    bool unprocessed = sent.sequence == sequence && sent.length == answer.size() &&
                       sent.malformation == Malformation::kWrongType;
    for (std::size_t i = 0; unprocessed && i < answer.size(); ++i) {
      unprocessed = i == 6 || answer[i] == sent.bytes[i];
    }
    if (unprocessed) {
      ++report_.malformedForwarded;
      return;
    }
    ++report_.malformedAnswered;
    error(fmt::format("malformed frame {} ({}) was answered", sequence,
                      sent.sequence == sequence ? toString(sent.malformation) : "kind unknown"));
  }

  RawSocketLink& link_;
  const SoakOptions& options_;
  std::FILE* log_;
  std::vector<Slot> slots_;
  std::vector<SoakFrame> kept_;
  std::array<std::uint8_t, kMaxSoakFrame> buffer_{};
  FrameSource probe_{0, Network{1, 0}, 0};
  Network net_{};
  std::size_t inFlight_{0};
  unsigned shown_{0};
  SoakReport report_;
};

}  // namespace

std::uint64_t SoakReport::malformedTotal() const {
  std::uint64_t total = 0;
  for (auto n : malformedSent) total += n;
  return total;
}

bool SoakReport::failed() const {
  return !setupError.empty() || serverDied || timeouts != 0 || wkcErrors != 0 ||
         dataErrors != 0 || sendErrors != 0 || malformedAnswered != 0 || answered != validSent;
}

long residentKb(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  }
  return -1;
}

bool processAlive(pid_t pid) {
  // /proc/PID/stat: "pid (comm) S ...": the state follows the last ')'.
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string stat;
  if (!std::getline(in, stat)) return false;
  const auto close = stat.rfind(')');
  if (close == std::string::npos || close + 2 >= stat.size()) return false;
  const char state = stat[close + 2];
  return state != 'Z' && state != 'X';
}

SoakReport runSoak(RawSocketLink& link, const SoakOptions& options, std::FILE* log) {
  return Run(link, options, log).run();
}

void printReport(const SoakReport& r, const SoakOptions& o, std::FILE* out) {
  fmt::print(out, "seed               {}\n", o.seed);
  fmt::print(out, "slaves             {}\n", r.slaves);
  if (!r.setupError.empty()) fmt::print(out, "set-up error       {}\n", r.setupError);
  fmt::print(out, "frames sent        {}\n", r.sent);
  fmt::print(out, "valid sent         {}\n", r.validSent);
  fmt::print(out, "answered           {}\n", r.answered);
  fmt::print(out, "timeouts           {}\n", r.timeouts);
  fmt::print(out, "wkc errors         {}\n", r.wkcErrors);
  fmt::print(out, "data errors        {}\n", r.dataErrors);
  fmt::print(out, "send errors        {}\n", r.sendErrors);
  fmt::print(out, "late answers       {}\n", r.lateAnswers);
  fmt::print(out, "foreign frames     {}\n", r.foreignFrames);
  fmt::print(out, "malformed sent     {}\n", r.malformedTotal());
  for (std::size_t k = 1; k < kMalformations; ++k) {
    fmt::print(out, "  {:<19} {}\n", toString(static_cast<Malformation>(k)), r.malformedSent[k]);
  }
  fmt::print(out, "malformed refused  {} (by the kernel: longer than the MTU)\n",
             r.malformedRefused);
  fmt::print(out, "malformed answered {}\n", r.malformedAnswered);
  fmt::print(out, "malformed returned {} (unprocessed, EtherCAT type not 1)\n",
             r.malformedForwarded);
  fmt::print(out, "seconds            {:.2f}\n", r.seconds);
  fmt::print(out, "frames/s           {:.0f}\n", r.seconds > 0 ? static_cast<double>(r.sent) / r.seconds : 0.0);
  if (o.serverPid > 0) {
    fmt::print(out, "server rss kB      {} at start, {} at end\n", r.rssStartKb, r.rssEndKb);
    fmt::print(out, "server             {}\n", r.serverDied ? "ENDED" : "running");
  }
  fmt::print(out, "result             {}\n", r.failed() ? "FAIL" : "PASS");
}

}  // namespace ecsim::soak
