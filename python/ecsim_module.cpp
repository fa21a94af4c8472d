// The Python module `ecsim._ecsim` (re-exported by the package `ecsim`, docs/python.md): a
// simulated network in the Python process, its slaves seen from their PDI side, fault
// injection with the scenarios' action lines, our master in-process, and serving the network
// on an interface from a thread. An edge of the project: Result errors become exceptions here
// (kNotFound -> KeyError, kInvalidArgument/kParse -> ValueError, others -> RuntimeError, each
// with the error's text, which names the closest valid name where there is one).
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <pthread.h>
#include <sched.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "embed/simulated_network.hpp"
#include "embed/slave_variables.hpp"
#include "link/memory_link.hpp"
#include "link/netns.hpp"
#include "link/raw_socket_link.hpp"
#include "master/bus.hpp"
#include "master/master.hpp"
#include "master/variables.hpp"
#include "protocol/closest_name.hpp"
#include "protocol/sdo_info.hpp"
#include "topology/faults.hpp"
#include "topology/slave_names.hpp"

namespace py = pybind11;

namespace ecsim::python {
namespace {

constexpr std::size_t kLinkCapacity = 256;  // frames in flight per direction, in process
constexpr std::size_t kClosestListed = 3;

[[noreturn]] void raise(const Error& error) {
  switch (error.code) {
    case ErrorCode::kNotFound:
      throw py::key_error(error.context);
    case ErrorCode::kInvalidArgument:
    case ErrorCode::kParse:
      throw py::value_error(error.context);
    default:
      throw std::runtime_error(error.message());
  }
}
void check(const Status& status) {
  if (!status.ok()) raise(status.error());
}
template <typename T>
T take(Result<T> result) {
  if (!result.ok()) raise(result.error());
  return std::move(*result);
}

// "0x7000:03", as master/variables.cpp spells an entry's index in variable names.
std::string hexIndex(std::uint16_t index, std::uint8_t subindex) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%04X:%02X", static_cast<unsigned>(index),
                static_cast<unsigned>(subindex));
  return text;
}

// ---- values: the bits of an entry, typed as the master types its variables ------------------
master::VariableInfo valueInfo(std::uint16_t dataType, std::uint16_t bitLength) {
  master::VariableInfo info;
  info.bitLength = static_cast<std::uint8_t>(bitLength);
  info.dataType = dataType;
  info.type = master::variableType(dataType, info.bitLength);
  return info;
}
bool fitsValue(std::uint16_t bitLength) { return bitLength >= 1 && bitLength <= 64; }

py::object toPython(const master::PdoVariable& v) {
  switch (v.info().type) {
    case master::VariableType::kBool:
      return py::bool_(v.get<bool>());
    case master::VariableType::kReal32:
    case master::VariableType::kReal64:
      return py::float_(v.asDouble());
    case master::VariableType::kInt8:
    case master::VariableType::kInt16:
    case master::VariableType::kInt32:
    case master::VariableType::kInt64:
      return py::int_(v.get<std::int64_t>());
    default:
      return py::int_(v.raw());
  }
}
void fromPython(master::PdoVariable& v, const py::handle& value) {
  if (py::isinstance<py::bool_>(value)) {
    v.setRaw(value.cast<bool>() ? 1 : 0);
  } else if (py::isinstance<py::float_>(value)) {
    v.setDouble(value.cast<double>());
  } else if (py::isinstance<py::int_>(value)) {
    const bool isFloat = v.info().type == master::VariableType::kReal32 ||
                         v.info().type == master::VariableType::kReal64;
    if (isFloat) {
      v.setDouble(value.cast<double>());
    } else if (value.cast<py::int_>() < py::int_(0)) {
      v.setRaw(static_cast<std::uint64_t>(value.cast<std::int64_t>()));
    } else {
      v.setRaw(value.cast<std::uint64_t>());
    }
  } else {
    throw py::type_error("a value for '" + v.name() + "' must be a bool, int or float");
  }
}

// An entry's bytes as a Python value (bytes for entries wider than 64 bits: strings, arrays).
py::object entryValue(const slavesim::coe::Entry& entry) {
  if (!fitsValue(entry.bitLength)) return py::bytes(reinterpret_cast<const char*>(entry.value.data()), entry.value.size());
  std::vector<std::uint8_t> bytes = entry.value;
  master::PdoVariable v(valueInfo(entry.dataType, entry.bitLength), bytes);
  return toPython(v);
}
std::vector<std::uint8_t> entryBytes(const slavesim::coe::Entry& entry, const py::handle& value) {
  if (py::isinstance<py::bytes>(value)) {
    auto s = value.cast<std::string>();
    return {s.begin(), s.end()};
  }
  if (!fitsValue(entry.bitLength)) throw py::type_error("'" + entry.name + "' takes bytes");
  std::vector<std::uint8_t> bytes(entry.byteSize(), 0);
  master::PdoVariable v(valueInfo(entry.dataType, entry.bitLength), bytes);
  fromPython(v, value);
  return bytes;
}
py::bytes toBytes(const std::vector<std::uint8_t>& data) {
  return {reinterpret_cast<const char*>(data.data()), data.size()};
}
std::vector<std::uint8_t> fromBytes(const py::bytes& data) {
  auto s = data.cast<std::string>();
  return {s.begin(), s.end()};
}

class Network;

// One slave by name, PDI side. Every access holds the network's lock (serve() may run).
class Slave {
 public:
  Slave(std::shared_ptr<Network> net, embed::SimulatedSlave slave)
      : net_(std::move(net)), slave_(slave) {}
  std::string name() const { return slave_.name(); }
  std::size_t position() const { return slave_.position(); }
  std::string state();
  std::uint16_t alStatusCode();
  py::bytes readRegisters(std::uint16_t address, std::size_t length);
  void writeRegisters(std::uint16_t address, const py::bytes& data);
  py::object readEntry(std::uint16_t index, std::uint8_t subindex);
  void writeEntry(std::uint16_t index, std::uint8_t subindex, const py::handle& value);
  py::object get(const std::string& name);
  void set(const std::string& name, const py::handle& value);
  std::vector<std::string> names();

 private:
  struct Named {
    std::string name;
    std::uint16_t index;
    std::uint8_t subindex;
  };
  std::vector<Named> processEntries();
  Named find(const std::string& name);
  const slavesim::coe::Entry& entry(std::uint16_t index, std::uint8_t subindex);

  std::shared_ptr<Network> net_;
  embed::SimulatedSlave slave_;
};

// Serving on an interface: a thread runs SimulatedNetwork::serve until close().
class Serving {
 public:
  // rtPriority > 0: the thread runs SCHED_FIFO at it (as `ecsim serve --rt`), so that answers
  // come within a master's timeout on a loaded host; refused, a note on stderr.
  Serving(std::shared_ptr<Network> net, std::unique_ptr<RawSocketLink> link, int rtPriority);
  ~Serving() {
    if (thread_.joinable()) (void)join();
  }
  void close() { check(join()); }
  std::string interfaceName() const { return link_->interfaceName(); }

 private:
  std::shared_ptr<Network> net_;
  std::unique_ptr<RawSocketLink> link_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  Status status_;
  Status join();
};

class Network : public std::enable_shared_from_this<Network> {
 public:
  Network(const std::string& topology, bool realTime) {
    embed::NetworkOptions options;
    options.time = realTime ? embed::TimeMode::kRealTime : embed::TimeMode::kVirtual;
    net_ = take(embed::SimulatedNetwork::fromTopologyFile(topology, options));
  }
  ~Network() {
    faults_.reset();  // uninstalls itself from the segment
  }

  embed::SimulatedNetwork& sim() { return *net_; }
  // The network's lock for an access from Python. SimulatedNetwork::serve takes the lock again
  // right after each step, and a std::mutex is not fair: a thread that only waits for it can
  // wait for seconds. So a waiter says so, and the serving thread lets it in between steps.
  std::unique_lock<std::mutex> lock() {
    ++waiting_;
    auto guard = net_->lock();
    --waiting_;
    return guard;
  }
  // The serving thread, between two steps: sleeps while an access waits for the lock.
  void letWaitersIn() const {
    while (waiting_.load() > 0) std::this_thread::sleep_for(std::chrono::microseconds(20));
  }
  bool serving() const { return serving_; }
  void setServing(bool on) { serving_ = on; }

  void runFor(double ms) {
    requireIdle("run_for");
    py::gil_scoped_release release;
    check(net_->runFor(static_cast<SimTime>(ms * static_cast<double>(kNsPerMs))));
  }
  void step() {
    requireIdle("step");
    check(net_->step());
  }
  SimTime now() { return net_->now(); }
  std::size_t slaveCount() const { return net_->slaveCount(); }
  std::vector<std::string> slaveNames() { return topology::slaveNamesInBusOrder(net_->segment()); }

  Slave slave(const py::object& which) {
    if (py::isinstance<py::int_>(which)) {
      return {shared_from_this(), take(net_->slave(which.cast<std::size_t>()))};
    }
    return {shared_from_this(), take(net_->slave(which.cast<std::string>()))};
  }

  // A scenario action line, applied now ("link-down cable=drives"; topology/faults.hpp).
  std::string fault(const std::string& line) {
    auto guard = lock();
    auto fault = topology::parseFaultLine(line);
    if (!fault.ok()) throw py::value_error(fault.error().context);
    if (!faults_) faults_ = std::make_unique<topology::FaultInjector>(net_->network(), seed_);
    auto done = faults_->apply(*fault, net_->now(), "python");
    if (!done.ok()) raise(done.error());
    return *done;
  }

  std::unique_ptr<Serving> serve(const std::string& iface, const std::string& netns,
                                 int rtPriority) {
    if (net_->options().time != embed::TimeMode::kRealTime) {
      throw std::runtime_error("serve: the network runs on virtual time; make it with "
                               "ecsim.Network(path, real_time=True)");
    }
    requireIdle("serve");
    RawSocketOptions options;
    options.netns = netns;
    auto link = std::make_unique<RawSocketLink>(take(RawSocketLink::open(iface, options)));
    return std::make_unique<Serving>(shared_from_this(), std::move(link), rtPriority);
  }

  void requireIdle(const char* what) const {
    if (serving_) throw std::runtime_error(std::string(what) + ": the network is being served");
  }

 private:
  std::unique_ptr<embed::SimulatedNetwork> net_;
  std::unique_ptr<topology::FaultInjector> faults_;
  std::uint64_t seed_{1};
  bool serving_{false};
  std::atomic<int> waiting_{0};
};

Serving::Serving(std::shared_ptr<Network> net, std::unique_ptr<RawSocketLink> link,
                 int rtPriority)
    : net_(std::move(net)), link_(std::move(link)) {
  net_->sim().attach(*link_);
  net_->setServing(true);
  thread_ = std::thread([this, rtPriority] {
    if (rtPriority > 0) {
      sched_param param{};
      param.sched_priority = rtPriority;
      if (const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param); rc != 0) {
        std::fprintf(stderr, "ecsim: serve: SCHED_FIFO %d not permitted (%s)\n", rtPriority,
                     std::strerror(rc));
      }
    }
    status_ = net_->sim().serve([this] {
      net_->letWaitersIn();
      return stop_.load();
    });
  });
}
Status Serving::join() {
  if (!thread_.joinable()) return okStatus();
  stop_ = true;
  {
    py::gil_scoped_release release;
    thread_.join();
  }
  net_->sim().detach();
  net_->setServing(false);
  return status_;
}

std::string Slave::state() {
  auto guard = net_->lock();
  return std::string(toString(slave_.state()));
}
std::uint16_t Slave::alStatusCode() {
  auto guard = net_->lock();
  return slave_.alStatusCode();
}
py::bytes Slave::readRegisters(std::uint16_t address, std::size_t length) {
  auto guard = net_->lock();
  return toBytes(take(slave_.readRegisters(address, length)));
}
void Slave::writeRegisters(std::uint16_t address, const py::bytes& data) {
  auto bytes = fromBytes(data);
  auto guard = net_->lock();
  check(slave_.writeRegisters(address, bytes));
}
const slavesim::coe::Entry& Slave::entry(std::uint16_t index, std::uint8_t subindex) {
  const auto* od = slave_.dictionary();
  if (od == nullptr) throw std::runtime_error("slave '" + name() + "' has no object dictionary");
  const auto* e = od->findEntry(index, subindex);
  if (e == nullptr) {
    throw py::key_error("slave '" + name() + "' has no object " + hexIndex(index, subindex));
  }
  return *e;
}
py::object Slave::readEntry(std::uint16_t index, std::uint8_t subindex) {
  auto guard = net_->lock();
  return entryValue(entry(index, subindex));
}
void Slave::writeEntry(std::uint16_t index, std::uint8_t subindex, const py::handle& value) {
  auto guard = net_->lock();
  auto bytes = entryBytes(entry(index, subindex), value);
  check(slave_.writeEntry(index, subindex, bytes));
}

// The entries the slave's current PDO mapping maps, named as a master names them and as
// `ecsim ctl get` does (embed/slave_variables.hpp: one naming rule), and always as
// "0xIIII:SS". Called with the lock.
std::vector<Slave::Named> Slave::processEntries() {
  if (slave_.dictionary() == nullptr) {
    throw std::runtime_error("slave '" + name() + "' has no process data");
  }
  auto& segment = net_->sim().segment();
  const auto order = topology::busOrder(segment);
  std::size_t bus = order.size();
  for (std::size_t p = 0; p < order.size(); ++p) {
    if (order[p] == slave_.position()) bus = p;
  }
  std::vector<Named> out;
  for (auto& v : embed::slaveVariables(segment)) {
    if (v.position == bus) out.push_back({std::move(v.entry), v.index, v.subindex});
  }
  return out;
}
Slave::Named Slave::find(const std::string& name) {
  auto entries = processEntries();
  for (const auto& n : entries) {
    if (n.name == name || hexIndex(n.index, n.subindex) == name) return n;
  }
  std::vector<std::string_view> names;
  for (const auto& n : entries) names.push_back(n.name);
  std::string hint;
  for (auto close : closestNames(name, names, kClosestListed)) {
    hint += (hint.empty() ? "; closest: " : ", ") + std::string(close);
  }
  throw py::key_error("slave '" + this->name() + "' maps no process-data entry '" + name + "'" +
                      hint);
}
py::object Slave::get(const std::string& name) {
  auto guard = net_->lock();
  auto n = find(name);
  return entryValue(entry(n.index, n.subindex));
}
void Slave::set(const std::string& name, const py::handle& value) {
  auto guard = net_->lock();
  auto n = find(name);
  auto bytes = entryBytes(entry(n.index, n.subindex), value);
  check(slave_.writeEntry(n.index, n.subindex, bytes));
}
std::vector<std::string> Slave::names() {
  auto guard = net_->lock();
  std::vector<std::string> out;
  for (const auto& n : processEntries()) out.push_back(n.name);
  return out;
}

// Our master on the network, in process on virtual time (as embed/testing/network_fixture.hpp
// pairs them): a MemoryLink between them, the master's VirtualBus serving the network.
class Master {
 public:
  Master(std::shared_ptr<Network> net, double cycleMs, const std::optional<std::string>& config)
      : net_(std::move(net)) {
    auto& sim = net_->sim();
    if (sim.virtualClock() == nullptr) {
      throw std::runtime_error("ecsim.Master runs in process on virtual time: make the network "
                               "with ecsim.Network(path) (real_time=False)");
    }
    net_->requireIdle("Master");
    auto [masterEnd, networkEnd] = MemoryLink::makePair(kLinkCapacity);
    masterLink_ = std::make_unique<MemoryLink>(std::move(masterEnd));
    networkLink_ = std::make_unique<MemoryLink>(std::move(networkEnd));
    sim.attach(*networkLink_);
    embed::SimulatedNetwork* s = &sim;
    bus_ = std::make_unique<master::VirtualBus>(*sim.virtualClock(),
                                                [s](SimTime) { return s->serveOne(); });
    master::MasterOptions options;
    period_ = static_cast<SimTime>(cycleMs * static_cast<double>(kNsPerMs));
    options.cycleTime = period_;
    master_ = std::make_unique<master::Master>(*masterLink_, *bus_, options);
    master_->setSlaveNames(topology::slaveNamesInBusOrder(sim.segment()));
    if (config) check(master_->loadConfig(*config));
  }
  ~Master() {
    master_.reset();
    net_->sim().detach();
  }

  void start() { check(master_->start()); }
  void stop() { check(master_->stop()); }
  // One cycle, then the network runs until a cycle time has passed since it began.
  void cycle(bool raiseOnError) {
    const SimTime begin = net_->sim().now();
    Status s = master_->cycle();
    const SimTime used = net_->sim().now() - begin;
    if (used < period_) check(net_->sim().runFor(period_ - used));
    if (raiseOnError) check(s);
  }
  py::object get(const std::string& name) { return toPython(take(master_->variable(name))); }
  void set(const std::string& name, const py::handle& value) {
    auto v = take(master_->variable(name));
    fromPython(v, value);
  }
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const auto& v : master_->variables()) out.push_back(v.name);
    return out;
  }
  py::bytes sdoRead(std::size_t position, std::uint16_t index, std::uint8_t subindex) {
    return toBytes(take(master_->sdoUpload(position, index, subindex)));
  }
  void sdoWrite(std::size_t position, std::uint16_t index, std::uint8_t subindex,
                const py::bytes& data) {
    auto bytes = fromBytes(data);
    check(master_->sdoDownload(position, index, subindex, bytes));
  }
  std::vector<std::string> events() const {
    std::vector<std::string> out;
    for (const auto& e : master_->events()) out.push_back(e.text);
    return out;
  }
  void clearEvents() { master_->clearEvents(); }

 private:
  std::shared_ptr<Network> net_;
  std::unique_ptr<MemoryLink> masterLink_;
  std::unique_ptr<MemoryLink> networkLink_;
  std::unique_ptr<master::Bus> bus_;
  std::unique_ptr<master::Master> master_;
  SimTime period_{kNsPerMs};
};

// A private network namespace with a veth pair (link/netns.hpp), deleted by close().
class Veth {
 public:
  Veth() : ns_(take(VethNamespace::create())) {}
  const VethNamespace& ns() const {
    if (!ns_) throw std::runtime_error("the veth namespace is closed");
    return *ns_;
  }
  void close() {
    if (ns_) {
      Status s = ns_->destroy();
      ns_.reset();
      check(s);
    }
  }

 private:
  std::optional<VethNamespace> ns_;
};

}  // namespace
}  // namespace ecsim::python

PYBIND11_MODULE(_ecsim, m) {
  using namespace ecsim::python;  // NOLINT: the module's classes
  m.doc() = "ecsim: a simulated EtherCAT network (docs/python.md)";

  py::class_<Slave>(m, "Slave")
      .def_property_readonly("name", &Slave::name)
      .def_property_readonly("position", &Slave::position)
      .def_property_readonly("state", &Slave::state)
      .def_property_readonly("al_status_code", &Slave::alStatusCode)
      .def("read_registers", &Slave::readRegisters, py::arg("address"), py::arg("length"))
      .def("write_registers", &Slave::writeRegisters, py::arg("address"), py::arg("data"))
      .def("read_entry", &Slave::readEntry, py::arg("index"), py::arg("subindex"))
      .def("write_entry", &Slave::writeEntry, py::arg("index"), py::arg("subindex"),
           py::arg("value"))
      .def("entries", &Slave::names)
      .def("__getitem__", &Slave::get)
      .def("__setitem__", &Slave::set);

  py::class_<Serving>(m, "Serving")
      .def_property_readonly("iface", &Serving::interfaceName)
      .def("close", &Serving::close)
      .def("__enter__", [](Serving& s) -> Serving& { return s; }, py::return_value_policy::reference)
      .def("__exit__", [](Serving& s, const py::args&) { s.close(); });

  py::class_<Network, std::shared_ptr<Network>>(m, "Network")
      .def(py::init<const std::string&, bool>(), py::arg("topology"), py::arg("real_time") = false)
      .def("run_for", &Network::runFor, py::arg("ms"))
      .def("step", &Network::step)
      .def_property_readonly("now_ns", &Network::now)
      .def_property_readonly("slave_count", &Network::slaveCount)
      .def("slave_names", &Network::slaveNames)
      .def("slave", &Network::slave, py::arg("name"))
      .def("fault", &Network::fault, py::arg("action"))
      .def_static("fault_verbs",
                  [] {
                    std::vector<std::string> out;
                    for (auto v : ecsim::topology::faultVerbs()) out.emplace_back(v);
                    return out;
                  })
      .def("serve", &Network::serve, py::arg("iface"), py::arg("netns") = "",
           py::arg("rt_priority") = 0);

  py::class_<Master>(m, "Master")
      .def(py::init([](std::shared_ptr<Network> net, double cycleMs,
                       std::optional<std::string> config) {
             return std::make_unique<Master>(std::move(net), cycleMs, config);
           }),
           py::arg("network"), py::arg("cycle_ms") = 1.0, py::arg("config") = py::none())
      .def("start", &Master::start)
      .def("stop", &Master::stop)
      .def("cycle", &Master::cycle, py::arg("check") = false)
      .def("__getitem__", &Master::get)
      .def("__setitem__", &Master::set)
      .def("variables", &Master::names)
      .def("sdo_read", &Master::sdoRead, py::arg("position"), py::arg("index"),
           py::arg("subindex"))
      .def("sdo_write", &Master::sdoWrite, py::arg("position"), py::arg("index"),
           py::arg("subindex"), py::arg("data"))
      .def_property_readonly("events", &Master::events)
      .def("clear_events", &Master::clearEvents);

  py::class_<Veth>(m, "VethNamespace")
      .def(py::init<>())
      .def_property_readonly("name", [](const Veth& v) { return v.ns().name(); })
      .def_property_readonly("master_iface", [](const Veth& v) { return v.ns().masterInterface(); })
      .def_property_readonly("simulator_iface",
                             [](const Veth& v) { return v.ns().simulatorInterface(); })
      .def("close", &Veth::close)
      .def("__enter__", [](Veth& v) -> Veth& { return v; }, py::return_value_policy::reference)
      .def("__exit__", [](Veth& v, const py::args&) { v.close(); });
}
