#include "link/veth_setup.hpp"

#include <sys/stat.h>

#include <charconv>
#include <fstream>
#include <map>

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

// The interface's index in namespace `ns` ("N: NAME..." from `ip -o link show`), kNotFound
// when there is no interface of that name.
Result<long> interfaceIndex(const std::string& ns, const std::string& ifname) {
  ECSIM_ASSIGN_OR_RETURN(CommandOutput out,
                         runCommand(inNs(ns, {"ip", "-o", "link", "show", "dev", ifname})));
  long index = 0;
  const char* begin = out.output.data();
  const auto [end, ec] = std::from_chars(begin, begin + out.output.size(), index);
  if (out.exitCode != 0 || ec != std::errc() || *end != ':') {
    return makeError(ErrorCode::kNotFound, "no interface '" + ifname + "'");
  }
  return index;
}

// Which network namespace: the inode of its nsfs file (unique while the namespace exists).
// `ns` empty: the one this process is in.
std::string namespaceIdentity(const std::string& ns) {
  const std::string path = ns.empty() ? "/proc/self/ns/net" : "/var/run/netns/" + ns;
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return "";
  return std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino);
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

// What the state file records: key=value lines.
std::map<std::string, std::string> readState(std::ifstream& in) {
  std::map<std::string, std::string> values;
  for (std::string line; std::getline(in, line);) {
    const auto eq = line.find('=');
    if (eq != std::string::npos) values[line.substr(0, eq)] = line.substr(eq + 1);
  }
  return values;
}

Status refuseExisting(const std::string& ns, const std::string& ifname) {
  if (!interfaceIndex(ns, ifname).ok()) return okStatus();
  return makeError(ErrorCode::kState,
                   "interface '" + ifname + "' already exists" +
                       (ns.empty() ? "" : " in network namespace '" + ns + "'") +
                       " and ecsim did not create it: choose another name (ecsim never touches "
                       "an interface it did not create)");
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
  // A run killed before `down` leaves its pair behind: remove what its state file proves was
  // made by ecsim (a record that proves nothing is dropped, and what exists is refused below).
  if (std::filesystem::exists(statePath(options, name))) (void)vethDown(name, options);
  VethSetup s;
  s.name = name;
  s.masterInterface = name;
  s.simulatorInterface = name + "s";
  if (options.ownNamespace) {
    s.netns = "ecsim-" + name;
    if (std::filesystem::exists("/var/run/netns/" + s.netns)) {
      return makeError(ErrorCode::kState, "network namespace '" + s.netns +
                                              "' already exists and ecsim did not create it");
    }
  } else {
    ECSIM_TRY(refuseExisting("", s.masterInterface));
    ECSIM_TRY(refuseExisting("", s.simulatorInterface));
  }
  if (options.ownNamespace) ECSIM_TRY(run({"ip", "netns", "add", s.netns}));
  const std::string nsIdentity = namespaceIdentity(s.netns);
  Status made = run(inNs(s.netns, {"ip", "link", "add", s.masterInterface, "type", "veth", "peer",
                                   "name", s.simulatorInterface}));
  if (!made.ok()) {
    if (options.ownNamespace) (void)run({"ip", "netns", "del", s.netns}, false);
    return made.takeError();
  }
  // Only now, with the pair made by us, the record that proves it: both ends' indexes (a pair
  // made later under the same names gets new ones) and the namespace's identity.
  auto masterIndex = interfaceIndex(s.netns, s.masterInterface);
  auto simulatorIndex = interfaceIndex(s.netns, s.simulatorInterface);
  if (!masterIndex.ok() || !simulatorIndex.ok()) {
    made = makeError(ErrorCode::kIo, "veth pair '" + name + "' vanished right after creation");
  } else {
    std::filesystem::create_directories(options.stateDir);
    std::ofstream state(statePath(options, name));
    state << "netns=" << s.netns << "\n"
          << "netnsId=" << nsIdentity << "\n"
          << "ownNetns=" << (options.ownNamespace ? 1 : 0) << "\n"
          << "master=" << s.masterInterface << "\n"
          << "masterIndex=" << *masterIndex << "\n"
          << "simulator=" << s.simulatorInterface << "\n"
          << "simulatorIndex=" << *simulatorIndex << "\n";
    if (!state.flush()) {
      made = makeError(ErrorCode::kIo, "writing " + statePath(options, name).string());
    }
  }
  if (made.ok()) made = configureEnd(s.netns, s.masterInterface);
  if (made.ok()) made = configureEnd(s.netns, s.simulatorInterface);
  if (made.ok()) made = waitOperational(s.netns, s.masterInterface);
  if (made.ok()) made = waitOperational(s.netns, s.simulatorInterface);
  if (!made.ok()) {
    if (std::filesystem::exists(statePath(options, name))) {
      (void)vethDown(name, options);
    } else {  // no record: the pair was made a moment ago by this call
      (void)run(inNs(s.netns, {"ip", "link", "del", s.masterInterface}), false);
      if (options.ownNamespace) (void)run({"ip", "netns", "del", s.netns}, false);
    }
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
  auto state = readState(in);
  in.close();
  // The record is used once: removed whether it proves ownership or not.
  std::filesystem::remove(path);
  const std::string& netns = state["netns"];
  const std::string identity = namespaceIdentity(netns);
  if (identity.empty()) return okStatus();  // its own namespace is gone, and the pair with it
  if (identity != state["netnsId"]) {
    return makeError(ErrorCode::kState,
                     "ecsim net '" + name + "': network namespace " +
                         (netns.empty() ? "of this process" : "'" + netns + "'") +
                         " is not the one ecsim created the pair in: left alone");
  }
  const std::string& master = state["master"];
  const std::string& simulator = state["simulator"];
  auto masterIndex = interfaceIndex(netns, master);
  auto simulatorIndex = interfaceIndex(netns, simulator);
  Status status;
  if (masterIndex.ok() || simulatorIndex.ok()) {
    const bool ours = masterIndex.ok() && simulatorIndex.ok() &&
                      std::to_string(*masterIndex) == state["masterIndex"] &&
                      std::to_string(*simulatorIndex) == state["simulatorIndex"];
    if (ours) {
      // Deleting one end deletes the pair.
      (void)run(inNs(netns, {"ip", "link", "del", master}), false);
    } else {
      status =
          makeError(ErrorCode::kState, "interfaces '" + master + "'/'" + simulator +
                                           "' are not the pair ecsim created (recorded indexes " +
                                           state["masterIndex"] + "/" + state["simulatorIndex"] +
                                           "): left alone");
    }
  }
  // Deleting our namespace deletes what is inside; a foreign interface moved into it meanwhile
  // is the only thing that could be lost, so the namespace goes only when the pair was ours.
  if (state["ownNetns"] == "1" && status.ok()) (void)run({"ip", "netns", "del", netns}, false);
  return status;
}

}  // namespace ecsim
