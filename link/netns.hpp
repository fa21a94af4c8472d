// Privileged set-up for tests and tools, kept apart from the links themselves: a private
// network namespace holding a veth pair (VethNamespace), child processes started inside it
// (ChildProcess), and a check of the capabilities all this needs. Everything is done with
// iproute2's `ip` command run through posix_spawn; nothing here is used on a frame path.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <string>
#include <vector>

#include "protocol/result.hpp"

namespace ecsim {

// Effective capabilities of this process that the network set-up needs.
struct NetworkCapabilities {
  bool netAdmin{false};  // CAP_NET_ADMIN: create interfaces, TAP devices
  bool netRaw{false};    // CAP_NET_RAW: AF_PACKET raw sockets
  bool sysAdmin{false};  // CAP_SYS_ADMIN: create and enter network namespaces
};
NetworkCapabilities networkCapabilities();
bool hasNetAdminCapability();
// ok, or kPermission naming every capability that is missing.
Status checkNetworkCapabilities();

// Where a child's standard streams go. Empty path: inherited from this process. stdin is
// always /dev/null.
struct SpawnOptions {
  std::string stdoutPath;
  std::string stderrPath;  // may equal stdoutPath: both streams then share the file
  // SCHED_FIFO priority of the child (and of what it starts); 0: the caller's policy. Needs
  // root or CAP_SYS_NICE (a RealTimeThread's ok() tells); without it the spawn fails (EPERM).
  int fifoPriority{0};
};

// A child process in its own process group. kill() signals the whole group; the destructor
// stops (SIGTERM, then SIGKILL) and reaps a child that is still running. Move-only.
class ChildProcess {
 public:
  ChildProcess() = default;
  explicit ChildProcess(pid_t pid) : pid_(pid) {}
  ChildProcess(ChildProcess&& other) noexcept;
  ChildProcess& operator=(ChildProcess&& other) noexcept;
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;
  ~ChildProcess();

  pid_t pid() const { return pid_; }
  bool running();
  // Waits for the exit: the exit code, or 128 + signal number when a signal ended it
  // (shell convention). kTimeout when still running after timeout.
  Result<int> wait(std::chrono::nanoseconds timeout);
  Status kill(int signal);
  // SIGTERM, up to `grace` to exit, then SIGKILL; returns the exit status as wait() does.
  Result<int> stop(std::chrono::nanoseconds grace = std::chrono::seconds(2));

 private:
  pid_t pid_{-1};
  bool reaped_{false};
  int status_{0};
};

// Starts argv[0] (searched in PATH) with argv. kNotFound when the program does not exist.
Result<ChildProcess> spawnProcess(const std::vector<std::string>& argv,
                                  const SpawnOptions& options = {});

struct CommandOutput {
  int exitCode{0};             // as ChildProcess::wait()
  std::string output;          // stdout and stderr together, in the order they arrived
  std::string standardOutput;  // stdout alone: what a program prints for other programs
};
// Runs a command to completion, collecting its output.
Result<CommandOutput> runCommand(const std::vector<std::string>& argv);

// Waits (up to 5 s) until `interface` (in `netns`, or here when empty) is operationally up with
// its real queueing discipline. `ip link set up` returns before the kernel's link watcher has
// seen the carrier; until then the qdisc is "noop" and every frame sent is dropped without an
// error (a test's first frame vanished this way on a busy CI machine).
Status waitOperational(const std::string& netns, const std::string& interface);

struct VethOptions {
  int mtu{1500};  // an MTU of 1500 carries the largest EtherCAT frame (1514 bytes)
  bool disableIpv6{true};
  // A second pair "ecm2-<random>" / "ecs2-<random>" in the same namespace: a redundant
  // master's second port and the simulator's end of it (cable redundancy).
  bool secondPair{false};
};

// A private network namespace "ecsim-<pid>-<random>" holding a veth pair "ecm-<random>"
// (the master's end) and "ecs-<random>" (the simulator's end), both up, with IPv6 disabled
// so that the kernel puts no frames of its own on them. Nothing is created outside the
// namespace. The destructor deletes the pair and the namespace. Move-only.
class VethNamespace {
 public:
  static Result<VethNamespace> create(const VethOptions& options = {});

  VethNamespace(VethNamespace&& other) noexcept;
  VethNamespace& operator=(VethNamespace&& other) noexcept;
  VethNamespace(const VethNamespace&) = delete;
  VethNamespace& operator=(const VethNamespace&) = delete;
  ~VethNamespace();

  const std::string& name() const { return name_; }
  const std::string& masterInterface() const { return masterInterface_; }
  const std::string& simulatorInterface() const { return simulatorInterface_; }
  // The second pair (VethOptions::secondPair); empty without.
  const std::string& secondMasterInterface() const { return secondMasterInterface_; }
  const std::string& secondSimulatorInterface() const { return secondSimulatorInterface_; }

  // Starts a program inside the namespace (`ip netns exec NAME argv...`); the returned pid is
  // the program's own.
  Result<ChildProcess> spawn(const std::vector<std::string>& argv,
                             const SpawnOptions& options = {}) const;
  // Runs a program inside the namespace to completion.
  Result<CommandOutput> run(const std::vector<std::string>& argv) const;

  // Deletes the pair and the namespace now (the destructor does it otherwise).
  Status destroy();

 private:
  VethNamespace() = default;

  std::string name_;
  std::string masterInterface_;
  std::string simulatorInterface_;
  std::string secondMasterInterface_;
  std::string secondSimulatorInterface_;
};

}  // namespace ecsim
