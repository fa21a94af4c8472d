// Our master as the master under test (scenario/master_under_test.hpp): in-process on virtual
// time over a memory link, or over a veth pair on real time. Both run the same cycle: the
// cycle's start awaited (the network served meanwhile), the slaves' firmware run, one
// Master::cycle(), its result and events handed to the judge. They differ in the clock, the
// link and how time passes while the master waits (the Bus). A topology with cable redundancy
// (<Master redundant=>) gives our master its second port too, wired to the ring's far end.
#include <fmt/core.h>
#include <poll.h>

#include <algorithm>
#include <cstring>
#include <optional>

#include "link/memory_link.hpp"
#include "link/netns.hpp"
#include "link/raw_socket_link.hpp"
#include "link/signal_flag.hpp"
#include "master/bus.hpp"
#include "master/master.hpp"
#include "scenario/master_under_test.hpp"
#include "topology/network_builder.hpp"
#include "topology/network_server.hpp"
#include "topology/slave_names.hpp"

namespace ecsim::scenario {
namespace {

// How long one step of the simulator waits for a frame while our master waits over veth: the
// resolution of the cycle's start.
constexpr auto kPumpWait = std::chrono::microseconds(100);

class OurMaster : public MasterUnderTest {
 public:
  explicit OurMaster(RunContext& c) : c_(c), segment_(*c.network.segment) {}
  bool pausable() const override { return true; }
  std::optional<SimTime> zero() const override { return zero_; }
  std::optional<Tick> next() override;
  Exchange exchange(const Tick& tick, bool paused) override;
  RunEnd stop() override;
  std::uint64_t cycles() const override { return total_; }
  std::string error() const override { return error_; }

 protected:
  // Brings the master to OP over `link` (and `second`, its redundant port, if not null); time
  // zero is then.
  Status startMaster(Link& link, master::Bus& bus, Link* second);
  // Lets time pass until `t`, the network served meanwhile; false when interrupted.
  virtual bool waitUntil(SimTime t) = 0;
  // The master goes before the link and bus it uses: the subclasses' destructors call this.
  void releaseMaster() { master_.reset(); }

  RunContext& c_;
  topology::Segment& segment_;
  std::string error_;

 private:
  bool cleanCycle() const;
  void observeCycle(const Status& status, std::uint64_t cycle);

  std::unique_ptr<master::Master> master_;
  std::optional<SimTime> zero_;
  SimTime nextStart_{0};
  std::uint64_t cycle_{0};
  std::uint64_t total_{0};
  std::size_t emergenciesSeen_{0};
};

Status OurMaster::startMaster(Link& link, master::Bus& bus, Link* second) {
  const Scenario& s = c_.scenario;
  master::MasterOptions mo;
  mo.cycleTime = s.cycleTime;
  mo.recovery = c_.options.recovery;
  master_ = std::make_unique<master::Master>(link, bus, mo);
  master_->setRedundantLink(second);
  // Its events and messages name the slaves as the topology does ("slave 5 (0x1006 'Drive2')").
  master_->setSlaveNames(topology::slaveNamesInBusOrder(segment_));
  if (auto st = master_->start(); !st.ok()) {
    return makeError(st.error().code, "the master did not reach OP: " + st.error().message());
  }
  // <Variable name="..."> names exist now that the master has scanned.
  ECSIM_TRY(checkVariableNames(s, master_->variables()));
  master_->resetStatistics();  // the scenario's figures, from the moment all slaves are in OP
  zero_ = clock().now();
  nextStart_ = *zero_;
  total_ = static_cast<std::uint64_t>(s.duration / s.cycleTime);
  c_.judge.attach(master_.get(), &c_.faults);
  return okStatus();
}

std::optional<Tick> OurMaster::next() {
  if (cycle_ >= total_) return std::nullopt;
  const SimTime period = c_.scenario.cycleTime;
  Tick tick;
  if (clock().now() > nextStart_) {
    // A cycle took longer than its period (a frame waited for until it was given up): the
    // cycles in between had no process data.
    const auto late =
        static_cast<std::uint64_t>((clock().now() - nextStart_ + period - 1) / period);
    tick.skipped = std::min(late, total_ - cycle_);
    cycle_ += tick.skipped;
    nextStart_ += static_cast<SimTime>(late) * period;
    if (cycle_ >= total_) {
      tick.cycle = cycle_;
      tick.now = clock().now();
      tick.end = true;
      return tick;
    }
  }
  if (!waitUntil(nextStart_)) return std::nullopt;
  // The slaves' firmware runs on its own time, frames or not (an SM watchdog expires while no
  // frame reaches the slave, not when the next one does).
  segment_.pollSlaves(clock().now());
  tick.cycle = cycle_;
  tick.now = clock().now();
  return tick;
}

// Every slave in OP (simulator side) and the master exchanging with every one of them: none
// lost, recovering or failed in its health.
bool OurMaster::cleanCycle() const {
  if (!c_.judge.allOp() || master_->slaves().size() != segment_.size()) return false;
  const auto health = master_->health();
  return health.slaves.size() == segment_.size() && health.allOperational();
}

void OurMaster::observeCycle(const Status& st, std::uint64_t cycle) {
  const SimTime now = clock().now();
  const SimTime since = now - *zero_;
  const auto& last = master_->lastCycle();
  if (last.framesLost > 0) {
    c_.judge.observe(cycle, now, since, "frame-lost", {},
                     fmt::format("{} frame(s) lost", last.framesLost));
  }
  if (last.wkcErrors > 0 && last.firstMismatch) {
    std::set<std::string> names;
    for (auto p : last.firstMismatch->slaves) names.insert(c_.judge.slaveNameAtPosition(p));
    c_.judge.observe(cycle, now, since, "wkc-error", names,
                     last.firstMismatch->describe(master_->slaves()));
  }
  if (!st.ok() && last.framesLost == 0 && last.wkcErrors == 0) {
    c_.judge.observe(cycle, now, since,
                     st.error().code == ErrorCode::kTimeout ? "frame-lost" : "cycle-error", {},
                     st.error().message());
  }
  if (master_->emergencies().size() > emergenciesSeen_) {
    emergenciesSeen_ = master_->emergencies().size();
    c_.judge.observe(cycle, now, since, "emergency", {}, "emergency received");
  }
  c_.judge.takeEvents(cycle, now, since);
}

Exchange OurMaster::exchange(const Tick& tick, bool paused) {
  Exchange out;
  if (paused) {
    segment_.pollSlaves(clock().now());
    out.good = false;
  } else {
    auto st = master_->cycle();
    out.good = st.ok() && master_->lastCycle().ok();
    observeCycle(st, tick.cycle);
  }
  out.clean = *out.good && cleanCycle();
  ++cycle_;
  nextStart_ += c_.scenario.cycleTime;
  return out;
}

RunEnd OurMaster::stop() {
  RunEnd end;
  end.at = clock().now();
  end.zero = zero_;
  end.ranToEnd = error_.empty() && cycle_ >= total_;
  end.text = end.ranToEnd ? "the scenario's duration passed" : error_;
  return end;
}

// ---- in-process: virtual time, a memory link, the network served while the master waits --

class InProcessMaster final : public OurMaster {
 public:
  explicit InProcessMaster(RunContext& c) : OurMaster(c) {}
  ~InProcessMaster() override { releaseMaster(); }
  const Clock& clock() const override { return clock_; }
  bool virtualTime() const override { return true; }
  Status start() override {
    topology::ServerOptions options;
    options.idleWait = std::chrono::nanoseconds(0);
    server_.emplace(links_.second, segment_, clock_, options);
    if (segment_.redundant()) server_->setRedundantLink(&secondLinks_.second);
    bus_.emplace(clock_, [this](SimTime) -> std::optional<SimTime> {
      const bool waiting = links_.second.pending() > 0 || secondLinks_.second.pending() > 0;
      const auto before = server_->counters().framesAnswered;
      (void)server_->step();
      if (waiting && server_->counters().framesAnswered != before) {
        return server_->counters().lastRoundTrip;
      }
      return std::nullopt;
    });
    return startMaster(links_.first, *bus_, segment_.redundant() ? &secondLinks_.first : nullptr);
  }

 private:
  bool waitUntil(SimTime t) override {
    clock_.set(t);
    return true;
  }

  VirtualClock clock_{kNsPerSecond};
  std::pair<MemoryLink, MemoryLink> links_ = MemoryLink::makePair(256);        // master, network
  std::pair<MemoryLink, MemoryLink> secondLinks_ = MemoryLink::makePair(256);  // redundancy
  std::optional<topology::NetworkServer> server_;
  std::optional<master::VirtualBus> bus_;
};

// ---- veth: real time, raw sockets on a veth pair, the network served in this thread -----

bool readable(int fd) {
  pollfd p{fd, POLLIN, 0};
  return ::poll(&p, 1, 0) > 0;
}

// While our master waits for its frames or its next deadline, the simulator on the other end
// of the pair serves (one thread: no lock between the master, the network and the timeline).
class ServingBus final : public master::Bus {
 public:
  ServingBus(const Clock& clock, topology::NetworkServer& server, Link& masterLink,
             Link* secondLink)
      : clock_(clock), server_(server), masterLink_(masterLink), secondLink_(secondLink) {}
  SimTime now() const override { return clock_.now(); }
  void wait(SimTime deadline) override {
    while (!readable(masterLink_.pollFd()) &&
           (secondLink_ == nullptr || !readable(secondLink_->pollFd())) &&
           clock_.now() < deadline) {
      (void)server_.step();
    }
  }

 private:
  const Clock& clock_;
  topology::NetworkServer& server_;
  Link& masterLink_;
  Link* secondLink_;  // the master's redundant port, if any
};

class VethMaster final : public OurMaster {
 public:
  explicit VethMaster(RunContext& c) : OurMaster(c) {}
  ~VethMaster() override { releaseMaster(); }
  const Clock& clock() const override { return clock_; }
  bool virtualTime() const override { return false; }
  Status start() override {
    VethOptions veth;
    veth.secondPair = segment_.redundant();  // the master's second port and its peer
    auto ns = VethNamespace::create(veth);
    if (!ns.ok()) {
      return makeError(ns.error().code,
                       "cannot make the veth pair for our master: " + ns.error().message());
    }
    ns_.emplace(std::move(*ns));
    auto sim = RawSocketLink::open(ns_->simulatorInterface(), RawSocketOptions{ns_->name(), true});
    if (!sim.ok()) return sim.error();
    simulatorLink_.emplace(std::move(*sim));
    auto ours = RawSocketLink::open(ns_->masterInterface(), RawSocketOptions{ns_->name(), true});
    if (!ours.ok()) return ours.error();
    masterLink_.emplace(std::move(*ours));
    if (veth.secondPair) {
      const RawSocketOptions raw{ns_->name(), true};
      auto simSecond = RawSocketLink::open(ns_->secondSimulatorInterface(), raw);
      if (!simSecond.ok()) return simSecond.error();
      secondSimulatorLink_.emplace(std::move(*simSecond));
      auto oursSecond = RawSocketLink::open(ns_->secondMasterInterface(), raw);
      if (!oursSecond.ok()) return oursSecond.error();
      secondMasterLink_.emplace(std::move(*oursSecond));
    }
    topology::ServerOptions options;
    options.paced = true;
    options.idleWait = kPumpWait;
    server_.emplace(*simulatorLink_, segment_, clock_, options);
    Link* second = secondMasterLink_ ? &*secondMasterLink_ : nullptr;
    if (second != nullptr) server_->setRedundantLink(&*secondSimulatorLink_);
    bus_.emplace(clock_, *server_, *masterLink_, second);
    if (c_.options.external.realtime) {
      if (auto note = scheduling_.enable(); !note.empty())
        c_.log.add(clock_.now(), "note: " + note);
    }
    return startMaster(*masterLink_, *bus_, second);
  }

 private:
  bool waitUntil(SimTime t) override {
    while (clock_.now() < t) {
      if (c_.signals != nullptr && c_.signals->raised()) {
        error_ = fmt::format("interrupted by signal {} ({}): the run was stopped",
                             c_.signals->signal(), strsignal(c_.signals->signal()));
        return false;
      }
      (void)server_->step();
    }
    return true;
  }

  RealClock clock_;
  RealtimeScheduling scheduling_;
  std::optional<VethNamespace> ns_;
  std::optional<RawSocketLink> simulatorLink_;
  std::optional<RawSocketLink> masterLink_;
  std::optional<RawSocketLink> secondSimulatorLink_;  // cable redundancy
  std::optional<RawSocketLink> secondMasterLink_;
  std::optional<topology::NetworkServer> server_;
  std::optional<ServingBus> bus_;
};

}  // namespace

std::unique_ptr<MasterUnderTest> makeInProcessMaster(RunContext& context) {
  return std::make_unique<InProcessMaster>(context);
}

std::unique_ptr<MasterUnderTest> makeVethMaster(RunContext& context) {
  return std::make_unique<VethMaster>(context);
}

}  // namespace ecsim::scenario
