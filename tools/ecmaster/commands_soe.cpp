// ecmaster soe read | write: SoE (servo drive profile over EtherCAT) IDNs of one drive.
//
//   ecmaster soe read -p 1                every IDN of S-0-0017 with its type, name and value
//   ecmaster soe read -p 1 S-0-0001       one IDN with all its elements
//   ecmaster soe write -p 1 S-0-0001 250  the value element; the value is read per the IDN's
//                                         attribute: a number (decimals as the attribute says),
//                                         an IDN, text, or a list "S-0-0011,S-0-0380"
#include <fmt/core.h>

#include <cmath>
#include <sstream>

#include "config/esi.hpp"
#include "tools/ecmaster/commands.hpp"
#include "tools/ecmaster/values.hpp"

namespace ecsim::tools::ecmaster {
namespace {

struct SoeOptions {
  std::size_t position{0};
  unsigned drive{0};
  std::string idn;
  std::string value;
};

constexpr std::uint8_t kAllElements =
    soe_element::kName | soe_element::kAttribute | soe_element::kUnit | soe_element::kMinimum |
    soe_element::kMaximum | soe_element::kValue | soe_element::kDefault;

// One element (of an element size) as the attribute's data type shows it.
std::string formatElement(SoeAttribute a, ConstBytes bytes) {
  switch (a.dataType()) {
    case SoeDataType::kIdn:
      return formatIdn(static_cast<std::uint16_t>(soeNumber(bytes, false)));
    case SoeDataType::kHex:
    case SoeDataType::kBinary:
      return hex(static_cast<std::uint64_t>(soeNumber(bytes, false)),
                 static_cast<int>(2 * bytes.size()));
    case SoeDataType::kText:
      return std::string(1, static_cast<char>(bytes[0]));
    default:
      break;
  }
  const bool isSigned = a.dataType() == SoeDataType::kSigned;
  const std::int64_t v = soeNumber(bytes, isSigned);
  if (a.decimals() == 0) {
    return isSigned ? std::to_string(v) : std::to_string(static_cast<std::uint64_t>(v));
  }
  return fmt::format("{:.{}f}", static_cast<double>(v) / std::pow(10.0, a.decimals()),
                     a.decimals());
}

// A value element: fixed length, or a list with its header.
std::string formatValue(SoeAttribute a, ConstBytes bytes) {
  if (!a.isList()) {
    if (bytes.size() < a.elementSize()) return hexBytes(bytes);
    return formatElement(a, bytes.first(a.elementSize()));
  }
  auto list = decodeSoeList(bytes);
  if (!list.ok()) return hexBytes(bytes);
  if (a.dataType() == SoeDataType::kText) {
    return "\"" + std::string(list->data.begin(), list->data.end()) + "\"";
  }
  std::string out = "[";
  const std::size_t size = a.elementSize();
  for (std::size_t at = 0; at + size <= list->data.size(); at += size) {
    if (at > 0) out += ", ";
    out += formatElement(a, list->data.subspan(at, size));
  }
  return out + "]";
}

Result<std::vector<std::uint8_t>> encodeElement(SoeAttribute a, std::string_view text) {
  const std::size_t size = a.elementSize();
  std::int64_t v = 0;
  if (a.dataType() == SoeDataType::kIdn) {
    ECSIM_ASSIGN_OR_RETURN(std::uint16_t idn, parseIdn(text));
    v = idn;
  } else if (a.decimals() > 0 || text.find('.') != std::string_view::npos) {
    double d = 0;
    std::istringstream in{std::string(text)};
    if (!(in >> d) || !in.eof()) {
      return makeError(ErrorCode::kInvalidArgument, fmt::format("'{}' is not a number", text));
    }
    v = static_cast<std::int64_t>(std::llround(d * std::pow(10.0, a.decimals())));
  } else {
    auto parsed = parseEsiInteger(text);
    if (!parsed.ok()) return parsed.takeError();
    v = *parsed;
  }
  std::vector<std::uint8_t> out(size);
  for (std::size_t i = 0; i < size; ++i) {
    out[i] = static_cast<std::uint8_t>(static_cast<std::uint64_t>(v) >> (8 * i));
  }
  return out;
}

// The bytes of a value element for `a` written as text: a number, an IDN, a text, or a list
// of elements separated by commas or blanks.
Result<std::vector<std::uint8_t>> encodeValue(SoeAttribute a, const std::string& text) {
  if (!a.isList()) return encodeElement(a, text);
  std::vector<std::uint8_t> data;
  if (a.dataType() == SoeDataType::kText) {
    data.assign(text.begin(), text.end());
  } else {
    std::string item;
    std::istringstream in(text);
    std::string all;
    for (char c : text) all += (c == ',') ? ' ' : c;
    std::istringstream words(all);
    while (words >> item) {
      ECSIM_ASSIGN_OR_RETURN(auto bytes, encodeElement(a, item));
      data.insert(data.end(), bytes.begin(), bytes.end());
    }
  }
  return encodeSoeList(data, 0);
}

Result<std::uint8_t> driveNumber(unsigned drive) {
  if (drive > kSoeDriveMax) {
    return makeError(ErrorCode::kInvalidArgument,
                     fmt::format("--drive {}: a drive number is 0-{}", drive, kSoeDriveMax));
  }
  return static_cast<std::uint8_t>(drive);
}

int readOne(const GlobalOptions& g, master::Master& m, const SoeOptions& o, std::uint8_t drive,
            std::uint16_t idn) {
  // Elements the IDN lacks (a list has no minimum) answer with an error: ask for the ones
  // every IDN has, then each optional one alone.
  auto base = m.soeRead(o.position, drive,
                        soe_element::kName | soe_element::kAttribute | soe_element::kValue, idn);
  if (!base.ok()) return fail(base.error());
  auto e =
      splitSoeElements(soe_element::kName | soe_element::kAttribute | soe_element::kValue, *base);
  if (!e.ok()) return fail(e.error());
  auto optional = [&](std::uint8_t element) -> std::optional<std::vector<std::uint8_t>> {
    auto r = m.soeRead(o.position, drive, element, idn);
    if (!r.ok()) return std::nullopt;
    return std::move(r).value();
  };
  std::string unit;
  if (auto u = optional(soe_element::kUnit); u) {
    if (auto l = decodeSoeList(*u); l.ok()) unit.assign(l->data.begin(), l->data.end());
  }
  const auto minimum = optional(soe_element::kMinimum);
  const auto maximum = optional(soe_element::kMaximum);
  const auto defaultValue = optional(soe_element::kDefault);
  std::optional<std::uint16_t> state;
  if (e->attribute.isProcedureCommand()) {
    if (auto s = optional(soe_element::kDataState); s && s->size() >= 2) state = readLe16(*s, 0);
  }
  const SoeAttribute a = e->attribute;
  if (g.json) {
    nlohmann::json j{{"position", o.position},
                     {"drive", drive},
                     {"idn", formatIdn(idn)},
                     {"name", e->name},
                     {"attribute", a.raw},
                     {"type", a.describe()},
                     {"value", formatValue(a, e->value)},
                     {"bytes", hexBytes(e->value)}};
    if (!unit.empty()) j["unit"] = unit;
    if (minimum) j["minimum"] = formatValue(a, *minimum);
    if (maximum) j["maximum"] = formatValue(a, *maximum);
    if (defaultValue) j["default"] = formatValue(a, *defaultValue);
    if (state) j["commandState"] = *state;
    printJson(j);
    return 0;
  }
  fmt::print("{} {}\n", formatIdn(idn), e->name);
  fmt::print(
      "  attribute {} ({}{}{})\n", hex(a.raw, 8), a.describe(),
      a.readOnly() ? ", read-only" : (a.writeProtectedInPhase(2) ? "" : ", writable in PREOP"),
      a.readOnly() ? ""
                   : std::string(a.writeProtectedInPhase(3) ? "" : ", SAFEOP") +
                         (a.writeProtectedInPhase(4) ? "" : ", OP"));
  fmt::print("  value     {}{}\n", formatValue(a, e->value), unit.empty() ? "" : " " + unit);
  if (minimum) fmt::print("  minimum   {}\n", formatValue(a, *minimum));
  if (maximum) fmt::print("  maximum   {}\n", formatValue(a, *maximum));
  if (defaultValue) fmt::print("  default   {}\n", formatValue(a, *defaultValue));
  if (state) fmt::print("  command   {} (data state)\n", hex(*state, 4));
  return 0;
}

int listIdns(const GlobalOptions& g, master::Master& m, const SoeOptions& o, std::uint8_t drive) {
  constexpr std::uint16_t kAllIdns = 17;  // S-0-0017, IDN-list of all operation data
  auto all = m.soeRead(o.position, drive, soe_element::kValue, kAllIdns);
  if (!all.ok()) return fail(all.error());
  auto list = decodeSoeList(*all);
  if (!list.ok()) return fail(list.error());
  nlohmann::json rows = nlohmann::json::array();
  const std::uint8_t asked =
      soe_element::kName | soe_element::kAttribute | soe_element::kUnit | soe_element::kValue;
  for (std::size_t at = 0; at + 1 < list->data.size(); at += 2) {
    const std::uint16_t idn = readLe16(list->data, at);
    // The unit is asked too, and asked again without it when the IDN has none (0x4001).
    auto r = m.soeRead(o.position, drive, asked, idn);
    std::uint8_t got = asked;
    if (!r.ok()) {
      got = static_cast<std::uint8_t>(asked & ~soe_element::kUnit);
      r = m.soeRead(o.position, drive, got, idn);
    }
    if (!r.ok()) return fail(r.error());
    auto e = splitSoeElements(got, *r);
    if (!e.ok()) return fail(e.error());
    const std::string value = e->attribute.isProcedureCommand()
                                  ? std::string("(command)")
                                  : formatValue(e->attribute, e->value);
    if (g.json) {
      rows.push_back({{"idn", formatIdn(idn)},
                      {"name", e->name},
                      {"type", e->attribute.describe()},
                      {"value", value},
                      {"unit", e->unit}});
    } else {
      fmt::print("{}  {:<9} {:<48} {}{}\n", formatIdn(idn), e->attribute.describe(), e->name,
                 value.size() > 60 ? value.substr(0, 57) + "..." : value,
                 e->unit.empty() ? "" : " " + e->unit);
    }
  }
  if (g.json) printJson({{"position", o.position}, {"drive", drive}, {"idns", rows}});
  return 0;
}

int runSoeRead(const GlobalOptions& g, const SoeOptions& o) {
  auto drive = driveNumber(o.drive);
  if (!drive.ok()) return fail(drive.error());
  std::optional<std::uint16_t> idn;
  if (!o.idn.empty()) {
    auto parsed = parseIdn(o.idn);
    if (!parsed.ok()) return fail(parsed.error());
    idn = *parsed;
  }
  auto c = connectAndScan(g, false);
  if (!c.ok()) return fail(c.error());
  master::Master& m = (*c)->master();
  if (auto s = ensureMailbox(m, o.position); !s.ok()) return fail(s.error());
  return idn ? readOne(g, m, o, *drive, *idn) : listIdns(g, m, o, *drive);
}

int runSoeWrite(const GlobalOptions& g, const SoeOptions& o) {
  auto drive = driveNumber(o.drive);
  if (!drive.ok()) return fail(drive.error());
  auto idn = parseIdn(o.idn);
  if (!idn.ok()) return fail(idn.error());
  auto c = connectAndScan(g, false);
  if (!c.ok()) return fail(c.error());
  master::Master& m = (*c)->master();
  if (auto s = ensureMailbox(m, o.position); !s.ok()) return fail(s.error());
  // The attribute says how to write the value.
  auto attr = m.soeRead(o.position, *drive, soe_element::kAttribute, *idn);
  if (!attr.ok()) return fail(attr.error());
  if (attr->size() < kSoeAttributeSize) return fail("short attribute element");
  const SoeAttribute a{readLe32(*attr, 0)};
  auto bytes = encodeValue(a, o.value);
  if (!bytes.ok()) {
    return fail(fmt::format("{} ({}): {}", formatIdn(*idn), a.describe(), bytes.error().context));
  }
  if (auto s = m.soeWrite(o.position, *drive, *idn, *bytes); !s.ok()) return fail(s.error());
  if (g.json) {
    printJson({{"position", o.position},
               {"drive", *drive},
               {"idn", formatIdn(*idn)},
               {"written", hexBytes(*bytes)}});
  }
  return 0;
}

}  // namespace

CommandRunner addSoeCommand(CLI::App& app, const GlobalOptions& global) {
  auto read = std::make_shared<SoeOptions>();
  auto write = std::make_shared<SoeOptions>();
  auto* soe = app.add_subcommand("soe", "SoE IDNs of a servo drive (read, write)");
  soe->require_subcommand(1);
  auto* r = soe->add_subcommand("read", "Read one IDN with its elements, or list all (S-0-0017)");
  r->add_option("-p,--position", read->position, "Slave position");
  r->add_option("--drive", read->drive, "Drive number in the slave (0-7)");
  r->add_option("idn", read->idn, "S-0-0001, P-0-0009 or a number; none: list every IDN");
  auto* w = soe->add_subcommand("write", "Write an IDN's value (operation data)");
  w->add_option("-p,--position", write->position, "Slave position");
  w->add_option("--drive", write->drive, "Drive number in the slave (0-7)");
  w->add_option("idn", write->idn, "S-0-0001, P-0-0009 or a number")->required();
  w->add_option("value", write->value,
                "Number, IDN, text, or a list separated by commas (S-0-0011,S-0-0380)")
      ->required();
  return [&global, read, write, r] {
    return r->parsed() ? runSoeRead(global, *read) : runSoeWrite(global, *write);
  };
}

}  // namespace ecsim::tools::ecmaster
