// The embedding API: a simulated EtherCAT network inside a user's own program or test.
//
//   auto net = embed::SimulatedNetwork::fromTopologyFile("demo.xml");   // Result<...>
//   (*net)->attach(link);               // frames from a master arrive on this Link
//   (*net)->runFor(10 * kNsPerMs);      // virtual time: serve frames, run the firmware
//   auto di = (*net)->slave("DI1");     // by name (or position)
//   di->write<bool>(0x6000, 1, true);   // an input entry, as the slave's application sets it
//   auto out = (*net)->slave("DO1")->read<bool>(0x7000, 1);   // what the master wrote
//
// Time runs either virtually (the default: nothing happens between calls, runFor() advances
// a clock of our own, results are deterministic) or on the real monotonic clock (serve() and
// runFor() wait for frames, optionally answering each at its modelled round-trip time).
//
// Slave access is from the PDI side, as the slave's own firmware sees it: registers, the
// object dictionary (every entry, whatever its SDO access rights; no master needed) and the
// SyncManager buffers of the process data. When serve() runs in another thread, hold lock()
// around every access.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string_view>
#include <vector>

#include "config/topology_file.hpp"
#include "link/link.hpp"
#include "protocol/al_status.hpp"
#include "protocol/result.hpp"
#include "protocol/time.hpp"
#include "slavesim/coe/object_dictionary.hpp"
#include "slavesim/slave.hpp"
#include "topology/network_builder.hpp"
#include "topology/network_server.hpp"

namespace ecsim::embed {

enum class TimeMode : std::uint8_t {
  kVirtual,   // a clock of our own, advanced only by runFor()/advance()
  kRealTime,  // the monotonic clock; runFor() and serve() wait for frames
};

struct NetworkOptions {
  TimeMode time{TimeMode::kVirtual};
  // Virtual time: the slaves' firmware runs at least this often inside runFor().
  SimTime firmwareTick{100 * kNsPerUs};
  // Real time: answer each frame at its modelled return time (busy-waits microseconds).
  bool paced{false};
  // Real time: how long one server step waits for a frame before running the firmware.
  SimTime idleWait{kNsPerMs};
};

class SimulatedNetwork;

// One slave of a SimulatedNetwork, seen from its PDI side. A small handle: copy it freely
// while the network lives.
class SimulatedSlave {
 public:
  SimulatedSlave(slavesim::Slave& slave, std::size_t position)
      : slave_(&slave), position_(position) {}

  const std::string& name() const { return slave_->name(); }
  std::size_t position() const { return position_; }
  AlState state() const { return slave_->state(); }
  std::uint16_t alStatusCode() const;

  // ---- registers (PDI side: any address of the ESC's memory) --------------------------------
  Result<std::vector<std::uint8_t>> readRegisters(std::uint16_t address, std::size_t length) const;
  Status writeRegisters(std::uint16_t address, ConstBytes data);
  Result<std::uint16_t> readRegister16(std::uint16_t address) const;
  Result<std::uint32_t> readRegister32(std::uint16_t address) const;

  // ---- object dictionary (inputs, outputs, parameters) --------------------------------------
  // kNotFound when the slave has no dictionary or no such entry. Inputs written here reach
  // the master with the next process-data copy (SAFEOP/OP); outputs read here are the values
  // the master last wrote.
  bool hasDictionary() const { return dictionary() != nullptr; }
  Result<std::vector<std::uint8_t>> readEntry(std::uint16_t index, std::uint8_t subindex) const;
  Status writeEntry(std::uint16_t index, std::uint8_t subindex, ConstBytes data);
  template <typename T>
  Result<T> read(std::uint16_t index, std::uint8_t subindex) const {
    const auto* od = dictionary();
    if (od == nullptr) return noDictionary();
    return od->get<T>(index, subindex);
  }
  template <typename T>
  Status write(std::uint16_t index, std::uint8_t subindex, T value) {
    auto* od = dictionary();
    if (od == nullptr) return noDictionary();
    return od->set<T>(index, subindex, value);
  }

  // ---- process data as SyncManager buffers --------------------------------------------------
  // The newest complete buffer the master wrote into output SM `sm` (kNotFound: none yet or
  // not a buffered SM).
  Result<std::vector<std::uint8_t>> outputBuffer(unsigned sm) const;
  // Writes a complete input buffer into SM `sm` (its full length), as the firmware would.
  Status writeInputBuffer(unsigned sm, ConstBytes data);

  // Everything else: the simulated slave itself.
  slavesim::Slave& simulated() { return *slave_; }
  slavesim::coe::ObjectDictionary* dictionary() const;

 private:
  Error noDictionary() const;
  slavesim::Slave* slave_;
  std::size_t position_;
};

class SimulatedNetwork {
 public:
  static Result<std::unique_ptr<SimulatedNetwork>> fromTopologyFile(
      const std::filesystem::path& path, NetworkOptions options = {});
  static Result<std::unique_ptr<SimulatedNetwork>> fromTopology(const TopologyConfig& config,
                                                                NetworkOptions options = {});
  // Takes over an already built network (e.g. a Segment wired in code).
  static std::unique_ptr<SimulatedNetwork> fromNetwork(topology::Network network,
                                                       NetworkOptions options = {});

  SimulatedNetwork(const SimulatedNetwork&) = delete;
  SimulatedNetwork& operator=(const SimulatedNetwork&) = delete;

  // Frames from a master arrive on `link` (MemoryLink, RawSocketLink, TapLink, ...), which
  // must outlive the attachment. Replaces a previous attachment.
  void attach(Link& link);
  void detach();
  bool attached() const { return server_ != nullptr; }

  // ---- time ---------------------------------------------------------------------------------
  const NetworkOptions& options() const { return options_; }
  const Clock& clock() const;
  SimTime now() const { return clock().now(); }
  // The virtual clock (kVirtual only; a master's VirtualBus runs on it). nullptr otherwise.
  VirtualClock* virtualClock() {
    return options_.time == TimeMode::kVirtual ? &virtualClock_ : nullptr;
  }

  // One server step: at most one frame is taken from the link and answered, then the
  // firmware runs. Without a link, only the firmware runs.
  Status step();
  // For a master's VirtualBus: serves one waiting frame and returns its modelled round trip,
  // or nullopt when none was waiting.
  std::optional<SimTime> serveOne();
  // Virtual: serves every waiting frame and runs the firmware each firmware tick until the
  // clock has advanced by `duration`. Real time: serves frames for `duration` of real time.
  Status runFor(SimTime duration);
  // Real time (or virtual, without advancing): steps until stop() returns true, taking the
  // lock around each step so that another thread may look at the slaves in between.
  Status serve(const std::function<bool()>& stop);
  // Held by the caller while serve() runs in another thread.
  std::unique_lock<std::mutex> lock() { return std::unique_lock<std::mutex>(mutex_); }

  // ---- slaves -------------------------------------------------------------------------------
  std::size_t slaveCount() const { return network_.segment->size(); }
  std::optional<std::size_t> findSlave(std::string_view name) const;
  // kNotFound naming the slave asked for.
  Result<SimulatedSlave> slave(std::string_view name);
  Result<SimulatedSlave> slave(std::size_t position);

  topology::Segment& segment() { return *network_.segment; }
  topology::Network& network() { return network_; }
  // Frames served since attach() (all zero without a link).
  topology::ServerCounters serverCounters() const;

 private:
  SimulatedNetwork(topology::Network network, NetworkOptions options);
  Status stepLocked();

  topology::Network network_;
  NetworkOptions options_;
  VirtualClock virtualClock_;
  RealClock realClock_;
  std::unique_ptr<topology::NetworkServer> server_;
  std::mutex mutex_;
};

}  // namespace ecsim::embed
