// A fixture for tests of device models configured from a topology file: a temporary folder of
// the test's own, a topology with one slave "Axis" of the examples ESI (attributes and body of
// the test's choosing) written into it, and the network built from that file.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "config/topology_file.hpp"
#include "tests/slavesim/drive_test_support.hpp"
#include "topology/network_builder.hpp"

namespace ecsim::testing {

class OneSlaveTopology : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("ecsim-one-slave-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // net.xml: one <Slave name="Axis"> of examples/esi with `product`, `attributes` on the
  // element and `body` inside it.
  std::filesystem::path writeTopology(const std::string& attributes, const std::string& body,
                                      std::uint32_t product) {
    const auto path = dir_ / "net.xml";
    std::ofstream(path) << "<Topology name=\"t\">\n"
                        << "  <Slave name=\"Axis\" esi=\"" << examplesEsiPath().string()
                        << "\" product=\"" << product << "\" " << attributes << ">\n"
                        << body << "  </Slave>\n</Topology>\n";
    return path;
  }
  Result<topology::Network> build(const std::filesystem::path& path) {
    auto config = loadTopologyFile(path);
    if (!config.ok()) return config.takeError();
    return topology::buildNetwork(*config);
  }

  std::filesystem::path dir_;
};

}  // namespace ecsim::testing
