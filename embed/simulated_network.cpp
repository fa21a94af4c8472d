#include "embed/simulated_network.hpp"

#include <algorithm>
#include <chrono>
#include <string>
#include <thread>

#include "protocol/registers.hpp"
#include "slavesim/esi_slave.hpp"

namespace ecsim::embed {
namespace {

std::string slaveLabel(const slavesim::Slave& slave, std::size_t position) {
  return "slave " + std::to_string(position) + " '" + slave.name() + "'";
}

}  // namespace

// ---- SimulatedSlave --------------------------------------------------------------------------

std::uint16_t SimulatedSlave::alStatusCode() const {
  return slave_->esc().read(reg::kAlStatusCode);
}

Result<std::vector<std::uint8_t>> SimulatedSlave::readRegisters(std::uint16_t address,
                                                                std::size_t length) const {
  const slavesim::Esc& esc = slave_->esc();
  if (static_cast<std::size_t>(address) + length > esc.memorySize()) {
    return makeError(ErrorCode::kInvalidArgument,
                     slaveLabel(*slave_, position_) + ": registers " + std::to_string(address) +
                         "+" + std::to_string(length) + " run past the ESC memory (" +
                         std::to_string(esc.memorySize()) + " bytes)");
  }
  std::vector<std::uint8_t> out(length);
  for (std::size_t i = 0; i < length; ++i) {
    out[i] = esc.reg8(static_cast<std::uint16_t>(address + i));
  }
  return out;
}

Status SimulatedSlave::writeRegisters(std::uint16_t address, ConstBytes data) {
  slavesim::Esc& esc = slave_->esc();
  if (static_cast<std::size_t>(address) + data.size() > esc.memorySize()) {
    return makeError(ErrorCode::kInvalidArgument,
                     slaveLabel(*slave_, position_) + ": registers " + std::to_string(address) +
                         "+" + std::to_string(data.size()) + " run past the ESC memory (" +
                         std::to_string(esc.memorySize()) + " bytes)");
  }
  for (std::size_t i = 0; i < data.size(); ++i) {
    esc.pdiWrite8(static_cast<std::uint16_t>(address + i), data[i]);
  }
  return okStatus();
}

Result<std::uint16_t> SimulatedSlave::readRegister16(std::uint16_t address) const {
  ECSIM_ASSIGN_OR_RETURN(auto bytes, readRegisters(address, 2));
  return readLe16(bytes, 0);
}

Result<std::uint32_t> SimulatedSlave::readRegister32(std::uint16_t address) const {
  ECSIM_ASSIGN_OR_RETURN(auto bytes, readRegisters(address, 4));
  return readLe32(bytes, 0);
}

slavesim::coe::ObjectDictionary* SimulatedSlave::dictionary() const {
  return slavesim::objectDictionaryOf(*slave_);
}

Error SimulatedSlave::noDictionary() const {
  return makeError(ErrorCode::kNotFound,
                   slaveLabel(*slave_, position_) + " has no object dictionary");
}

Result<std::vector<std::uint8_t>> SimulatedSlave::readEntry(std::uint16_t index,
                                                            std::uint8_t subindex) const {
  const auto* od = dictionary();
  if (od == nullptr) return noDictionary();
  const auto* entry = od->findEntry(index, subindex);
  if (entry == nullptr) {
    return makeError(ErrorCode::kNotFound, slaveLabel(*slave_, position_) + ": no entry " +
                                               std::to_string(index) + ":" +
                                               std::to_string(subindex));
  }
  return entry->value;
}

Status SimulatedSlave::writeEntry(std::uint16_t index, std::uint8_t subindex, ConstBytes data) {
  auto* od = dictionary();
  if (od == nullptr) return noDictionary();
  return od->setBytes(index, subindex, data);
}

Result<std::vector<std::uint8_t>> SimulatedSlave::outputBuffer(unsigned sm) const {
  const slavesim::Esc& esc = slave_->esc();
  if (!esc.pdiOutputsReceived(sm)) {
    return makeError(ErrorCode::kNotFound, slaveLabel(*slave_, position_) + ": SM" +
                                               std::to_string(sm) +
                                               " holds no complete output buffer");
  }
  ConstBytes data = esc.pdiOutputs(sm);
  return std::vector<std::uint8_t>(data.begin(), data.end());
}

Status SimulatedSlave::writeInputBuffer(unsigned sm, ConstBytes data) {
  if (!slave_->esc().pdiWriteInputs(sm, data)) {
    return makeError(ErrorCode::kState, slaveLabel(*slave_, position_) + ": SM" +
                                            std::to_string(sm) +
                                            " is not an enabled input buffer of " +
                                            std::to_string(data.size()) + " bytes");
  }
  return okStatus();
}

// ---- SimulatedNetwork ------------------------------------------------------------------------

SimulatedNetwork::SimulatedNetwork(topology::Network network, NetworkOptions options)
    : network_(std::move(network)), options_(options) {}

Result<std::unique_ptr<SimulatedNetwork>> SimulatedNetwork::fromTopologyFile(
    const std::filesystem::path& path, NetworkOptions options) {
  ECSIM_ASSIGN_OR_RETURN(auto config, loadTopologyFile(path));
  return fromTopology(config, options);
}

Result<std::unique_ptr<SimulatedNetwork>> SimulatedNetwork::fromTopology(
    const TopologyConfig& config, NetworkOptions options) {
  ECSIM_ASSIGN_OR_RETURN(auto network, topology::buildNetwork(config));
  return fromNetwork(std::move(network), options);
}

std::unique_ptr<SimulatedNetwork> SimulatedNetwork::fromNetwork(topology::Network network,
                                                                NetworkOptions options) {
  if (!network.segment) network.segment = std::make_unique<topology::Segment>();
  return std::unique_ptr<SimulatedNetwork>(new SimulatedNetwork(std::move(network), options));
}

const Clock& SimulatedNetwork::clock() const {
  if (options_.time == TimeMode::kVirtual) return virtualClock_;
  return realClock_;
}

void SimulatedNetwork::attach(Link& link) {
  topology::ServerOptions server;
  if (options_.time == TimeMode::kVirtual) {
    // Virtual time never passes while a step waits: never wait, never pace.
    server.idleWait = std::chrono::nanoseconds(0);
  } else {
    server.idleWait = std::chrono::nanoseconds(options_.idleWait);
    server.paced = options_.paced;
  }
  server_ = std::make_unique<topology::NetworkServer>(link, *network_.segment, clock(), server);
}

void SimulatedNetwork::detach() {
  server_.reset();
}

Status SimulatedNetwork::stepLocked() {
  if (server_) return server_->step();
  network_.segment->pollSlaves(now());
  if (options_.time == TimeMode::kRealTime) {
    std::this_thread::sleep_for(std::chrono::nanoseconds(options_.idleWait));
  }
  return okStatus();
}

Status SimulatedNetwork::step() {
  return stepLocked();
}

std::optional<SimTime> SimulatedNetwork::serveOne() {
  if (!server_) {
    network_.segment->pollSlaves(now());
    return std::nullopt;
  }
  const auto before = server_->counters().framesAnswered;
  (void)server_->step();
  if (server_->counters().framesAnswered != before) return server_->counters().lastRoundTrip;
  return std::nullopt;
}

Status SimulatedNetwork::runFor(SimTime duration) {
  const SimTime end = now() + std::max<SimTime>(duration, 0);
  if (options_.time == TimeMode::kRealTime) {
    while (now() < end) ECSIM_TRY(stepLocked());
    return okStatus();
  }
  const SimTime tick = std::max<SimTime>(options_.firmwareTick, 1);
  for (;;) {
    // Every frame waiting now is answered at this instant.
    if (server_) {
      for (;;) {
        const auto& c = server_->counters();
        const auto seen = c.framesReceived + c.receiveErrors;
        ECSIM_TRY(server_->step());
        if (server_->counters().framesReceived + server_->counters().receiveErrors == seen) break;
      }
    } else {
      network_.segment->pollSlaves(now());
    }
    if (now() >= end) break;
    virtualClock_.set(std::min(now() + tick, end));
  }
  return okStatus();
}

Status SimulatedNetwork::serve(const std::function<bool()>& stop) {
  while (!stop()) {
    Status s = [&] {
      std::lock_guard<std::mutex> guard(mutex_);
      return stepLocked();
    }();
    if (!s.ok()) return s;
  }
  return okStatus();
}

std::optional<std::size_t> SimulatedNetwork::findSlave(std::string_view name) const {
  const topology::Segment& segment = *network_.segment;
  for (std::size_t i = 0; i < segment.size(); ++i) {
    if (segment.slave(i).name() == name) return i;
  }
  return std::nullopt;
}

Result<SimulatedSlave> SimulatedNetwork::slave(std::string_view name) {
  auto position = findSlave(name);
  if (!position) {
    return makeError(ErrorCode::kNotFound,
                     "the network has no slave named '" + std::string(name) + "'");
  }
  return SimulatedSlave(network_.segment->slave(*position), *position);
}

Result<SimulatedSlave> SimulatedNetwork::slave(std::size_t position) {
  if (position >= slaveCount()) {
    return makeError(ErrorCode::kNotFound, "the network has no slave at position " +
                                               std::to_string(position) + " (it has " +
                                               std::to_string(slaveCount()) + ")");
  }
  return SimulatedSlave(network_.segment->slave(position), position);
}

topology::ServerCounters SimulatedNetwork::serverCounters() const {
  return server_ ? server_->counters() : topology::ServerCounters{};
}

}  // namespace ecsim::embed
