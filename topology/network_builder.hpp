// Builds a simulated network (Segment) from a topology file's description: each slave from
// its ESI device or as a device of ours, ESC type and delays, clocks, wiring with cable
// lengths, initial inputs. Cable names are kept so captures and faults can address cables.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "config/esi.hpp"
#include "config/topology_file.hpp"
#include "protocol/result.hpp"
#include "topology/segment.hpp"

namespace ecsim::topology {

struct CableRef {
  std::string name;
  std::size_t slave{0};  // the downstream end: observers and faults attach here
  unsigned port{0};
};

// A hot-connect group (docs/topology.md): its slaves, attached and detached together.
struct HotConnectGroup {
  std::string name;
  std::vector<std::size_t> slaves;
};

struct Network {
  std::unique_ptr<Segment> segment;
  std::vector<CableRef> cables;  // "master" first (slave 0, port 0), then the file's links
  std::vector<HotConnectGroup> groups;
  // Values a tolerant reader ignored ("file, line N: ..."; e.g. an ENI's absurd cycle time),
  // for the tool to show.
  std::vector<std::string> warnings;
  const CableRef* findCable(std::string_view name) const;
};

// Makes the slaves topology entries describe: built-in devices, and devices from ESI files
// (slavesim/esi_slave.hpp), reading each ESI file once.
// Modular devices get their modules (config/esi_modules.hpp): the entry's <Module> list, else
// the slots' default modules, looked up in the entry's module file, the device's own file and
// every other ESI file in the device file's folder.
class SlaveFactory {
 public:
  Result<std::unique_ptr<slavesim::Slave>> make(const TopologySlave& entry);
  // ESI warnings (malformed values the reader replaced) and module notes, once per file.
  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  Result<const EsiFile*> esiFile(const std::filesystem::path& path);
  Result<EsiDevice> withModules(const TopologySlave& entry, const EsiFile& file,
                                const EsiDevice& device);

  std::map<std::filesystem::path, EsiFile> esiFiles_;
  std::vector<std::string> warnings_;
};

Result<Network> buildNetwork(const TopologyConfig& config);

}  // namespace ecsim::topology
