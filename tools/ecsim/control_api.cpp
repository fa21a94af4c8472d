#include "tools/ecsim/control_api.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>

#include "embed/slave_variables.hpp"
#include "protocol/closest_name.hpp"
#include "protocol/registers.hpp"
#include "slavesim/coe/data_types.hpp"
#include "slavesim/esi_slave.hpp"
#include "topology/slave_names.hpp"

namespace ecsim::tools {
namespace {

using nlohmann::json;
using ClientId = topology::ControlServer::ClientId;

// The ops and the keys each takes ("op" always).
struct OpKeys {
  std::string_view op;
  std::array<std::string_view, 6> keys;
};
constexpr std::array<OpKeys, 6> kOps{{
    {"get", {"slave", "entry", "name", "object", "register"}},
    {"set", {"slave", "entry", "name", "object", "register", "value"}},
    {"state", {}},
    {"faults", {}},
    {"subscribe", {"slave", "entry", "name"}},
    {"fault", {"action"}},
}};

std::string reply(json j) {
  return j.dump(-1, ' ', false, json::error_handler_t::replace);
}
std::string failure(const std::string& why) {
  return reply(json{{"ok", false}, {"error", why}});
}

std::string closestHint(std::string_view name, const std::vector<std::string_view>& names) {
  if (auto best = closestName(name, names)) return "; did you mean '" + std::string(*best) + "'?";
  return {};
}

std::string hexIndex(std::uint16_t index, std::uint8_t subindex) {
  return fmt::format("0x{:04X}:{:02X}", index, subindex);
}

// A value as JSON: its bits read as the entry's type (master::variableType).
json decodeValue(std::uint64_t raw, std::uint16_t dataType, std::uint16_t bitLength) {
  using master::VariableType;
  const auto type = master::variableType(dataType, static_cast<std::uint8_t>(bitLength));
  switch (type) {
    case VariableType::kReal32:
      return static_cast<double>(std::bit_cast<float>(static_cast<std::uint32_t>(raw)));
    case VariableType::kReal64:
      return std::bit_cast<double>(raw);
    case VariableType::kInt8:
    case VariableType::kInt16:
    case VariableType::kInt32:
    case VariableType::kInt64: {
      if (bitLength >= 64) return static_cast<std::int64_t>(raw);
      const std::uint64_t sign = std::uint64_t{1} << (bitLength - 1);
      return static_cast<std::int64_t>((raw ^ sign) - sign);
    }
    default:
      return raw;
  }
}

// The bits a JSON value gives an entry of this type, or why it does not fit.
Result<std::uint64_t> encodeValue(const json& value, std::uint16_t dataType,
                                  std::uint16_t bitLength, const std::string& what) {
  using master::VariableType;
  const auto type = master::variableType(dataType, static_cast<std::uint8_t>(bitLength));
  if (type == VariableType::kReal32 || type == VariableType::kReal64) {
    if (!value.is_number())
      return makeError(ErrorCode::kInvalidArgument, what + ": value is not a number");
    const double d = value.get<double>();
    if (type == VariableType::kReal32)
      return std::uint64_t{std::bit_cast<std::uint32_t>(static_cast<float>(d))};
    return std::bit_cast<std::uint64_t>(d);
  }
  json v = value;
  if (v.is_boolean()) v = v.get<bool>() ? 1 : 0;
  if (!v.is_number_integer()) {
    return makeError(ErrorCode::kInvalidArgument,
                     what + ": value must be an integer (or true/false), got " + value.dump());
  }
  const bool isSigned = type == VariableType::kInt8 || type == VariableType::kInt16 ||
                        type == VariableType::kInt32 || type == VariableType::kInt64;
  const unsigned bits = std::min<unsigned>(bitLength, 64);
  if (isSigned) {
    const std::int64_t lo =
        bits >= 64 ? std::numeric_limits<std::int64_t>::min() : -(std::int64_t{1} << (bits - 1));
    const std::int64_t hi =
        bits >= 64 ? std::numeric_limits<std::int64_t>::max() : (std::int64_t{1} << (bits - 1)) - 1;
    if (v.is_number_unsigned() && v.get<std::uint64_t>() > static_cast<std::uint64_t>(hi)) {
      return makeError(ErrorCode::kInvalidArgument,
                       fmt::format("{}: value {} out of range {}..{}", what, value.dump(), lo, hi));
    }
    const auto s = v.get<std::int64_t>();
    if (s < lo || s > hi) {
      return makeError(ErrorCode::kInvalidArgument,
                       fmt::format("{}: value {} out of range {}..{}", what, s, lo, hi));
    }
    return static_cast<std::uint64_t>(s) &
           (bits >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1);
  }
  const std::uint64_t hi = bits >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1;
  if (v.is_number_unsigned() || v.get<std::int64_t>() >= 0) {
    const auto u = v.get<std::uint64_t>();
    if (u <= hi) return u;
  }
  return makeError(ErrorCode::kInvalidArgument,
                   fmt::format("{}: value {} out of range 0..{}", what, value.dump(), hi));
}

// "0x6041:00" (index and subindex in hex, the form master/variables.hpp names entries by).
std::optional<std::pair<std::uint16_t, std::uint8_t>> parseObject(std::string_view text) {
  if (text.size() < 8 || (text.substr(0, 2) != "0x" && text.substr(0, 2) != "0X")) return {};
  const auto colon = text.find(':');
  if (colon != 6 || colon + 1 >= text.size() || text.size() - colon - 1 > 2) return {};
  unsigned index = 0;
  unsigned sub = 0;
  for (char c : text.substr(2, 4)) {
    if (!std::isxdigit(static_cast<unsigned char>(c))) return {};
    index = index * 16 + static_cast<unsigned>(std::stoi(std::string(1, c), nullptr, 16));
  }
  for (char c : text.substr(colon + 1)) {
    if (!std::isxdigit(static_cast<unsigned char>(c))) return {};
    sub = sub * 16 + static_cast<unsigned>(std::stoi(std::string(1, c), nullptr, 16));
  }
  return std::pair{static_cast<std::uint16_t>(index), static_cast<std::uint8_t>(sub)};
}

// Register names compared without case, spaces or a leading 'k' ("kAlStatus", "AL Status").
// The registers the PDI may write, after the ESC datasheet section II register overview
// (ET1100 column): AL Status and AL Status Code (ECAT read, PDI read/write), the RUN and ERR
// LED overrides and the PDI's AL Event Mask (PDI read/write). Every other named register is
// read-only from the PDI (AL Control, DL Control, the SM and FMMU channels' ECAT parts, DC...), so
// the socket refuses to write it: the slave's firmware could not either.
constexpr std::array kPdiWritable{
    reg::RegisterInfo{reg::kAlStatus.address, reg::kAlStatus.width, reg::kAlStatus.name},
    reg::RegisterInfo{reg::kAlStatusCode.address, reg::kAlStatusCode.width,
                      reg::kAlStatusCode.name},
    reg::RegisterInfo{reg::kRunLedOverride.address, reg::kRunLedOverride.width,
                      reg::kRunLedOverride.name},
    reg::RegisterInfo{reg::kErrLedOverride.address, reg::kErrLedOverride.width,
                      reg::kErrLedOverride.name},
    reg::RegisterInfo{reg::kPdiAlEventMask.address, reg::kPdiAlEventMask.width,
                      reg::kPdiAlEventMask.name},
};

bool pdiWritable(const reg::RegisterInfo& r) {
  return std::any_of(kPdiWritable.begin(), kPdiWritable.end(),
                     [&](const reg::RegisterInfo& w) { return w.address == r.address; });
}

std::string registerKey(std::string_view name) {
  if (name.size() > 1 && name[0] == 'k' && std::isupper(static_cast<unsigned char>(name[1]))) {
    name.remove_prefix(1);
  }
  std::string key;
  for (char c : name) {
    if (std::isalnum(static_cast<unsigned char>(c))) {
      key += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    }
  }
  return key;
}

Result<reg::RegisterInfo> lookUpRegister(std::string_view text) {
  if (text.size() > 2 && (text.substr(0, 2) == "0x" || text.substr(0, 2) == "0X")) {
    unsigned long address = 0;
    try {
      std::size_t used = 0;
      address = std::stoul(std::string(text.substr(2)), &used, 16);
      if (used != text.size() - 2 || address > 0xFFFF) throw std::out_of_range("");
    } catch (const std::exception&) {
      return makeError(ErrorCode::kInvalidArgument,
                       "register '" + std::string(text) + "' is not an address 0x0000..0xFFFF");
    }
    auto found = reg::findRegister(static_cast<std::uint16_t>(address));
    if (!found) {
      return makeError(ErrorCode::kNotFound, fmt::format("no register at 0x{:04X}", address));
    }
    if (found->address != address) {
      return makeError(ErrorCode::kInvalidArgument,
                       fmt::format("0x{:04X} is inside {} (0x{:04X}, {} bytes): give its start",
                                   address, found->name, found->address, found->width));
    }
    return *found;
  }
  const std::string key = registerKey(text);
  std::vector<std::string_view> names;
  for (const auto& r : reg::registerTable()) {
    if (registerKey(r.name) == key) return r;
    names.push_back(r.name);
  }
  return makeError(ErrorCode::kNotFound,
                   "no register named '" + std::string(text) + "'" + closestHint(text, names));
}

}  // namespace

std::string ControlApi::answer(std::string_view line, ClientId client, SimTime now) {
  // JSON starts with '{' (a '[' too, refused as not an object); no fault action does.
  if (!line.empty() && (line.front() == '{' || line.front() == '[')) {
    return answerJson(line, client, now);
  }
  return answerFault(line, now);
}

std::string ControlApi::answerFault(std::string_view line, SimTime now) {
  if (!faults_) faults_.emplace(network_, 1);
  std::string answer = topology::answerFaultLine(*faults_, line, now);
  if (answer.rfind("ok ", 0) == 0) applied_.push_back({now, std::string(line), answer.substr(3)});
  return answer;
}

std::string ControlApi::answerJson(std::string_view line, ClientId client, SimTime now) {
  json request;
  try {
    request = json::parse(line);
  } catch (const json::parse_error& e) {
    return failure(fmt::format("malformed JSON at byte {}: {}", e.byte, e.what()));
  }
  if (!request.is_object()) return failure("a request is a JSON object {\"op\": ...}");
  if (!request.contains("op") || !request["op"].is_string()) {
    return failure("no \"op\" (a string: get, set, state, faults, subscribe, fault)");
  }
  const std::string op = request["op"].get<std::string>();
  const OpKeys* spec = nullptr;
  std::vector<std::string_view> opNames;
  for (const auto& o : kOps) {
    opNames.push_back(o.op);
    if (o.op == op) spec = &o;
  }
  if (spec == nullptr) return failure("unknown op '" + op + "'" + closestHint(op, opNames));
  std::vector<std::string_view> keys{"op"};
  for (auto k : spec->keys) {
    if (!k.empty()) keys.push_back(k);
  }
  for (const auto& [key, value] : request.items()) {
    if (std::find(keys.begin(), keys.end(), key) == keys.end()) {
      return failure("op '" + op + "' takes no key '" + key + "'" + closestHint(key, keys));
    }
    if (key != "value" && !value.is_string()) {
      return failure("\"" + key + "\" must be a string, got " + value.dump());
    }
  }
  auto text = [&](const char* key) {
    return request.contains(key) ? request[key].get<std::string>() : std::string();
  };
  topology::Segment& segment = *network_.segment;

  if (op == "state") {
    json slaves = json::array();
    const auto order = topology::busOrder(segment);
    for (std::size_t p = 0; p < order.size(); ++p) {
      const slavesim::Slave& s = segment.slave(order[p]);
      slaves.push_back({{"position", p},
                        {"name", s.name()},
                        {"state", toString(s.state())},
                        {"error", (s.esc().alStatus() & reg::al::kErrorFlag) != 0},
                        {"alStatusCode", s.esc().read(reg::kAlStatusCode)}});
    }
    return reply({{"ok", true}, {"slaves", slaves}});
  }
  if (op == "faults") {
    json list = json::array();
    for (const auto& f : applied_) {
      list.push_back({{"atNs", f.at}, {"action", f.action}, {"result", f.result}});
    }
    return reply({{"ok", true}, {"faults", list}});
  }
  if (op == "fault") {
    if (!request.contains("action")) return failure("op 'fault' needs \"action\"");
    const std::string answer = answerFault(text("action"), now);
    if (answer.rfind("ok ", 0) == 0) return reply({{"ok", true}, {"result", answer.substr(3)}});
    return failure(answer.substr(answer.rfind("error ", 0) == 0 ? 6 : 0));
  }

  const int targets =
      static_cast<int>(request.contains("entry")) + static_cast<int>(request.contains("name")) +
      static_cast<int>(request.contains("object")) + static_cast<int>(request.contains("register"));
  if (targets != 1) {
    return failure("op '" + op + "' needs one of \"entry\" (with \"slave\"), \"name\"" +
                   (op == "subscribe" ? std::string() : ", \"object\"") +
                   (op == "subscribe" ? std::string() : ", \"register\"") + "; got " +
                   std::to_string(targets));
  }
  if (op == "set" && !request.contains("value")) return failure("op 'set' needs \"value\"");

  // A slave by name (or bus position), for objects and registers.
  const auto order = topology::busOrder(segment);
  auto findSlave = [&](const std::string& name) -> Result<std::size_t> {
    std::vector<std::string_view> names;
    for (std::size_t p = 0; p < order.size(); ++p) {
      if (segment.slave(order[p]).name() == name || std::to_string(p) == name) return order[p];
      names.push_back(segment.slave(order[p]).name());
    }
    return makeError(ErrorCode::kNotFound,
                     "no slave named '" + name + "'" + closestHint(name, names));
  };

  if (request.contains("register") || request.contains("object")) {
    if (!request.contains("slave")) return failure("op '" + op + "' needs \"slave\"");
    auto s = findSlave(text("slave"));
    if (!s.ok()) return failure(s.error().context);
    slavesim::Slave& slave = segment.slave(*s);
    if (request.contains("register")) {
      auto r = lookUpRegister(text("register"));
      if (!r.ok()) return failure(r.error().context);
      if (op == "set") {
        // Written from the PDI side, as the slave's own firmware writes its ESC (AL status,
        // AL status code, PDI-owned registers): what the master then reads.
        const std::string what = text("slave") + " " + std::string(r->name);
        if (!pdiWritable(*r)) {
          std::string names;
          for (const auto& w : kPdiWritable)
            names += (names.empty() ? "" : ", ") + std::string(w.name);
          return failure(what +
                         " is read-only from the PDI (ESC datasheet section II); the PDI "
                         "writes: " +
                         names);
        }
        if (r->width > 8) return failure(what + " is longer than 8 bytes: not settable here");
        auto raw = encodeValue(request["value"], 0, static_cast<std::uint16_t>(8 * r->width), what);
        if (!raw.ok()) return failure(raw.error().context);
        for (unsigned b = 0; b < r->width; ++b) {
          slave.esc().pdiWrite8(static_cast<std::uint16_t>(r->address + b),
                                static_cast<std::uint8_t>(*raw >> (8 * b)));
        }
      }
      json j{{"ok", true}, {"register", r->name}, {"address", fmt::format("0x{:04X}", r->address)}};
      if (r->width <= 8) {
        std::uint64_t v = 0;
        for (unsigned b = 0; b < r->width; ++b) {
          v |= std::uint64_t{slave.esc().reg8(static_cast<std::uint16_t>(r->address + b))}
               << (8 * b);
        }
        j["value"] = v;
      } else {
        std::string hex;
        for (unsigned b = 0; b < r->width; ++b) {
          hex +=
              fmt::format("{:02x}", slave.esc().reg8(static_cast<std::uint16_t>(r->address + b)));
        }
        j["bytes"] = hex;
      }
      return reply(j);
    }
    auto* od = slavesim::objectDictionaryOf(slave);
    if (od == nullptr) return failure("slave '" + text("slave") + "' has no object dictionary");
    auto where = parseObject(text("object"));
    if (!where) {
      return failure("object '" + text("object") +
                     "' is not 0xIIII:SS (index and subindex in hex)");
    }
    const auto [index, sub] = *where;
    const auto* e = od->findEntry(index, sub);
    if (e == nullptr) {
      return failure("slave '" + text("slave") + "' has no object " + hexIndex(index, sub));
    }
    const std::string what = text("slave") + " " + hexIndex(index, sub);
    if (e->bitLength > 64) {
      if (op == "set") return failure(what + " is longer than 64 bits: not settable here");
      std::string hex;
      for (auto b : e->value) hex += fmt::format("{:02x}", b);
      return reply(
          {{"ok", true}, {"object", hexIndex(index, sub)}, {"name", e->name}, {"bytes", hex}});
    }
    if (op == "set") {
      auto raw = encodeValue(request["value"], e->dataType, e->bitLength, what);
      if (!raw.ok()) return failure(raw.error().context);
      std::array<std::uint8_t, 8> bytes{};
      slavesim::coe::writeRawValue(Bytes(bytes.data(), bytes.size()), *raw, e->bitLength);
      if (auto st = od->setBytes(index, sub, ConstBytes(bytes.data(), e->byteSize())); !st.ok()) {
        return failure(what + ": " + st.error().context);
      }
    }
    const auto raw = slavesim::coe::readRawValue(od->bytes(index, sub), e->bitLength);
    return reply({{"ok", true},
                  {"object", hexIndex(index, sub)},
                  {"name", e->name},
                  {"value", decodeValue(raw, e->dataType, e->bitLength)}});
  }

  // A process-data entry.
  std::string name = text("name");
  if (request.contains("entry")) {
    if (!request.contains("slave")) return failure("\"entry\" needs \"slave\"");
    name = text("slave") + "." + text("entry");
  } else if (request.contains("slave")) {
    return failure("give \"name\" alone, or \"slave\" with \"entry\"");
  }
  const auto variables = embed::slaveVariables(segment);
  auto found = master::findVariable(variables, name);
  if (!found.ok()) return failure(found.error().context);
  const std::size_t slaveIndex = order[found->position];
  auto* od = slavesim::objectDictionaryOf(segment.slave(slaveIndex));
  if (od == nullptr) return failure(found->name + ": the slave has no dictionary");
  if (op == "set") {
    if (found->output) {
      return failure(found->name + " is an output (RxPDO): the master writes it; set inputs");
    }
    auto raw = encodeValue(request["value"], found->dataType, found->bitLength, found->name);
    if (!raw.ok()) return failure(raw.error().context);
    std::array<std::uint8_t, 8> bytes{};
    slavesim::coe::writeRawValue(Bytes(bytes.data(), bytes.size()), *raw, found->bitLength);
    if (auto st = od->setBytes(found->index, found->subindex,
                               ConstBytes(bytes.data(), (found->bitLength + 7u) / 8u));
        !st.ok()) {
      return failure(found->name + ": " + st.error().context);
    }
  }
  const auto raw =
      slavesim::coe::readRawValue(od->bytes(found->index, found->subindex), found->bitLength);
  const json value = decodeValue(raw, found->dataType, found->bitLength);
  if (op == "subscribe") {
    std::size_t mine = 0;
    for (const auto& s : subscriptions_) mine += s.client == client ? 1 : 0;
    if (mine >= kMaxSubscriptionsPerClient) {
      return failure(
          fmt::format("at most {} subscriptions per connection", kMaxSubscriptionsPerClient));
    }
    subscriptions_.push_back({client, *found, slaveIndex, raw});
    return reply({{"ok", true}, {"subscribed", found->name}, {"value", value}});
  }
  return reply({{"ok", true},
                {"name", found->name},
                {"output", found->output},
                {"type", master::toString(found->type)},
                {"value", value}});
}

void ControlApi::publish(topology::ControlServer& server) {
  std::erase_if(subscriptions_, [&](const Subscription& s) { return !server.connected(s.client); });
  for (auto& s : subscriptions_) {
    server.holdOpen(s.client);
    auto* od = slavesim::objectDictionaryOf(network_.segment->slave(s.slave));
    if (od == nullptr) continue;
    const auto raw = slavesim::coe::readRawValue(od->bytes(s.variable.index, s.variable.subindex),
                                                 s.variable.bitLength);
    if (raw == s.last) continue;
    const std::string line =
        reply({{"event", "change"},
               {"name", s.variable.name},
               {"value", decodeValue(raw, s.variable.dataType, s.variable.bitLength)}});
    if (server.push(s.client, line)) s.last = raw;
  }
}

}  // namespace ecsim::tools
