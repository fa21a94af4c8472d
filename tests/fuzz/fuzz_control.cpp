// libFuzzer target for the control command line (`ecsim ctl`, scenario actions): arbitrary
// bytes as lines of text, each parsed (parseFaultAction, topology/faults.hpp) and applied by a
// FaultInjector to a small network: a coupler, digital inputs, an analog input terminal, an
// encoder terminal and a CiA 402 drive from the project's example ESI files, so that every
// verb finds a slave it applies to. Lines that name a file (a CSV signal) are skipped: the
// fuzzer reads no file. No frame is sent: what is exercised is the checking and the applying.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include "config/topology_file.hpp"
#include "topology/faults.hpp"
#include "topology/network_builder.hpp"

namespace {

using namespace ecsim;

std::vector<TopologySlave> exampleSlaves() {
  const std::filesystem::path esi = ECSIM_FUZZ_SOURCE_DIR "/examples/esi";
  struct Entry {
    const char* name;
    const char* file;
    std::uint32_t product;
  };
  const Entry entries[] = {{"Coupler", "ecsim_devices.xml", 0x1100},
                           {"DI1", "ecsim_devices.xml", 0x1008},
                           {"AI1", "ecsim_devices.xml", 0x3102},
                           {"Encoder1", "ecsim_encoders.xml", 0x5001},
                           {"Drive1", "ecsim_devices.xml", 0x7201}};
  std::vector<TopologySlave> slaves;
  for (const auto& e : entries) {
    TopologySlave s;
    s.name = e.name;
    s.esiFile = esi / e.file;
    s.productCode = e.product;
    slaves.push_back(s);
  }
  return slaves;
}

// The network is expensive to make (5 ms of CPU: a drive's dictionary, device models, ESC
// memories), so it is kept across inputs and made again after kRebuildAfter inputs that changed
// it (loss, corrupt and delay only change the FaultInjector, made per input; a failed action
// changes nothing). A finding that needs an earlier input's changes does not reproduce alone:
// FUZZ_CONTROL_FRESH=1 makes the network for every input, to replay a run's inputs in order.
constexpr int kRebuildAfter = 100;

topology::Network makeNetwork() {
  static topology::SlaveFactory factory;  // reads each ESI file once
  static const std::vector<TopologySlave> slaves = exampleSlaves();
  topology::Network net;
  net.segment = std::make_unique<topology::Segment>();
  for (const auto& entry : slaves) {
    auto slave = factory.make(entry);
    if (!slave.ok()) __builtin_trap();  // the example files are broken: nothing to fuzz
    net.segment->addSlave(std::move(slave).value());
  }
  net.segment->wireLine();
  net.cables.push_back({"master", 0, 0});
  for (std::size_t i = 1; i < slaves.size(); ++i) {
    net.cables.push_back({"ebus" + std::to_string(i), i, 0});
  }
  return net;
}

bool changesOnlyTheInjector(std::string_view verb) {
  return verb == "loss" || verb == "corrupt" || verb == "delay";
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool fresh = std::getenv("FUZZ_CONTROL_FRESH") != nullptr;
  static topology::Network net;
  static int changedInputs = kRebuildAfter;
  if (changedInputs >= kRebuildAfter || (fresh && changedInputs > 0)) {
    net = makeNetwork();
    changedInputs = 0;
  }
  bool changed = false;
  topology::FaultInjector faults(net, 1);
  std::string_view rest(reinterpret_cast<const char*>(data), size);
  SimTime now = 1'000'000;
  while (!rest.empty()) {
    const std::size_t end = rest.find('\n');
    const std::string_view line = rest.substr(0, end);
    rest = end == std::string_view::npos ? std::string_view() : rest.substr(end + 1);
    if (line.find("csv") != std::string_view::npos) continue;
    auto fault = topology::parseFaultLine(line);
    if (!fault.ok()) continue;
    if (faults.apply(*fault, now).ok() && !changesOnlyTheInjector(topology::verbOf(*fault))) {
      changed = true;
    }
    now += 1'000'000;
  }
  if (changed) ++changedInputs;
  return 0;
}
