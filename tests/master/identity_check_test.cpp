// Identity checks as masters do them (issue #16 item 5): vendor ID and product code always,
// the revision where the configuration gives one, the serial number only when asked for
// (IgH: a slave configuration names vendor and product; TwinCAT: the serial number check is
// off unless enabled). So scan -> ENI of the bus (what `ecmaster xml` writes) -> a network
// served from that ENI (`ecsim serve ENI`, whose slaves get serial numbers of their own) ->
// a master configured with the ENI (`ecmaster --config`) round-trips.
#include <gtest/gtest.h>

#include <fstream>

#include "config/eni.hpp"
#include "config/topology_file.hpp"
#include "link/memory_link.hpp"
#include "master/eni_config.hpp"
#include "master/eni_export.hpp"
#include "master/master.hpp"
#include "support/readiness.hpp"
#include "topology/network_builder.hpp"
#include "topology/network_from_eni.hpp"
#include "topology/network_server.hpp"
#include "topology/slave_names.hpp"

namespace ecsim::testing {
namespace {

const std::filesystem::path kSource = ECSIM_SOURCE_DIR;

// ---- checkIdentities on its own ----------------------------------------------------------------

master::SlaveInfo slaveWith(std::uint32_t vendor, std::uint32_t product, std::uint32_t revision,
                            std::uint32_t serial) {
  master::SlaveInfo s;
  s.station = 0x1001;
  s.name = "ECS7201";
  s.siiContents.identity = {vendor, product, revision, serial};
  return s;
}

MasterConfig configOf(const std::string& slaveAttributes) {
  auto config = master::parseMasterConfig(
      "<EcsimMaster>\n  <Slave name=\"Drive1\" " + slaveAttributes + "/>\n</EcsimMaster>\n",
      "bus.xml");
  EXPECT_TRUE(config.ok()) << config.error().message();
  return config.ok() ? *config : MasterConfig{};
}

TEST(IdentityCheck, SerialMismatchIsAcceptedUnlessAskedFor) {
  const auto config = configOf(R"(vendor="#xE5C" product="#x7201" serial="1")");
  const std::vector<master::SlaveInfo> bus{slaveWith(0xE5C, 0x7201, 0x10000, 2)};
  EXPECT_TRUE(master::checkIdentities(config, bus).ok());
  auto strict = master::checkIdentities(config, bus, master::IdentityCheck{.serial = true});
  ASSERT_FALSE(strict.ok());
  EXPECT_EQ(strict.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(strict.error().context.find("serial 0x00000002 (expected 0x00000001)"),
            std::string::npos)
      << strict.error().context;
  // The same serial passes the strict check.
  const std::vector<master::SlaveInfo> same{slaveWith(0xE5C, 0x7201, 0x10000, 1)};
  EXPECT_TRUE(master::checkIdentities(config, same, {.serial = true}).ok());
}

TEST(IdentityCheck, VendorProductAndConfiguredRevisionAreAlwaysChecked) {
  const std::vector<master::SlaveInfo> bus{slaveWith(0xE5C, 0x7201, 0x10000, 7)};
  auto vendor = master::checkIdentities(configOf(R"(vendor="#x2" product="#x7201")"), bus);
  ASSERT_FALSE(vendor.ok());
  EXPECT_NE(vendor.error().context.find("vendor 0x00000E5C (expected 0x00000002)"),
            std::string::npos)
      << vendor.error().context;
  // The message names the slave by what it is (SII) and what it is configured as, file, line.
  EXPECT_NE(vendor.error().context.find("slave 0 (0x1001 'ECS7201') configured as 'Drive1', "
                                        "bus.xml line 2"),
            std::string::npos)
      << vendor.error().context;
  auto product = master::checkIdentities(configOf(R"(vendor="#xE5C" product="#x7202")"), bus);
  ASSERT_FALSE(product.ok());
  EXPECT_NE(product.error().context.find("product code 0x00007201 (expected 0x00007202)"),
            std::string::npos)
      << product.error().context;
  auto revision = master::checkIdentities(
      configOf(R"(vendor="#xE5C" product="#x7201" revision="#x20000")"), bus);
  ASSERT_FALSE(revision.ok());
  EXPECT_NE(revision.error().context.find("revision"), std::string::npos);
  // No revision configured: any revision is accepted.
  EXPECT_TRUE(master::checkIdentities(configOf(R"(vendor="#xE5C" product="#x7201")"), bus).ok());
}

// ---- the round trip, in process ----------------------------------------------------------------

// A network served in process on virtual time, and a master on it.
struct Served {
  explicit Served(topology::Network net, master::MasterOptions options = {})
      : network(std::move(net)),
        links(MemoryLink::makePair(256)),
        server(links.second, *network.segment, clock, serverOptions()),
        bus(clock,
            [this](SimTime) -> std::optional<SimTime> {
              const bool waiting = links.second.pending() > 0;
              const auto before = server.counters().framesAnswered;
              (void)server.step();
              if (waiting && server.counters().framesAnswered != before) {
                return server.counters().lastRoundTrip;
              }
              return std::nullopt;
            }),
        master(links.first, bus, options) {}
  static topology::ServerOptions serverOptions() {
    topology::ServerOptions o;
    o.idleWait = std::chrono::nanoseconds(0);
    return o;
  }

  topology::Network network;
  VirtualClock clock;
  std::pair<MemoryLink, MemoryLink> links;
  topology::NetworkServer server;
  master::VirtualBus bus;
  master::Master master;
};

class IdentityRoundTrip : public ::testing::Test {
 protected:
  void TearDown() override {
    if (!eniFile_.empty()) std::filesystem::remove(eniFile_);
  }

  // Scan of the demo topology, named as it names its slaves, written as ENI.
  void exportDemo() {
    auto config = loadTopologyFile(kSource / "examples/topologies/demo.xml");
    ASSERT_TRUE(config.ok()) << config.error().message();
    auto net = topology::buildNetwork(*config);
    ASSERT_TRUE(net.ok()) << net.error().message();
    Served scanned(std::move(net).value());
    scanned.master.setSlaveNames(topology::slaveNamesInBusOrder(*scanned.network.segment));
    ASSERT_TRUE(scanned.master.scan().ok());
    ASSERT_TRUE(scanned.master.bringTo(AlState::kPreOp).ok());
    ASSERT_TRUE(scanned.master.configureProcessData().ok());
    eni_ = master::eniFromMaster(scanned.master);
    eniFile_ = uniqueTempPath("identity_round_trip_eni.xml");
    std::ofstream(eniFile_) << formatEni(eni_);
  }

  // The network `ecsim serve ENI` serves.
  topology::Network servedFromEni() {
    auto net = topology::buildNetworkFromEni(eniFile_, {kSource / "examples/esi"});
    EXPECT_TRUE(net.ok()) << net.error().message();
    return net.ok() ? std::move(net).value() : topology::Network{};
  }

  EniConfig eni_;
  std::filesystem::path eniFile_;
};

TEST_F(IdentityRoundTrip, EniOfAScannedBusConfiguresTheBusServedFromIt) {
  ASSERT_NO_FATAL_FAILURE(exportDemo());
  Served served(servedFromEni());
  ASSERT_TRUE(served.network.segment);
  ASSERT_TRUE(served.master.loadConfig(eniFile_).ok());
  auto status = served.master.start();
  ASSERT_TRUE(status.ok()) << status.error().message();
  // The check had something to forgive: the served slaves' serial numbers are their own.
  std::size_t differing = 0;
  for (std::size_t i = 0; i < served.master.slaves().size(); ++i) {
    ASSERT_TRUE(eni_.slaves[i].serialNo.has_value());
    if (served.master.slaves()[i].identity().serial != *eni_.slaves[i].serialNo) ++differing;
  }
  EXPECT_GT(differing, 0u);
  // The ENI carried the topology's names through: variables and labels use them.
  auto statusword = served.master.variable("Drive1.Statusword");
  EXPECT_TRUE(statusword.ok()) << statusword.error().message();
  EXPECT_EQ(served.master.slaves()[4].label(), "slave 4 (0x1005 'Drive1')");
}

TEST_F(IdentityRoundTrip, WithTheSerialCheckTheServedBusIsRefused) {
  ASSERT_NO_FATAL_FAILURE(exportDemo());
  master::MasterOptions options;
  options.identity.serial = true;
  Served served(servedFromEni(), options);
  ASSERT_TRUE(served.network.segment);
  ASSERT_TRUE(served.master.loadConfig(eniFile_).ok());
  auto status = served.master.start();
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(status.error().context.find("identity mismatch"), std::string::npos)
      << status.error().context;
  EXPECT_NE(status.error().context.find("serial"), std::string::npos) << status.error().context;
}

}  // namespace
}  // namespace ecsim::testing
