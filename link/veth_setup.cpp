#include "link/veth_setup.hpp"

#include <fstream>
#include <sstream>

#include "link/netns.hpp"

namespace ecsim {
namespace {

std::filesystem::path statePath(const VethSetupOptions& o, const std::string& name) {
  return o.stateDir / ("net-" + name + ".state");
}

Status run(const std::vector<std::string>& argv, bool mustSucceed = true) {
  auto out = runCommand(argv);
  if (!out.ok()) return out.takeError();
  if (mustSucceed && out->exitCode != 0) {
    std::string cmd;
    for (const auto& a : argv) cmd += (cmd.empty() ? "" : " ") + a;
    return makeError(ErrorCode::kIo, "'" + cmd + "' failed: " + out->output);
  }
  return okStatus();
}

std::vector<std::string> inNs(const std::string& ns, std::vector<std::string> argv) {
  if (ns.empty()) return argv;
  std::vector<std::string> wrapped{"ip", "netns", "exec", ns};
  wrapped.insert(wrapped.end(), argv.begin(), argv.end());
  return wrapped;
}

Status configureEnd(const std::string& ns, const std::string& ifname) {
  ECSIM_TRY(run(inNs(ns, {"ip", "link", "set", ifname, "mtu", "1500"})));
  // IPv6 off: no router solicitations or other frames of the kernel's own on the wire.
  ECSIM_TRY(
      run(inNs(ns, {"sysctl", "-q", "-w", "net.ipv6.conf." + ifname + ".disable_ipv6=1"}), false));
  // No offloads that could split, merge or checksum frames (ethtool may be absent: then the
  // veth defaults stay, which do not alter EtherCAT frames).
  (void)run(inNs(ns, {"ethtool", "-K", ifname, "tx", "off", "rx", "off", "tso", "off", "gso", "off",
                      "gro", "off"}),
            false);
  return run(inNs(ns, {"ip", "link", "set", ifname, "up"}));
}

}  // namespace

Result<VethSetup> vethUp(const std::string& name, const VethSetupOptions& options) {
  if (name.empty() || name.size() > 14 ||
      name.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-") !=
          std::string::npos) {
    return makeError(ErrorCode::kInvalidArgument,
                     "net name '" + name + "': use 1-14 characters of A-Z a-z 0-9 _ -");
  }
  if (!hasNetAdminCapability()) {
    return makeError(ErrorCode::kPermission,
                     "creating a veth pair needs CAP_NET_ADMIN (run as root or with sudo)");
  }
  // A run killed before `down` leaves its pair behind: clean what its state file records.
  if (std::filesystem::exists(statePath(options, name))) (void)vethDown(name, options);
  VethSetup s;
  s.name = name;
  s.masterInterface = name;
  s.simulatorInterface = name + "s";
  if (options.ownNamespace) {
    s.netns = "ecsim-" + name;
    ECSIM_TRY(run({"ip", "netns", "add", s.netns}));
  }
  std::filesystem::create_directories(options.stateDir);
  {
    std::ofstream state(statePath(options, name));
    state << "netns=" << s.netns << "\n"
          << "master=" << s.masterInterface << "\n"
          << "simulator=" << s.simulatorInterface << "\n";
  }
  Status made = run(inNs(s.netns, {"ip", "link", "add", s.masterInterface, "type", "veth", "peer",
                                   "name", s.simulatorInterface}));
  if (made.ok()) made = configureEnd(s.netns, s.masterInterface);
  if (made.ok()) made = configureEnd(s.netns, s.simulatorInterface);
  if (made.ok()) made = waitOperational(s.netns, s.masterInterface);
  if (made.ok()) made = waitOperational(s.netns, s.simulatorInterface);
  if (!made.ok()) {
    (void)vethDown(name, options);
    return made.takeError();
  }
  return s;
}

Status vethDown(const std::string& name, const VethSetupOptions& options) {
  const auto path = statePath(options, name);
  std::ifstream in(path);
  if (!in)
    return makeError(ErrorCode::kNotFound,
                     "no ecsim net named '" + name + "' (" + path.string() + ")");
  std::string line, netns, master;
  while (std::getline(in, line)) {
    if (line.rfind("netns=", 0) == 0) netns = line.substr(6);
    if (line.rfind("master=", 0) == 0) master = line.substr(7);
  }
  // Deleting one end deletes the pair; deleting the namespace deletes what is inside.
  if (!master.empty()) (void)run(inNs(netns, {"ip", "link", "del", master}), false);
  if (!netns.empty()) (void)run({"ip", "netns", "del", netns}, false);
  std::filesystem::remove(path);
  return okStatus();
}

}  // namespace ecsim
