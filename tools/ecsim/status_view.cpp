#include "tools/ecsim/status_view.hpp"

#include <fmt/core.h>

#include <cstdio>
#include <fstream>
#include <system_error>

#include "embed/slave_variables.hpp"
#include "protocol/registers.hpp"
#include "slavesim/coe/data_types.hpp"
#include "slavesim/esi_slave.hpp"
#include "topology/slave_names.hpp"

namespace ecsim::tools {
namespace {

constexpr std::uint16_t kAlStatusErrorFlag = reg::al::kErrorFlag;

std::string jsonString(std::string_view text) {
  std::string out = "\"";
  for (char c : text) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          out += fmt::format("\\u{:04x}", static_cast<unsigned>(c));
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

std::string stateText(const SlaveStatus& s) {
  std::string text(toString(s.state));
  if (s.alError) text += "+ERR";
  return text;
}

std::string valuesText(const SlaveStatus& s) {
  std::string out;
  for (std::size_t i = 0; i < s.values.size() && i < kTableValues; ++i) {
    const auto& v = s.values[i];
    if (!out.empty()) out += ' ';
    out += fmt::format("{}{:04X}:{:02X}={}", v.output ? '>' : '<', v.index, v.subindex, v.value);
  }
  return out;
}

double micros(SimTime ns) {
  return static_cast<double>(ns) / 1e3;
}

}  // namespace

std::int64_t decodeSystemTimeDifference(std::uint32_t raw) {
  const auto magnitude = static_cast<std::int64_t>(raw & 0x7FFFFFFFu);
  return (raw & 0x80000000u) != 0 ? -magnitude : magnitude;
}

StatusSnapshot takeStatusSnapshot(topology::Segment& segment,
                                  const topology::ServerCounters& counters, SimTime uptime,
                                  double framesPerSecond, std::size_t maxValues) {
  StatusSnapshot snap;
  snap.uptime = uptime;
  snap.framesReceived = counters.framesReceived;
  snap.framesAnswered = counters.framesAnswered;
  snap.framesDropped = counters.framesDropped;
  snap.framesLost = counters.framesLost;
  snap.receiveErrors = counters.receiveErrors;
  snap.sendErrors = counters.sendErrors;
  snap.framesPerSecond = framesPerSecond;
  snap.lastRoundTrip = counters.lastRoundTrip;
  // Named as the control socket and a master name them, in bus order.
  const std::vector<master::VariableInfo> variables = embed::slaveVariables(segment);
  const std::vector<std::size_t> order = topology::busOrder(segment);
  for (std::size_t i = 0; i < segment.size(); ++i) {
    slavesim::Slave& slave = segment.slave(i);
    const slavesim::Esc& esc = slave.esc();
    SlaveStatus s;
    s.name = slave.name();
    s.state = slave.state();
    s.alError = (esc.alStatus() & kAlStatusErrorFlag) != 0;
    s.alStatusCode = esc.read(reg::kAlStatusCode);
    s.frames = segment.framesSeen(i);
    s.datagrams = esc.counters().datagramsAddressed;
    for (unsigned port = 0; port < topology::kPortCount; ++port) {
      s.rxErrors += esc.reg8(reg::rxErrorCounters(port));
      s.rxErrors += esc.reg8(static_cast<std::uint16_t>(reg::rxErrorCounters(port) + 1));
      s.rxErrors += esc.reg8(reg::forwardedRxErrorCounter(port));
      s.lostLinks += esc.reg8(reg::lostLinkCounter(port));
    }
    s.dcDifferenceNs = decodeSystemTimeDifference(esc.read(reg::kSystemTimeDifference));
    if (auto* device = slavesim::processDataDeviceOf(slave)) {
      const auto& od = device->dictionary();
      for (const auto& v : variables) {
        if (v.position >= order.size() || order[v.position] != i) continue;
        if (s.values.size() >= maxValues) break;
        const auto* e = od.findEntry(v.index, v.subindex);
        if (e == nullptr) continue;
        std::int64_t value = 0;
        if (slavesim::coe::isRealType(e->dataType)) {
          value = static_cast<std::int64_t>(od.getOr<double>(v.index, v.subindex, 0.0));
        } else if (slavesim::coe::isSignedType(e->dataType)) {
          value = od.getOr<std::int64_t>(v.index, v.subindex, 0);
        } else {  // BOOL, BITn, UNSIGNEDn: never sign-extended
          value = static_cast<std::int64_t>(od.getOr<std::uint64_t>(v.index, v.subindex, 0));
        }
        s.values.push_back({v.name, v.index, v.subindex, v.output, value});
      }
    }
    snap.slaves.push_back(std::move(s));
  }
  return snap;
}

std::string formatStatusTable(const StatusSnapshot& snap) {
  std::string out = fmt::format(
      "ecsim serve  up {:.1f} s  frames {} in / {} out ({:.0f}/s)  malformed {}  lost {}  "
      "rx errors {}  tx errors {}  last round trip {:.2f} us\n",
      static_cast<double>(snap.uptime) / 1e9, snap.framesReceived, snap.framesAnswered,
      snap.framesPerSecond, snap.framesDropped, snap.framesLost, snap.receiveErrors,
      snap.sendErrors, micros(snap.lastRoundTrip));
  out += fmt::format("{:>3}  {:<16} {:<10} {:>6}  {:>10} {:>10}  {:>6} {:>5}  {:>12}  {}\n", "pos",
                     "name", "state", "code", "frames", "datagrams", "rxerr", "lost", "dc diff ns",
                     "process data (>out <in)");
  for (std::size_t i = 0; i < snap.slaves.size(); ++i) {
    const SlaveStatus& s = snap.slaves[i];
    out += fmt::format("{:>3}  {:<16} {:<10} {:#06x}  {:>10} {:>10}  {:>6} {:>5}  {:>12}  {}\n", i,
                       s.name.substr(0, 16), stateText(s), s.alStatusCode, s.frames, s.datagrams,
                       s.rxErrors, s.lostLinks, s.dcDifferenceNs, valuesText(s));
  }
  return out;
}

std::string formatStatusJson(const StatusSnapshot& snap) {
  std::string out = "{";
  out += fmt::format(
      "\"uptimeNs\":{},\"framesReceived\":{},\"framesAnswered\":{},\"framesDropped\":{},"
      "\"framesLost\":{},\"receiveErrors\":{},\"sendErrors\":{},\"framesPerSecond\":{:.1f},"
      "\"lastRoundTripNs\":{},\"slaves\":[",
      snap.uptime, snap.framesReceived, snap.framesAnswered, snap.framesDropped, snap.framesLost,
      snap.receiveErrors, snap.sendErrors, snap.framesPerSecond, snap.lastRoundTrip);
  for (std::size_t i = 0; i < snap.slaves.size(); ++i) {
    const SlaveStatus& s = snap.slaves[i];
    if (i > 0) out += ',';
    out += fmt::format(
        "{{\"position\":{},\"name\":{},\"state\":{},\"alError\":{},\"alStatusCode\":{},"
        "\"frames\":{},\"datagrams\":{},\"rxErrors\":{},\"lostLinks\":{},"
        "\"dcDifferenceNs\":{},\"processData\":[",
        i, jsonString(s.name), jsonString(toString(s.state)), s.alError ? "true" : "false",
        s.alStatusCode, s.frames, s.datagrams, s.rxErrors, s.lostLinks, s.dcDifferenceNs);
    for (std::size_t v = 0; v < s.values.size(); ++v) {
      const ProcessValue& pv = s.values[v];
      if (v > 0) out += ',';
      out += fmt::format("{{\"name\":{},\"entry\":\"{:04X}:{:02X}\",\"output\":{},\"value\":{}}}",
                         jsonString(pv.name), pv.index, pv.subindex, pv.output ? "true" : "false",
                         pv.value);
    }
    out += "]}";
  }
  out += "]}\n";
  return out;
}

Status writeFileAtomically(const std::filesystem::path& path, const std::string& text) {
  std::filesystem::path tmp = path;
  tmp += ".tmp";
  {
    std::ofstream file(tmp, std::ios::binary | std::ios::trunc);
    if (!file) {
      return makeError(ErrorCode::kIo, tmp.string() + ": cannot open for writing");
    }
    file << text;
    file.flush();
    if (!file) return makeError(ErrorCode::kIo, tmp.string() + ": write failed");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    return makeError(ErrorCode::kIo,
                     "renaming " + tmp.string() + " to " + path.string() + ": " + ec.message());
  }
  return okStatus();
}

void StatusReporter::tick(SimTime now, topology::Segment& segment,
                          const topology::ServerCounters& counters) {
  if (!enabled()) return;
  if (!started_) {
    started_ = true;
    start_ = now;
    last_ = now;
    lastFrames_ = counters.framesReceived;
    return;
  }
  if (now - last_ < period_) return;
  const double seconds = static_cast<double>(now - last_) / 1e9;
  const double fps = static_cast<double>(counters.framesReceived - lastFrames_) / seconds;
  last_ = now;
  lastFrames_ = counters.framesReceived;
  const StatusSnapshot snap = takeStatusSnapshot(segment, counters, now - start_, fps);
  if (terminal_) {
    // Home the cursor, clear the screen, draw: one redraw per period.
    fmt::print("\x1b[H\x1b[2J{}", formatStatusTable(snap));
    std::fflush(stdout);
  }
  if (!jsonPath_.empty()) lastWrite_ = writeFileAtomically(jsonPath_, formatStatusJson(snap));
}

}  // namespace ecsim::tools
