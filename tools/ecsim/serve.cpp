// `ecsim serve`: answer an EtherCAT master on a network interface (one end of a veth pair, a
// TAP device, or a real NIC) as a line of simulated slaves.
#include <fmt/core.h>

#include <sched.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "config/topology_file.hpp"
#include "link/pcap.hpp"
#include "link/raw_socket_link.hpp"
#include "link/signal_flag.hpp"
#include "link/tap_link.hpp"
#include "link/veth_setup.hpp"
#include "slavesim/generic_slave.hpp"
#include "tools/common/install_paths.hpp"
#include "tools/ecsim/commands.hpp"
#include "tools/ecsim/control_api.hpp"
#include "tools/ecsim/status_view.hpp"
#include "topology/control_server.hpp"
#include "topology/faults.hpp"
#include "topology/network_builder.hpp"
#include "topology/network_from_eni.hpp"
#include "topology/network_server.hpp"
#include "topology/pcap_cable_tap.hpp"

namespace ecsim::tools {
namespace {

// While frames come back to back, how often the serve loop looks at its control socket and
// status and flushes its captures (an action injected through the socket takes effect within
// this time).
constexpr SimTime kHousekeepingInterval = kNsPerMs;

struct ServeOptions {
  std::string topology;
  std::string esiDir;  // ESI files for an ENI's devices; empty: the data folder's esi/
  std::vector<std::string> pcapLinks;  // NAME=FILE
  std::string iface;
  std::string redundantIface;  // the master's second port (cable redundancy)
  std::string veth;
  std::string tap;
  std::string netns;
  std::string pcap;
  std::string pcapMalformed;  // malformed frames the simulator dropped, to their own capture
  unsigned slaves{0};         // 0: not given
  bool paced{false};
  bool quiet{false};
  bool realtime{false};
  bool busyPoll{false};
  int sendCpu{-1};         // --send-cpu; -1: answers sent with send(2)
  bool status{false};      // live table on the terminal
  std::string statusJson;  // status rewritten periodically to this file
  std::string control;     // live-injection socket; empty: /run/ecsim/<interface>.sock
};

namespace {

// --send-cpu: this process leaves `cpu`, where the sending thread polls: the server's
// busy-polling at real-time priority beside it would hold the answers back. An error when the
// process may run nowhere else.
Status leaveCpu(int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) != 0) {
    return makeError(ErrorCode::kIo, std::string("sched_getaffinity: ") + std::strerror(errno));
  }
  if (cpu >= CPU_SETSIZE || !CPU_ISSET(cpu, &set)) return okStatus();
  CPU_CLR(cpu, &set);
  if (CPU_COUNT(&set) == 0) {
    return makeError(
        ErrorCode::kInvalidArgument,
        "--send-cpu " + std::to_string(cpu) + ": this process may run on no other CPU (taskset?)");
  }
  if (sched_setaffinity(0, sizeof set, &set) != 0) {
    return makeError(ErrorCode::kIo, std::string("sched_setaffinity: ") + std::strerror(errno));
  }
  return okStatus();
}

}  // namespace

int runServe(ServeOptions o) {
  if (static_cast<int>(!o.iface.empty()) + static_cast<int>(!o.tap.empty()) +
          static_cast<int>(!o.veth.empty()) !=
      1) {
    fmt::print(stderr, "ecsim serve: give exactly one of --iface, --veth or --tap\n");
    return 2;
  }
  if (o.sendCpu >= 0 && !o.busyPoll) {
    fmt::print(stderr,
               "ecsim serve: --send-cpu needs --busy-poll (a server that sleeps in the kernel for "
               "every frame gains nothing from sending without it)\n");
    return 2;
  }
  if (o.busyPoll && !o.tap.empty()) {
    fmt::print(stderr,
               "ecsim serve: --busy-poll needs a raw socket (--iface or --veth), not --tap\n");
    return 2;
  }
  // --veth NAME: create the pair for the run (cleaning a stale one) and remove it after.
  struct VethGuard {
    std::string name;
    ~VethGuard() {
      if (!name.empty()) (void)vethDown(name);
    }
  } vethGuard;
  if (!o.veth.empty()) {
    auto pair = vethUp(o.veth);
    if (!pair.ok()) {
      fmt::print(stderr, "ecsim serve: {}\n", pair.error().message());
      return 1;
    }
    vethGuard.name = o.veth;
    o.iface = pair->simulatorInterface;
    fmt::print("ecsim: veth pair ready, point your master at {}\n", pair->masterInterface);
  }
  if (!o.redundantIface.empty() && o.iface.empty()) {
    fmt::print(stderr, "ecsim serve: --redundant-iface needs --iface or --veth\n");
    return 2;
  }
  // --send-cpu: the answers leave through a kernel thread on that CPU, so that the server's
  // thread never enters the kernel between frames (docs/served-path.md).
  if (o.sendCpu >= 0) {
    if (auto left = leaveCpu(o.sendCpu); !left.ok()) {
      fmt::print(stderr, "ecsim serve: {}\n", left.error().message());
      return 2;
    }
  }
  auto openServed = [&](const std::string& name) {
    return RawSocketLink::open(name, RawSocketOptions{.netns = o.netns,
                                                      .promiscuous = true,
                                                      .qdiscBypass = true,
                                                      .busyPoll = o.busyPoll,
                                                      .sendCpu = o.sendCpu});
  };
  std::unique_ptr<Link> link;
  std::unique_ptr<Link> redundantLink;
  if (!o.redundantIface.empty()) {
    auto raw = openServed(o.redundantIface);
    if (!raw.ok()) {
      fmt::print(stderr, "ecsim serve: {}\n", raw.error().message());
      return 1;
    }
    redundantLink = std::make_unique<RawSocketLink>(std::move(raw).value());
  }
  if (!o.iface.empty()) {
    auto raw = openServed(o.iface);
    if (!raw.ok()) {
      fmt::print(stderr, "ecsim serve: {}\n", raw.error().message());
      return 1;
    }
    link = std::make_unique<RawSocketLink>(std::move(raw).value());
  } else {
    auto tap = TapLink::open(o.tap);
    if (!tap.ok()) {
      fmt::print(stderr, "ecsim serve: {}\n", tap.error().message());
      return 1;
    }
    link = std::make_unique<TapLink>(std::move(tap).value());
  }

  topology::Network network;
  if (o.topology.empty() && o.slaves == 0) {
    auto demo = dataFile("topologies/demo.xml");
    if (!demo.ok()) {
      fmt::print(stderr, "ecsim serve: {}\n", demo.error().message());
      return 1;
    }
    o.topology = demo->string();
  }
  auto root = o.topology.empty() ? Result<std::string>(std::string()) : xmlRootName(o.topology);
  if (root.ok() && *root == "EtherCATConfig") {  // an ENI: devices from the ESI folder
    if (o.esiDir.empty()) {
      auto esi = dataFile("esi");
      if (!esi.ok()) {
        fmt::print(stderr, "ecsim serve: {}\n", esi.error().message());
        return 1;
      }
      o.esiDir = esi->string();
    }
    auto built = topology::buildNetworkFromEni(o.topology, {o.esiDir});
    if (!built.ok()) {
      fmt::print(stderr, "ecsim serve: {}\n", built.error().message());
      return 1;
    }
    network = std::move(built).value();
  } else if (!o.topology.empty()) {
    auto config = loadTopologyFile(o.topology);
    if (!config.ok()) {
      fmt::print(stderr, "ecsim serve: {}\n", config.error().message());
      return 1;
    }
    auto built = topology::buildNetwork(*config);
    if (!built.ok()) {
      fmt::print(stderr, "ecsim serve: {}\n", built.error().message());
      return 1;
    }
    network = std::move(built).value();
  } else {
    network.segment = std::make_unique<topology::Segment>();
    for (unsigned i = 0; i < o.slaves; ++i) {
      network.segment->addSlave(slavesim::makeGenericSlave(fmt::format("Slave{}", i + 1), i + 1));
    }
    network.segment->wireLine();
    network.cables.push_back({"master", 0, 0});
  }
  // What the ENI reader ignored and what building the devices could not take as written.
  for (const auto& w : network.warnings) fmt::print(stderr, "ecsim serve: warning: {}\n", w);
  topology::Segment& segment = *network.segment;
  if (redundantLink != nullptr && !segment.redundant()) {
    fmt::print(stderr,
               "ecsim serve: --redundant-iface: the topology has no redundant port (<Master "
               "redundant=\"SLAVE:PORT\">, docs/topology.md)\n");
    return 2;
  }
  if (redundantLink == nullptr && segment.redundant()) {
    fmt::print(stderr,
               "ecsim serve: warning: the topology's redundant port has no master port "
               "(--redundant-iface): the ring is open there\n");
  }

  RealClock clock;
  // Captures are stamped with model time; model time 0 is mapped to the Unix time now.
  const SimTime unixOffset = WallClock().now() - clock.now();
  // One capture per observed cable: --pcap is the master's cable, --pcap-link NAME=FILE any.
  std::vector<std::pair<std::string, std::string>> captures;
  if (!o.pcap.empty()) captures.emplace_back("master", o.pcap);
  for (const auto& spec : o.pcapLinks) {
    auto eq = spec.find('=');
    if (eq == std::string::npos) {
      fmt::print(stderr, "ecsim serve: --pcap-link wants NAME=FILE, got '{}'\n", spec);
      return 2;
    }
    captures.emplace_back(spec.substr(0, eq), spec.substr(eq + 1));
  }
  if (!o.pcapMalformed.empty()) captures.emplace_back("", o.pcapMalformed);
  // Each writer's header is on disk once opened (a full disk fails here, before serving).
  std::vector<std::unique_ptr<PcapWriter>> writers;
  std::vector<std::unique_ptr<topology::PcapCableTap>> taps;
  topology::CableObserver* malformedTap = nullptr;
  for (const auto& [cable, file] : captures) {
    const topology::CableRef* ref = cable.empty() ? nullptr : network.findCable(cable);
    if (!cable.empty() && ref == nullptr) {
      fmt::print(stderr, "ecsim serve: no cable named '{}' in the topology\n", cable);
      return 2;
    }
    auto w = PcapWriter::open(file);
    if (!w.ok()) {
      fmt::print(stderr, "ecsim serve: {}\n", w.error().message());
      return 1;
    }
    writers.push_back(std::make_unique<PcapWriter>(std::move(w).value()));
    taps.push_back(std::make_unique<topology::PcapCableTap>(*writers.back(), unixOffset));
    if (ref != nullptr) {
      segment.setCableObserver(ref->slave, ref->port, taps.back().get());
    } else {
      malformedTap = taps.back().get();
    }
  }
  Link* served = link.get();

  if (o.realtime) {
    // Answer within the master's timeout even on a loaded host: SCHED_FIFO and locked memory
    // when permitted (root or CAP_SYS_NICE), a clear warning otherwise.
    sched_param param{};
    param.sched_priority = 80;
    if (sched_setscheduler(0, SCHED_FIFO, &param) != 0) {
      fmt::print(stderr,
                 "ecsim serve: warning: SCHED_FIFO not permitted ({}); running with "
                 "normal priority\n",
                 std::strerror(errno));
    }
    if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
      fmt::print(stderr, "ecsim serve: warning: mlockall failed ({})\n", std::strerror(errno));
    }
  }
  topology::ServerOptions options;
  options.paced = o.paced;
  options.idleWait = std::chrono::milliseconds(10);
  // The firmware runs after every frame (ServerOptions::firmwareSpacing stays 0): spaced, a
  // slow build (AddressSanitizer) left the SII EEPROM interface busy while the master's frames
  // came back to back, and a scan timed out (StudyLatencyVeth, DriveVeth, SOEM v2 simple_ng).
  // Busy-polling looks at a receive ring without a system call, so the wait between frames
  // can fetch the ESCs ahead for the next one (docs/served-path.md).
  options.prefetchWhileIdle = o.busyPoll;
  options.malformedObserver = malformedTap;
  topology::NetworkServer server(*served, segment, clock, options);
  server.setRedundantLink(redundantLink.get());
  SignalFlag stop;
  if (!o.quiet) {
    fmt::print("ecsim: serving {} slave(s) on {}{}{}\n", segment.size(), link->describe(),
               redundantLink ? " and, redundant, " + redundantLink->describe() : std::string(),
               o.pcap.empty() ? "" : fmt::format(", capturing to {}", o.pcap));
    if (o.sendCpu >= 0) {
      fmt::print(
          "ecsim: busy-polling; answers sent by a kernel thread on CPU {} (io_uring), "
          "this process kept off it\n",
          o.sendCpu);
    }
    std::fflush(stdout);
  }
  StatusReporter reporter(o.status, o.statusJson);
  // The control socket (docs/control.md): queries, process data, subscriptions and fault
  // actions (docs/scenarios.md, "Live injection").
  ControlApi api(network);
  if (o.control.empty()) {
    o.control = topology::defaultControlSocket(o.iface.empty() ? o.tap : o.iface).string();
  }
  auto control = topology::ControlServer::open(o.control);
  if (!control.ok()) {
    fmt::print(stderr, "ecsim serve: warning: no control socket: {}\n", control.error().message());
  } else if (!o.quiet) {
    fmt::print("ecsim: control socket {} (ecsim ctl --socket {} ACTION ...)\n", o.control,
               o.control);
    std::fflush(stdout);
  }
  auto handle = [&](std::string_view line, topology::ControlServer::ClientId client) {
    return api.answer(line, client, clock.now());
  };
  // Captures reach the disk when the server idles and at least every kCaptureFlushInterval
  // under traffic; a capture error is reported at once and fails the run (it serves on).
  bool captureFailed = false;
  auto reportCapture = [&](const Status& s) {
    if (s.ok() || captureFailed) return;
    captureFailed = true;
    fmt::print(stderr, "ecsim serve: capture failed, serving on without it: {}\n",
               s.error().message());
    std::fflush(stderr);
  };
  // The control socket, the status and the captures' flushing are looked after whenever the
  // server idled, and while frames come back to back at most every kHousekeepingInterval:
  // not between every two frames, where it cost system calls on the answers' path.
  std::uint64_t receivedBefore = 0;
  SimTime housekeepingDue = 0;
  auto status = server.run([&] {
    const bool idle = server.counters().framesReceived == receivedBefore;
    receivedBefore = server.counters().framesReceived;
    const SimTime now = clock.now();
    if (!idle && now < housekeepingDue) return stop.raised();
    housekeepingDue = now + kHousekeepingInterval;
    if (control.ok()) {
      control->poll(topology::ControlServer::ClientHandler(handle), now);
      api.publish(*control);
    }
    reporter.tick(now, segment, server.counters());
    for (std::size_t i = 0; i < writers.size(); ++i) {
      reportCapture(taps[i]->status());
      reportCapture(idle ? writers[i]->flush() : writers[i]->flushIfDue(clock.now()));
    }
    return stop.raised();
  });
  for (auto& w : writers) reportCapture(w->close());
  const auto& c = server.counters();
  const auto& sc = segment.counters();
  fmt::print(
      "ecsim: stopped; frames received {}, answered {}, malformed dropped {}, "
      "lost in the network {}, late (paced, beyond 1 s) {}, receive errors {}, send errors {}, "
      "datagrams {}\n",
      c.framesReceived, c.framesAnswered, c.framesDropped, c.framesLost, c.framesLate,
      c.receiveErrors, c.sendErrors, sc.datagramsProcessed);
  if (!status.ok()) {
    fmt::print(stderr, "ecsim serve: {}\n", status.error().message());
    return 1;
  }
  return captureFailed ? 1 : 0;
}

}  // namespace

CommandRunner addServeCommand(CLI::App& app) {
  auto opts = std::make_shared<ServeOptions>();
  auto* cmd = app.add_subcommand("serve", "Answer an EtherCAT master on a network interface");
  cmd->add_option(
      "topology", opts->topology,
      "Topology file or ENI (EtherCATConfig) file (default: the demo network, or a line of "
      "--slaves generic slaves)");
  cmd->add_option("--esi-dir", opts->esiDir,
                  "Folder of ESI files for an ENI's devices (default: the examples' esi/)");
  cmd->add_option("--pcap-link", opts->pcapLinks, "Capture the cable NAME to FILE (NAME=FILE)");
  cmd->add_option("--iface", opts->iface, "Interface to serve (e.g. one end of a veth pair)");
  cmd->add_option("--redundant-iface", opts->redundantIface,
                  "The master's second port (cable redundancy: the topology's <Master "
                  "redundant=>)");
  cmd->add_option("--veth", opts->veth, "Create veth pair NAME for this run (master end NAME)");
  cmd->add_option("--tap", opts->tap, "Create/open this TAP device and serve on it");
  cmd->add_option("--netns", opts->netns, "Open the interface inside this network namespace");
  cmd->add_option("--slaves", opts->slaves, "Serve a line of N generic slaves instead")
      ->check(CLI::Range(1u, 65535u));
  cmd->add_option("--pcap", opts->pcap, "Capture every frame to this pcap file");
  cmd->add_option("--pcap-malformed", opts->pcapMalformed,
                  "Capture the malformed frames the simulator dropped to this pcap file");
  cmd->add_option(
      "--control", opts->control,
      "Control socket for queries and live fault injection (default /run/ecsim/IFACE.sock)");
  cmd->add_flag("--paced", opts->paced, "Answer at the modelled round-trip time");
  cmd->add_flag("--quiet", opts->quiet, "Print only the final statistics");
  cmd->add_flag("--rt", opts->realtime, "Run with SCHED_FIFO priority and locked memory");
  cmd->add_flag("--busy-poll", opts->busyPoll,
                "Wait for frames by polling a receive ring without sleeping, the slaves' state "
                "fetched ahead meanwhile: shorter round trips, one core kept busy (for a "
                "dedicated core)");
  cmd->add_option("--send-cpu", opts->sendCpu,
                  "With --busy-poll: send the answers through a kernel thread polling on CPU "
                  "(io_uring), which this process then leaves: no system call between frames. "
                  "For a CPU of its own: a real-time thread busy there (a polling master) holds "
                  "the answers back")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--status", opts->status, "Show a live status table (redrawn twice a second)");
  cmd->add_option("--status-json", opts->statusJson,
                  "Rewrite the status to FILE (JSON) twice a second");
  return [opts] { return runServe(*opts); };
}

}  // namespace ecsim::tools
