#include "link/netns.hpp"

#include <fcntl.h>
#include <linux/capability.h>
#include <poll.h>
#include <sched.h>
#include <spawn.h>
#include <sys/random.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <thread>
#include <utility>

#include "link/fd.hpp"
#include "link/net_namespace.hpp"

namespace ecsim {
namespace {

bool hasCapability(const std::array<__user_cap_data_struct, 2>& data, unsigned capability) {
  return (data[capability / 32].effective & (1u << (capability % 32))) != 0;
}

std::string joinCommand(const std::vector<std::string>& argv) {
  std::string s;
  for (const auto& arg : argv) {
    if (!s.empty()) s += ' ';
    s += arg;
  }
  return s;
}

int decodeWaitStatus(int status) {
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

// posix_spawn file actions and attributes, released on scope exit.
class SpawnSetup {
 public:
  SpawnSetup() {
    posix_spawn_file_actions_init(&actions_);
    posix_spawnattr_init(&attributes_);
    // Own process group (so kill() reaches grandchildren), an empty signal mask and default
    // dispositions for the signals a test harness might have changed.
    posix_spawnattr_setflags(
        &attributes_,
        static_cast<short>(POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF));
    posix_spawnattr_setpgroup(&attributes_, 0);
    sigset_t none;
    sigemptyset(&none);
    posix_spawnattr_setsigmask(&attributes_, &none);
    sigset_t defaults;
    sigemptyset(&defaults);
    for (int sig : {SIGINT, SIGTERM, SIGPIPE, SIGHUP, SIGQUIT}) sigaddset(&defaults, sig);
    posix_spawnattr_setsigdefault(&attributes_, &defaults);
    posix_spawn_file_actions_addopen(&actions_, 0, "/dev/null", O_RDONLY, 0);
  }
  SpawnSetup(const SpawnSetup&) = delete;
  SpawnSetup& operator=(const SpawnSetup&) = delete;
  ~SpawnSetup() {
    posix_spawn_file_actions_destroy(&actions_);
    posix_spawnattr_destroy(&attributes_);
  }

  void openFile(int fd, const std::string& path) {
    posix_spawn_file_actions_addopen(&actions_, fd, path.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
  }
  void duplicate(int from, int to) { posix_spawn_file_actions_adddup2(&actions_, from, to); }
  void fifo(int priority) {
    short flags = 0;
    posix_spawnattr_getflags(&attributes_, &flags);
    posix_spawnattr_setflags(&attributes_, static_cast<short>(flags | POSIX_SPAWN_SETSCHEDULER));
    posix_spawnattr_setschedpolicy(&attributes_, SCHED_FIFO);
    sched_param param{};
    param.sched_priority = priority;
    posix_spawnattr_setschedparam(&attributes_, &param);
  }

  Result<pid_t> spawn(const std::vector<std::string>& argv) {
    if (argv.empty()) return makeError(ErrorCode::kInvalidArgument, "empty command line");
    std::vector<char*> args;
    args.reserve(argv.size() + 1);
    for (const auto& arg : argv) args.push_back(const_cast<char*>(arg.c_str()));
    args.push_back(nullptr);
    pid_t pid = -1;
    const int rc = ::posix_spawnp(&pid, args[0], &actions_, &attributes_, args.data(), environ);
    if (rc == ENOENT) {
      return makeError(ErrorCode::kNotFound, "program '" + argv[0] + "' not found in PATH");
    }
    if (rc != 0) {
      return makeError(ErrorCode::kIo, "starting '" + joinCommand(argv) + "': " + errnoText(rc));
    }
    return pid;
  }

 private:
  posix_spawn_file_actions_t actions_{};
  posix_spawnattr_t attributes_{};
};

Status writeProcFile(const std::string& path, const std::string& value) {
  UniqueFd fd(::open(path.c_str(), O_WRONLY | O_CLOEXEC));
  if (!fd.valid()) return makeError(ErrorCode::kIo, "opening " + path + ": " + errnoText(errno));
  if (::write(fd.get(), value.data(), value.size()) != static_cast<ssize_t>(value.size())) {
    return makeError(ErrorCode::kIo, "writing " + path + ": " + errnoText(errno));
  }
  return okStatus();
}

Status runIp(const std::vector<std::string>& argv) {
  ECSIM_ASSIGN_OR_RETURN(CommandOutput out, runCommand(argv));
  if (out.exitCode != 0) {
    return makeError(ErrorCode::kIo, "'" + joinCommand(argv) + "' failed with status " +
                                         std::to_string(out.exitCode) + ": " + out.output);
  }
  return okStatus();
}

std::string randomSuffix() {
  std::uint32_t value = 0;
  if (::getrandom(&value, sizeof value, 0) != static_cast<ssize_t>(sizeof value)) {
    value = static_cast<std::uint32_t>(std::chrono::steady_clock::now().time_since_epoch().count());
  }
  char text[9];
  std::snprintf(text, sizeof text, "%08x", value);
  return text;
}

}  // namespace

NetworkCapabilities networkCapabilities() {
  __user_cap_header_struct header{};
  header.version = _LINUX_CAPABILITY_VERSION_3;
  header.pid = 0;
  std::array<__user_cap_data_struct, 2> data{};
  NetworkCapabilities caps;
  if (::syscall(SYS_capget, &header, data.data()) != 0) return caps;
  caps.netAdmin = hasCapability(data, CAP_NET_ADMIN);
  caps.netRaw = hasCapability(data, CAP_NET_RAW);
  caps.sysAdmin = hasCapability(data, CAP_SYS_ADMIN);
  return caps;
}

bool hasNetAdminCapability() {
  return networkCapabilities().netAdmin;
}

Status checkNetworkCapabilities() {
  const NetworkCapabilities caps = networkCapabilities();
  std::string missing;
  if (!caps.netAdmin) missing += " CAP_NET_ADMIN";
  if (!caps.netRaw) missing += " CAP_NET_RAW";
  if (!caps.sysAdmin) missing += " CAP_SYS_ADMIN";
  if (missing.empty()) return okStatus();
  return makeError(ErrorCode::kPermission,
                   "network namespaces, veth pairs and raw sockets need" + missing +
                       " (run as root, e.g. with sudo, or in a privileged container)");
}

ChildProcess::ChildProcess(ChildProcess&& other) noexcept
    : pid_(std::exchange(other.pid_, -1)), reaped_(other.reaped_), status_(other.status_) {}

ChildProcess& ChildProcess::operator=(ChildProcess&& other) noexcept {
  if (this != &other) {
    if (pid_ > 0 && !reaped_) (void)stop();
    pid_ = std::exchange(other.pid_, -1);
    reaped_ = other.reaped_;
    status_ = other.status_;
  }
  return *this;
}

ChildProcess::~ChildProcess() {
  if (pid_ > 0 && !reaped_) (void)stop(std::chrono::milliseconds(500));
}

bool ChildProcess::running() {
  if (pid_ <= 0 || reaped_) return false;
  auto result = wait(std::chrono::nanoseconds::zero());
  return !result.ok() && result.error().code == ErrorCode::kTimeout;
}

Result<int> ChildProcess::wait(std::chrono::nanoseconds timeout) {
  if (pid_ <= 0) return makeError(ErrorCode::kState, "no child process");
  if (reaped_) return decodeWaitStatus(status_);
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    int status = 0;
    const pid_t rc = ::waitpid(pid_, &status, WNOHANG);
    if (rc == pid_) {
      reaped_ = true;
      status_ = status;
      return decodeWaitStatus(status);
    }
    if (rc < 0 && errno != EINTR) {
      return makeError(ErrorCode::kIo,
                       "waitpid for process " + std::to_string(pid_) + ": " + errnoText(errno));
    }
    const auto now = std::chrono::steady_clock::now();
    if (now >= deadline) {
      return makeError(ErrorCode::kTimeout,
                       "process " + std::to_string(pid_) + " is still running");
    }
    std::this_thread::sleep_for(
        std::min<std::chrono::nanoseconds>(deadline - now, std::chrono::milliseconds(1)));
  }
}

Status ChildProcess::kill(int signal) {
  if (pid_ <= 0 || reaped_) {
    return makeError(ErrorCode::kState, "process " + std::to_string(pid_) + " has ended");
  }
  if (::kill(-pid_, signal) == 0 || ::kill(pid_, signal) == 0) return okStatus();
  return makeError(ErrorCode::kIo,
                   "signalling process " + std::to_string(pid_) + ": " + errnoText(errno));
}

Result<int> ChildProcess::stop(std::chrono::nanoseconds grace) {
  if (pid_ > 0 && !reaped_) {
    (void)kill(SIGTERM);
    auto status = wait(grace);
    if (status.ok()) return status;
    (void)kill(SIGKILL);
  }
  return wait(std::chrono::seconds(5));
}

Result<ChildProcess> spawnProcess(const std::vector<std::string>& argv,
                                  const SpawnOptions& options) {
  SpawnSetup setup;
  if (!options.stdoutPath.empty()) setup.openFile(1, options.stdoutPath);
  if (!options.stderrPath.empty()) {
    if (options.stderrPath == options.stdoutPath) {
      setup.duplicate(1, 2);
    } else {
      setup.openFile(2, options.stderrPath);
    }
  }
  if (options.fifoPriority > 0) setup.fifo(options.fifoPriority);
  ECSIM_ASSIGN_OR_RETURN(pid_t pid, setup.spawn(argv));
  return ChildProcess(pid);
}

Result<CommandOutput> runCommand(const std::vector<std::string>& argv) {
  // One pipe per stream, so that a program's notes on stderr never stand inside what it
  // prints on stdout for another program (JSON, a list): `output` keeps both, as a terminal
  // would show them.
  std::array<UniqueFd, 2> readEnds;
  SpawnSetup setup;
  std::array<UniqueFd, 2> writeEnds;
  for (std::size_t i = 0; i < readEnds.size(); ++i) {
    std::array<int, 2> pipeFds{-1, -1};
    if (::pipe2(pipeFds.data(), O_CLOEXEC) != 0) {
      return makeError(ErrorCode::kIo, "pipe for '" + joinCommand(argv) + "': " + errnoText(errno));
    }
    readEnds[i] = UniqueFd(pipeFds[0]);
    writeEnds[i] = UniqueFd(pipeFds[1]);
    setup.duplicate(writeEnds[i].get(), static_cast<int>(i) + 1);
  }
  ECSIM_ASSIGN_OR_RETURN(pid_t pid, setup.spawn(argv));
  ChildProcess child(pid);
  for (auto& end : writeEnds) end.reset();
  CommandOutput result;
  std::array<pollfd, 2> fds{pollfd{readEnds[0].get(), POLLIN, 0},
                            pollfd{readEnds[1].get(), POLLIN, 0}};
  std::array<char, 4096> chunk{};
  while (fds[0].fd >= 0 || fds[1].fd >= 0) {
    if (::poll(fds.data(), fds.size(), -1) < 0) {
      if (errno == EINTR) continue;
      break;
    }
    for (std::size_t i = 0; i < fds.size(); ++i) {
      if (fds[i].fd < 0 || fds[i].revents == 0) continue;
      const ssize_t n = ::read(fds[i].fd, chunk.data(), chunk.size());
      if (n > 0) {
        result.output.append(chunk.data(), static_cast<std::size_t>(n));
        if (i == 0) result.standardOutput.append(chunk.data(), static_cast<std::size_t>(n));
      } else if (n == 0 || errno != EINTR) {
        fds[i].fd = -1;  // poll skips a negative descriptor
      }
    }
  }
  ECSIM_ASSIGN_OR_RETURN(result.exitCode, child.wait(std::chrono::seconds(30)));
  return result;
}

Status waitOperational(const std::string& netns, const std::string& interface) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  std::string last;
  for (;;) {
    std::vector<std::string> argv{"ip"};
    if (!netns.empty()) argv.insert(argv.end(), {"-n", netns});
    argv.insert(argv.end(), {"-o", "link", "show", interface});
    auto out = runCommand(argv);
    if (out.ok() && out->exitCode == 0) {
      last = out->output;
      if (last.find("state UP") != std::string::npos &&
          last.find("qdisc noop") == std::string::npos) {
        return okStatus();
      }
    }
    if (std::chrono::steady_clock::now() >= deadline) {
      return makeError(ErrorCode::kTimeout,
                       interface + (netns.empty() ? "" : " in network namespace " + netns) +
                           " not operational after 5 s: " + last);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

Result<VethNamespace> VethNamespace::create(const VethOptions& options) {
  ECSIM_TRY(checkNetworkCapabilities());
  const std::string suffix = randomSuffix();
  VethNamespace ns;
  const std::string name = "ecsim-" + std::to_string(::getpid()) + "-" + suffix;
  ECSIM_TRY(runIp({"ip", "netns", "add", name}));
  ns.name_ = name;  // from here on the destructor removes what exists
  ns.masterInterface_ = "ecm-" + suffix;
  ns.simulatorInterface_ = "ecs-" + suffix;

  const std::string ipv6Conf = "/proc/sys/net/ipv6/conf/";
  const bool ipv6 = options.disableIpv6 && ::access("/proc/sys/net/ipv6", F_OK) == 0;
  if (ipv6) {
    // Interfaces created afterwards inherit "default".
    ECSIM_TRY(runInNetworkNamespace(
        name, [&] { return writeProcFile(ipv6Conf + "default/disable_ipv6", "1"); }));
  }
  const std::string mtu = std::to_string(options.mtu);
  const auto addPair = [&](const std::string& master, const std::string& simulator) -> Status {
    ECSIM_TRY(runIp({"ip", "-n", name, "link", "add", master, "mtu", mtu, "type", "veth", "peer",
                     "name", simulator, "mtu", mtu}));
    if (ipv6) {
      ECSIM_TRY(runInNetworkNamespace(name, [&]() -> Status {
        Status first = writeProcFile(ipv6Conf + master + "/disable_ipv6", "1");
        if (!first.ok()) return first;
        return writeProcFile(ipv6Conf + simulator + "/disable_ipv6", "1");
      }));
    }
    ECSIM_TRY(runIp({"ip", "-n", name, "link", "set", master, "up"}));
    ECSIM_TRY(runIp({"ip", "-n", name, "link", "set", simulator, "up"}));
    ECSIM_TRY(waitOperational(name, master));
    return waitOperational(name, simulator);
  };
  ECSIM_TRY(runIp({"ip", "-n", name, "link", "set", "lo", "up"}));
  ECSIM_TRY(addPair(ns.masterInterface_, ns.simulatorInterface_));
  if (options.secondPair) {
    ns.secondMasterInterface_ = "ecm2-" + suffix;
    ns.secondSimulatorInterface_ = "ecs2-" + suffix;
    ECSIM_TRY(addPair(ns.secondMasterInterface_, ns.secondSimulatorInterface_));
  }
  return ns;
}

VethNamespace::VethNamespace(VethNamespace&& other) noexcept
    : name_(std::exchange(other.name_, {})),
      masterInterface_(std::exchange(other.masterInterface_, {})),
      simulatorInterface_(std::exchange(other.simulatorInterface_, {})),
      secondMasterInterface_(std::exchange(other.secondMasterInterface_, {})),
      secondSimulatorInterface_(std::exchange(other.secondSimulatorInterface_, {})) {}

VethNamespace& VethNamespace::operator=(VethNamespace&& other) noexcept {
  if (this != &other) {
    (void)destroy();
    name_ = std::exchange(other.name_, {});
    masterInterface_ = std::exchange(other.masterInterface_, {});
    simulatorInterface_ = std::exchange(other.simulatorInterface_, {});
    secondMasterInterface_ = std::exchange(other.secondMasterInterface_, {});
    secondSimulatorInterface_ = std::exchange(other.secondSimulatorInterface_, {});
  }
  return *this;
}

VethNamespace::~VethNamespace() {
  (void)destroy();
}

Status VethNamespace::destroy() {
  if (name_.empty()) return okStatus();
  // Deleting one end removes the pair at once; namespace clean-up in the kernel is
  // asynchronous, so the pair would otherwise outlive `ip netns del` for a moment.
  (void)runIp({"ip", "-n", name_, "link", "del", masterInterface_});
  if (!secondMasterInterface_.empty()) {
    (void)runIp({"ip", "-n", name_, "link", "del", secondMasterInterface_});
  }
  Status status = runIp({"ip", "netns", "del", name_});
  name_.clear();
  return status;
}

Result<ChildProcess> VethNamespace::spawn(const std::vector<std::string>& argv,
                                          const SpawnOptions& options) const {
  std::vector<std::string> full{"ip", "netns", "exec", name_};
  full.insert(full.end(), argv.begin(), argv.end());
  return spawnProcess(full, options);
}

Result<CommandOutput> VethNamespace::run(const std::vector<std::string>& argv) const {
  std::vector<std::string> full{"ip", "netns", "exec", name_};
  full.insert(full.end(), argv.begin(), argv.end());
  return runCommand(full);
}

}  // namespace ecsim
