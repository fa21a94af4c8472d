// Test steps shared by the master tests: scan the simulated bus and bring every slave to
// PREOP with its mailbox configured, using the master's own tasks.
#pragma once

#include <vector>

#include <gtest/gtest.h>

#include "config/esi.hpp"
#include "master/batch.hpp"
#include "master/esc_config.hpp"
#include "master/health.hpp"
#include "master/master.hpp"
#include "master/scan.hpp"
#include "master/state_change.hpp"
#include "slavesim/esi_slave.hpp"
#include "tests/master/sim_network.hpp"

namespace ecsim::testing {

// The first of `events` of `kind` about the slave at `position`, or null.
inline const master::MasterEvent* findEvent(const std::vector<master::MasterEvent>& events,
                                            master::MasterEventKind kind, std::size_t position) {
  for (const auto& e : events) {
    if (e.kind == kind && e.position == position) return &e;
  }
  return nullptr;
}

// The events' texts, one per line (for failure messages).
inline std::string eventLog(const std::vector<master::MasterEvent>& events) {
  std::string s;
  for (const auto& e : events) s += e.text + "\n";
  return s;
}

inline Status scanAndPreOp(SimNetwork& net, master::Transport& transport,
                           std::vector<master::SlaveInfo>& slaves) {
  master::ScanTask scan(transport, slaves);
  scan.start(net.clock().now());
  ECSIM_TRY(master::runTask(scan, transport, net.bus(), kNsPerSecond));
  ECSIM_TRY(scan.status());
  master::DatagramBatch mailboxes;
  for (const auto& s : slaves) master::addMailboxSetup(mailboxes, s);
  mailboxes.queueAll(transport);
  master::BatchWait wait(mailboxes);
  ECSIM_TRY(master::runTask(wait, transport, net.bus(), kNsPerSecond));
  ECSIM_TRY(mailboxes.check());
  master::StateChangeTask preop(transport, slaves);
  preop.start(AlState::kPreOp, net.clock().now());
  ECSIM_TRY(master::runTask(preop, transport, net.bus(), kNsPerSecond));
  return preop.status();
}

inline const EsiFile& demoEsi() {
  static const EsiFile file = [] {
    auto f = loadEsiFile(std::string(ECSIM_SOURCE_DIR) + "/examples/esi/ecsim_devices.xml");
    EXPECT_TRUE(f.ok()) << (f.ok() ? "" : f.error().message());
    return f.ok() ? std::move(f).value() : EsiFile{};
  }();
  return file;
}

// A slave of ecsim's demo ESI file (examples/esi/ecsim_devices.xml) by product code.
inline std::unique_ptr<slavesim::Slave> makeDemoSlave(std::uint32_t product,
                                                      const std::string& name) {
  const EsiFile& file = demoEsi();
  for (const auto& device : file.devices) {
    if (device.productCode != product) continue;
    auto slave = slavesim::makeSlaveFromEsi(file, device, name);
    EXPECT_TRUE(slave.ok()) << (slave.ok() ? "" : slave.error().message());
    if (slave.ok()) return std::move(slave).value();
  }
  ADD_FAILURE() << "no demo device with product code " << product;
  return nullptr;
}

// The demo network of examples/topologies/demo.xml in a line: Coupler, DI1, DO1, AI1, Drive1
// and, with `drives` 2, Drive2. Then wired; the caller starts the network. `Net` has
// segment() (SimNetwork and the tests' served or virtual networks).
// Runs `n` cycles of 1 ms (Master::cycle(), then the bus waits out the period); returns how
// many failed.
template <typename Net>
std::uint64_t runCycles(master::Master& m, Net& net, std::uint64_t n) {
  std::uint64_t failed = 0;
  for (std::uint64_t i = 0; i < n; ++i) {
    const SimTime next = net.clock().now() + kNsPerMs;
    if (!m.cycle().ok()) ++failed;
    while (net.clock().now() < next) net.bus().wait(next);
  }
  return failed;
}

template <typename Net>
void addDemoSlaves(Net& net, int drives = 2) {
  net.segment().addSlave(makeDemoSlave(0x1100, "Coupler"));
  net.segment().addSlave(makeDemoSlave(0x1008, "DI1"));
  net.segment().addSlave(makeDemoSlave(0x2008, "DO1"));
  net.segment().addSlave(makeDemoSlave(0x3102, "AI1"));
  for (int d = 1; d <= drives; ++d) {
    net.segment().addSlave(makeDemoSlave(0x7201, "Drive" + std::to_string(d)));
  }
  net.segment().wireLine();
}

}  // namespace ecsim::testing
