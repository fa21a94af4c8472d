// Our master against a network built from a topology file, in-process on virtual time (the
// arrangement of `ecsim demo`): the master's side sees only frames on a MemoryLink; each wait
// of its VirtualBus serves one frame and runs the slaves' firmware. Plus a CiA 402 axis as a
// master application drives it through process data: the enable sequence and CSP targets.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <string>

#include "config/topology_file.hpp"
#include "link/memory_link.hpp"
#include "master/bus.hpp"
#include "master/master.hpp"
#include "slavesim/devices/cia402.hpp"
#include "topology/network_builder.hpp"
#include "topology/network_server.hpp"

namespace ecsim::testing {

class TopologyMaster {
 public:
  explicit TopologyMaster(const std::filesystem::path& topology)
      : links_(MemoryLink::makePair(256)), clock_(kNsPerSecond) {
    auto config = loadTopologyFile(topology);
    EXPECT_TRUE(config.ok()) << (config.ok() ? "" : config.error().message());
    if (!config.ok()) return;
    auto net = topology::buildNetwork(*config);
    EXPECT_TRUE(net.ok()) << (net.ok() ? "" : net.error().message());
    if (!net.ok()) return;
    network_ = std::move(net).value();
    topology::ServerOptions options;
    options.idleWait = std::chrono::nanoseconds(0);
    server_ = std::make_unique<topology::NetworkServer>(links_.second, *network_.segment, clock_,
                                                        options);
    bus_ = std::make_unique<master::VirtualBus>(clock_, [this](SimTime) -> std::optional<SimTime> {
      const bool waiting = links_.second.pending() > 0;
      const auto before = server_->counters().framesAnswered;
      (void)server_->step();
      if (waiting && server_->counters().framesAnswered != before) {
        return server_->counters().lastRoundTrip;
      }
      return std::nullopt;
    });
    master_ = std::make_unique<master::Master>(links_.first, *bus_);
  }

  bool ready() const { return master_ != nullptr; }
  master::Master& master() { return *master_; }
  topology::Segment& segment() { return *network_.segment; }
  VirtualClock& clock() { return clock_; }

  // One cyclic exchange, then the clock moves to the next period.
  Status cycle(SimTime period = kNsPerMs) {
    const SimTime start = clock_.now();
    Status s = master_->exchange();
    clock_.set(std::max(clock_.now(), start + period));
    return s;
  }

 private:
  std::pair<MemoryLink, MemoryLink> links_;
  VirtualClock clock_;
  topology::Network network_;
  std::unique_ptr<topology::NetworkServer> server_;
  std::unique_ptr<master::VirtualBus> bus_;
  std::unique_ptr<master::Master> master_;
};

// A CiA 402 drive at a bus position, through the default PDOs of the ECS7201/ECS7211.
class Cia402Axis {
 public:
  Cia402Axis(master::Master& m, std::size_t position)
      : controlword_(var(m, position, "0x6040:00")),
        target_(var(m, position, "0x607A:00")),
        mode_(var(m, position, "0x6060:00")),
        statusword_(var(m, position, "0x6041:00")),
        actual_(var(m, position, "0x6064:00")) {}

  bool ok() const { return controlword_ && target_ && mode_ && statusword_ && actual_; }
  std::uint16_t statusword() const { return statusword_->get<std::uint16_t>(); }
  std::int32_t actual() const { return actual_->get<std::int32_t>(); }
  void setTarget(std::int32_t t) { target_->set(t); }
  void setMode(std::int8_t m) { mode_->set(m); }
  bool operationEnabled() const {
    return (statusword() & slavesim::devices::cia402::sw::kStateMask) == 0x27;
  }
  bool fault() const { return (statusword() & slavesim::devices::cia402::sw::kFault) != 0; }

  // The controlword for the next cycle on the way to Operation enabled (CiA 402 sequence:
  // fault reset, shutdown, switch on, enable operation), with the target held at the actual
  // position so the drive does not jump when it is enabled.
  void stepEnable() {
    using slavesim::devices::cia402::State;
    const auto state = slavesim::devices::cia402::stateFromStatusword(statusword());
    std::uint16_t cw = 0x0006;
    if (state == State::kFault) cw = lastControlword_ == 0x0080 ? 0x0000 : 0x0080;
    if (state == State::kReadyToSwitchOn) cw = 0x0007;
    if (state == State::kSwitchedOn || state == State::kOperationEnabled) cw = 0x000F;
    if (state != State::kOperationEnabled) setTarget(actual());
    controlword_->set(cw);
    lastControlword_ = cw;
  }

 private:
  static std::optional<master::PdoVariable> var(master::Master& m, std::size_t position,
                                                const std::string& entry) {
    auto v = m.variable(std::to_string(position) + "." + entry);
    EXPECT_TRUE(v.ok()) << position << "." << entry << ": " << (v.ok() ? "" : v.error().message());
    if (!v.ok()) return std::nullopt;
    return std::move(v).value();
  }

  std::optional<master::PdoVariable> controlword_, target_, mode_, statusword_, actual_;
  std::uint16_t lastControlword_{0};
};

}  // namespace ecsim::testing
