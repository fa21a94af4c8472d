#include "config/eni_topology.hpp"

#include <algorithm>
#include <cstdio>
#include <map>

#include "config/esi.hpp"
#include "protocol/bytes.hpp"

namespace ecsim::topology {
namespace {

struct Candidate {
  std::filesystem::path file;
  std::uint32_t vendor{0};
  std::uint32_t product{0};
  std::uint32_t revision{0};
};

std::string hex8(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08X", v);
  return buf;
}

// Every device of every ESI file in the folders (files that are not ESI are skipped).
std::vector<Candidate> catalogue(const std::vector<std::filesystem::path>& dirs) {
  std::vector<Candidate> out;
  for (const auto& dir : dirs) {
    std::error_code ec;
    std::vector<std::filesystem::path> files;
    for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
      if (entry.is_regular_file() && entry.path().extension() == ".xml") {
        files.push_back(entry.path());
      }
    }
    std::sort(files.begin(), files.end());  // deterministic choice between equal devices
    for (const auto& file : files) {
      auto esi = loadEsiFile(file);
      if (!esi.ok()) continue;
      for (const auto& device : esi->devices) {
        if (!device.hasProductCode) continue;
        out.push_back({file, esi->vendor.id, device.productCode, device.revision});
      }
    }
  }
  return out;
}

// ETG.5001 0xF030 Configured Module List: what a configuration tool downloads to a modular
// device (TwinCAT as a CoE init command, complete access from sub 0 or one subindex at a time).
constexpr std::uint16_t kConfiguredModuleListIndex = 0xF030;
constexpr std::size_t kModuleIdentBytes = 4;

// The module idents a slave's CoE init commands download to 0xF030, in slot order; empty when
// there are none. A complete access stream holds sub 0 (the count) in one byte, padded to two
// when the entries start at bit 16 as in the vendors' dictionaries; both are taken.
Result<std::vector<TopologyModule>> modulesOf(const EniSlave& s, const std::filesystem::path& file) {
  std::vector<TopologyModule> out;
  if (!s.mailbox) return out;
  std::map<unsigned, TopologyModule> bySub;
  std::optional<unsigned> count;
  for (const EniCoeCmd& c : s.mailbox->coeInitCmds) {
    if (c.ccs != 1 || c.index != kConfiguredModuleListIndex) continue;
    auto bad = [&](const std::string& what) {
      return makeError(ErrorCode::kInvalidArgument,
                       file.string() + ", line " + std::to_string(c.line) + ": slave '" + s.name +
                           "': 0xF030 init command: " + what);
    };
    if (c.completeAccess) {
      if (c.data.empty()) return bad("no data");
      const std::size_t n = c.data[0];
      std::size_t offset = 1;
      if (c.data.size() == 2 + n * kModuleIdentBytes) {
        offset = 2;
      } else if (c.data.size() != 1 + n * kModuleIdentBytes) {
        return bad(std::to_string(c.data.size()) + " bytes of data for " + std::to_string(n) +
                   " modules");
      }
      for (std::size_t i = 0; i < n; ++i) {
        bySub[static_cast<unsigned>(i + 1)] = {
            "", readLe32(c.data, offset + i * kModuleIdentBytes), c.line};
      }
      count = static_cast<unsigned>(n);
    } else if (c.subIndex == 0) {
      if (c.data.empty()) return bad("no data for sub 0");
      count = c.data[0];
    } else {
      if (c.data.size() != kModuleIdentBytes) {
        return bad("sub " + std::to_string(c.subIndex) + " has " + std::to_string(c.data.size()) +
                   " bytes, a module ident has 4");
      }
      bySub[c.subIndex] = {"", readLe32(c.data, 0), c.line};
    }
  }
  const unsigned n = count.value_or(static_cast<unsigned>(bySub.size()));
  for (unsigned sub = 1; sub <= n; ++sub) {
    auto found = bySub.find(sub);
    if (found == bySub.end()) {
      return makeError(ErrorCode::kInvalidArgument,
                       file.string() + ", line " + std::to_string(s.line) + ": slave '" + s.name +
                           "': 0xF030 lists " + std::to_string(n) + " modules but sets no sub " +
                           std::to_string(sub));
    }
    out.push_back(found->second);
  }
  return out;
}

}  // namespace

Result<TopologyConfig> topologyFromEni(const EniConfig& eni,
                                       const std::vector<std::filesystem::path>& esiDirs) {
  const std::vector<Candidate> devices = catalogue(esiDirs);
  TopologyConfig config;
  config.file = eni.file;
  config.name = eni.file.stem().string();
  std::map<std::uint16_t, std::size_t> byAddress;
  for (std::size_t i = 0; i < eni.slaves.size(); ++i) {
    const EniSlave& s = eni.slaves[i];
    const Candidate* best = nullptr;
    for (const auto& c : devices) {
      if (c.vendor != s.vendorId || c.product != s.productCode) continue;
      if (s.revisionNo && c.revision == *s.revisionNo) {
        best = &c;
        break;
      }
      if (best == nullptr || c.revision > best->revision) best = &c;
    }
    if (best == nullptr) {
      std::string dirs;
      for (const auto& d : esiDirs) dirs += (dirs.empty() ? "" : ", ") + d.string();
      return makeError(ErrorCode::kNotFound,
                       eni.file.string() + ", line " + std::to_string(s.line) + ": slave '" +
                           s.name + "' (vendor " + hex8(s.vendorId) + " product " +
                           hex8(s.productCode) + "): no such device in the ESI files of " +
                           (dirs.empty() ? "(no folder)" : dirs));
    }
    TopologySlave slave;
    slave.name = s.name.empty() ? "slave" + std::to_string(i) : s.name;
    slave.esiFile = best->file;
    slave.productCode = best->product;
    slave.revision = best->revision;
    slave.line = s.line;
    ECSIM_ASSIGN_OR_RETURN(slave.modules, modulesOf(s, eni.file));
    config.slaves.push_back(std::move(slave));
    byAddress[s.physAddr] = i;
  }
  // Wiring: PreviousPort (parent's port -> this slave's port 0) when every slave after the
  // first has one; otherwise a line.
  bool tree = eni.slaves.size() > 1;
  for (std::size_t i = 1; i < eni.slaves.size(); ++i) {
    if (eni.slaves[i].previousPort() == nullptr) tree = false;
  }
  if (tree) {
    for (std::size_t i = 1; i < eni.slaves.size(); ++i) {
      const EniPreviousPort& p = *eni.slaves[i].previousPort();
      TopologyLink link;
      link.fromSlave = byAddress.at(p.physAddr);  // the reader checked it names a slave
      link.fromPort = p.port;
      link.toSlave = i;
      link.toPort = 0;
      link.line = eni.slaves[i].line;
      config.links.push_back(link);
    }
    config.explicitLinks = true;
  } else {
    for (std::size_t i = 1; i < eni.slaves.size(); ++i) {
      config.links.push_back({"", i - 1, 1, i, 0, 1.0, eni.slaves[i].line});
    }
  }
  for (auto& l : config.links) {  // cable names as topology files get them
    l.name = config.slaves[l.fromSlave].name + ":" + std::to_string(l.fromPort) + "-" +
             config.slaves[l.toSlave].name + ":" + std::to_string(l.toPort);
  }
  return config;
}

}  // namespace ecsim::topology
