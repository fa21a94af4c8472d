// A GoogleTest fixture that starts a simulated network for a test and tears it down after.
// Header-only; link ecsim::testing (or ecsim::sim and ecsim::master) and GTest.
//
//   class MyTest : public ecsim::testing::NetworkFixture {};
//   TEST_F(MyTest, ReachesOp) {
//     ASSERT_TRUE(startInProcess("demo.xml").ok());   // MemoryLink, virtual time, our master
//     ASSERT_TRUE(master().start().ok());
//     EXPECT_EQ(network().slave("DO1")->state(), ecsim::AlState::kOp);
//     auto status = master().variable("Drive1.Statusword");   // named as the topology names
//   }
//
// In process: the network and (optionally) ecsim's master meet over a MemoryLink, the master's
// VirtualBus steps the network on virtual time; deterministic and needs no privileges.
// On veth: a private network namespace with a fresh veth pair (link/netns.hpp), the simulator
// serving the simulator end from a thread on real time; the test points its own master at
// vethNamespace().masterInterface() inside vethNamespace().name() (or uses ours with
// withMaster). Needs CAP_NET_ADMIN, CAP_NET_RAW and CAP_SYS_ADMIN: without them startOnVeth()
// returns kPermission and ECSIM_FIXTURE_SKIP_WITHOUT_NETWORK() skips (fails under CI=true).
// While the server thread runs, hold network().lock() around slave access.
#pragma once

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "embed/simulated_network.hpp"
#include "link/memory_link.hpp"
#include "link/netns.hpp"
#include "link/raw_socket_link.hpp"
#include "master/bus.hpp"
#include "master/master.hpp"
#include "protocol/result.hpp"
#include "topology/slave_names.hpp"

namespace ecsim::testing {

struct FixtureOptions {
  bool withMaster{true};           // also make ecsim's master, reachable through master()
  master::MasterOptions master{};  // its options
  std::size_t linkCapacity{256};   // in process: frames in flight per direction
  bool paced{false};               // on veth: answer at the modelled round trip
};

class NetworkFixture : public ::testing::Test {
 protected:
  ~NetworkFixture() override { stopNetwork(); }
  void TearDown() override { stopNetwork(); }

  // The network from a topology file, in this process on virtual time.
  Status startInProcess(const std::filesystem::path& topology, FixtureOptions options = {}) {
    stopNetwork();
    ECSIM_ASSIGN_OR_RETURN(network_, embed::SimulatedNetwork::fromTopologyFile(topology));
    auto [masterEnd, networkEnd] = MemoryLink::makePair(options.linkCapacity);
    masterLink_ = std::make_unique<MemoryLink>(std::move(masterEnd));
    networkLink_ = std::make_unique<MemoryLink>(std::move(networkEnd));
    network_->attach(*networkLink_);
    if (options.withMaster) {
      embed::SimulatedNetwork* net = network_.get();
      bus_ = std::make_unique<master::VirtualBus>(*network_->virtualClock(),
                                                  [net](SimTime) { return net->serveOne(); });
      master_ = std::make_unique<master::Master>(*masterLink_, *bus_, options.master);
      nameSlaves();
    }
    return okStatus();
  }

  // The network from a topology file on a fresh veth pair in a private namespace, served by a
  // thread on real time. kPermission when this process lacks the capabilities.
  Status startOnVeth(const std::filesystem::path& topology, FixtureOptions options = {}) {
    stopNetwork();
    ECSIM_TRY(checkNetworkCapabilities());
    embed::NetworkOptions netOptions;
    netOptions.time = embed::TimeMode::kRealTime;
    netOptions.paced = options.paced;
    ECSIM_ASSIGN_OR_RETURN(network_,
                           embed::SimulatedNetwork::fromTopologyFile(topology, netOptions));
    ECSIM_ASSIGN_OR_RETURN(auto ns, VethNamespace::create());
    veth_.emplace(std::move(ns));
    ECSIM_ASSIGN_OR_RETURN(auto simEnd, RawSocketLink::open(veth_->simulatorInterface(),
                                                            RawSocketOptions{veth_->name(), true}));
    networkLink_ = std::make_unique<RawSocketLink>(std::move(simEnd));
    network_->attach(*networkLink_);
    if (options.withMaster) {
      ECSIM_ASSIGN_OR_RETURN(
          auto masterEnd,
          RawSocketLink::open(veth_->masterInterface(), RawSocketOptions{veth_->name(), true}));
      masterLink_ = std::make_unique<RawSocketLink>(std::move(masterEnd));
      bus_ = std::make_unique<master::RealTimeBus>(*masterLink_, realClock_);
      master_ = std::make_unique<master::Master>(*masterLink_, *bus_, options.master);
      nameSlaves();
    }
    stop_ = false;
    server_ =
        std::thread([this] { serverStatus_ = network_->serve([this] { return stop_.load(); }); });
    return okStatus();
  }

  // Stops the server thread, the master and the network, and removes the veth pair.
  void stopNetwork() {
    stop_ = true;
    if (server_.joinable()) server_.join();
    master_.reset();
    bus_.reset();
    if (network_) network_->detach();
    masterLink_.reset();
    networkLink_.reset();
    network_.reset();
    veth_.reset();
  }

  embed::SimulatedNetwork& network() { return *network_; }
  bool hasMaster() const { return master_ != nullptr; }
  master::Master& master() { return *master_; }
  // On veth only: the namespace and the master's interface in it.
  const VethNamespace& vethNamespace() const { return *veth_; }
  // The outcome of the server thread once it has stopped.
  const Status& serverStatus() const { return serverStatus_; }

  // In process: virtual time passes, the network serves what is waiting meanwhile.
  Status advance(SimTime duration) { return network_->runFor(duration); }

  static bool ciMode() {
    const char* ci = std::getenv("CI");
    return ci != nullptr && std::string(ci) == "true";
  }

 private:
  // Our master names the slaves as the topology does (its variables are "Drive1.Statusword",
  // its events "slave 4 (0x1005 'Drive1') lost"), by bus position.
  void nameSlaves() { master_->setSlaveNames(topology::slaveNamesInBusOrder(network_->segment())); }

  std::unique_ptr<embed::SimulatedNetwork> network_;
  std::optional<VethNamespace> veth_;
  std::unique_ptr<Link> masterLink_;
  std::unique_ptr<Link> networkLink_;
  RealClock realClock_;
  std::unique_ptr<master::Bus> bus_;
  std::unique_ptr<master::Master> master_;
  std::thread server_;
  std::atomic<bool> stop_{false};
  Status serverStatus_;
};

}  // namespace ecsim::testing

// In a TEST_F body: skips when startOnVeth()'s status says a capability is missing (fails
// under CI=true); any other error fails the test.
#define ECSIM_FIXTURE_SKIP_WITHOUT_NETWORK(status)                                 \
  do {                                                                             \
    const ::ecsim::Status& ecsim_fixture_status_ = (status);                       \
    if (!ecsim_fixture_status_.ok()) {                                             \
      if (ecsim_fixture_status_.error().code == ::ecsim::ErrorCode::kPermission && \
          !::ecsim::testing::NetworkFixture::ciMode())                             \
        GTEST_SKIP() << ecsim_fixture_status_.error().message();                   \
      FAIL() << ecsim_fixture_status_.error().message();                           \
    }                                                                              \
  } while (false)
