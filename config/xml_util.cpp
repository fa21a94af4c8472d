#include "config/xml_util.hpp"

#include <algorithm>
#include <array>
#include <cctype>

#include "protocol/closest_name.hpp"

namespace ecsim::xml {
namespace {

bool startsWith(std::string_view s, std::size_t at, std::string_view prefix) {
  return s.compare(at, prefix.size(), prefix) == 0;
}

bool isNameChar(char c) {
  const auto u = static_cast<unsigned char>(c);
  return std::isalnum(u) || c == '_' || c == '-' || c == '.' || c == ':' || u >= 0x80;
}

// Length of a valid entity reference starting at `at` (which holds '&'), 0 if none.
std::size_t entityReferenceLength(std::string_view s, std::size_t at) {
  std::size_t i = at + 1;
  if (i < s.size() && s[i] == '#') {
    ++i;
    const bool hex = i < s.size() && (s[i] == 'x' || s[i] == 'X');
    if (hex) ++i;
    const std::size_t digits = i;
    while (i < s.size() && (hex ? std::isxdigit(static_cast<unsigned char>(s[i]))
                                : std::isdigit(static_cast<unsigned char>(s[i])))) {
      ++i;
    }
    return (i > digits && i < s.size() && s[i] == ';') ? i + 1 - at : 0;
  }
  const std::size_t name = i;
  while (i < s.size() && isNameChar(s[i])) ++i;
  if (i == s.size() || s[i] != ';') return 0;
  static constexpr std::array<std::string_view, 5> kPredefined = {"amp", "lt", "gt", "quot",
                                                                  "apos"};
  const std::string_view ref = s.substr(name, i - name);
  return std::find(kPredefined.begin(), kPredefined.end(), ref) != kPredefined.end() ? i + 1 - at
                                                                                     : 0;
}

// The findings of checkNames in document order: attributes, then child elements.
template <typename Report>
void findUnknownNames(const Context& ctx, const Element* e, const Names& names, Report report) {
  const auto known = [](const std::vector<std::string_view>& list, std::string_view name) {
    return std::find(list.begin(), list.end(), name) != list.end();
  };
  // Built only for a message: a file of 65,535 slaves is checked without them.
  const auto on = [&] { return std::string(" on <") + e->Name() + ">"; };
  const auto in = [&] { return std::string(" in <") + e->Name() + ">"; };
  for (const tinyxml2::XMLAttribute* a = e->FirstAttribute(); a != nullptr; a = a->Next()) {
    if (!known(names.attributes, a->Name())) {
      if (!report(ctx.error(e, unknownNameText("attribute", a->Name(), names.attributes, on()))))
        return;
    }
  }
  std::vector<std::string_view> seen;
  for (const Element* child : Children(e, nullptr)) {
    const std::string_view name = child->Name();
    if (!known(names.children, name)) {
      if (!report(ctx.error(child, unknownNameText("element", name, names.children, in(), "<>"))))
        return;
    } else if (known(names.once, name)) {
      if (known(seen, name)) {
        if (!report(
                ctx.error(child, "second <" + std::string(name) + ">" + in() + " (it takes one)")))
          return;
      }
      seen.push_back(name);
    }
  }
}

}  // namespace

Status checkNames(const Context& ctx, const Element* e, const Names& names) {
  Status status = okStatus();
  findUnknownNames(ctx, e, names, [&](Error error) {
    status = std::move(error);
    return false;  // the first is enough
  });
  return status;
}

void warnUnknownNames(const Context& ctx, const Element* e, const Names& names) {
  findUnknownNames(ctx, e, names, [&](const Error& error) {
    ctx.warn(error.context);
    return true;
  });
}

std::string escapeText(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string_view text(const Element* e) {
  if (e == nullptr) return {};
  const char* t = e->GetText();
  return t == nullptr ? std::string_view{} : trimEsiText(t);
}

std::string_view childText(const Element* parent, const char* name) {
  return parent == nullptr ? std::string_view{} : text(parent->FirstChildElement(name));
}

std::vector<EsiLocalText> localTexts(const Element* parent, const char* name) {
  std::vector<EsiLocalText> out;
  for (const Element* e : Children(parent, name)) {
    EsiLocalText t;
    t.lcid = e->UnsignedAttribute("LcId", 0);
    t.text = std::string(text(e));
    out.push_back(std::move(t));
  }
  return out;
}

Result<bool> attrBool(const Context& ctx, const Element* e, const char* name, bool fallback) {
  const char* raw = e->Attribute(name);
  if (raw == nullptr || trimEsiText(raw).empty()) return fallback;
  auto value = parseEsiBool(raw);
  if (!value.ok())
    return ctx.error(e, std::string("attribute ") + name + ": " + value.error().context);
  return *value;
}

Result<std::vector<std::uint8_t>> childHex(const Context& ctx, const Element* parent,
                                           const char* name) {
  const Element* child = parent->FirstChildElement(name);
  if (child == nullptr) return std::vector<std::uint8_t>{};
  auto bytes = parseEsiHexBinary(text(child));
  if (!bytes.ok()) return ctx.error(child, std::string(name) + ": " + bytes.error().context);
  return bytes;
}

Status checkEntityReferences(std::string_view s, const Context& ctx) {
  int line = 1;
  auto skipTo = [&](std::size_t from, std::string_view end) -> std::size_t {
    const std::size_t stop = s.find(end, from);
    const std::size_t until = stop == std::string_view::npos ? s.size() : stop + end.size();
    line += static_cast<int>(std::count(s.begin() + static_cast<std::ptrdiff_t>(from),
                                        s.begin() + static_cast<std::ptrdiff_t>(until), '\n'));
    return until;
  };
  auto badAmpersand = [&](std::size_t at) {
    const std::size_t lineStart = s.rfind('\n', at);
    const std::size_t from = lineStart == std::string_view::npos ? 0 : lineStart + 1;
    const std::size_t to = std::min(s.find('\n', at), s.size());
    std::string excerpt(trimEsiText(s.substr(from, std::min<std::size_t>(to - from, 80))));
    return ctx.error(line, "'&' does not start an entity reference (write &amp;): " + excerpt);
  };
  std::size_t i = 0;
  while (i < s.size()) {
    const char c = s[i];
    if (c == '\n') {
      ++line;
      ++i;
    } else if (c == '&') {
      if (entityReferenceLength(s, i) == 0) return badAmpersand(i);
      ++i;
    } else if (c != '<') {
      ++i;
    } else if (startsWith(s, i, "<!--")) {
      i = skipTo(i, "-->");
    } else if (startsWith(s, i, "<![CDATA[")) {
      i = skipTo(i, "]]>");
    } else if (startsWith(s, i, "<?")) {
      i = skipTo(i, "?>");
    } else if (startsWith(s, i, "<!")) {
      i = skipTo(i, ">");
    } else {  // a tag: check attribute values
      ++i;
      char quote = 0;
      while (i < s.size() && (quote != 0 || s[i] != '>')) {
        if (s[i] == '\n') ++line;
        if (quote != 0) {
          if (s[i] == quote) {
            quote = 0;
          } else if (s[i] == '&' && entityReferenceLength(s, i) == 0) {
            return badAmpersand(i);
          }
        } else if (s[i] == '"' || s[i] == '\'') {
          quote = s[i];
        }
        ++i;
      }
      ++i;
    }
  }
  return okStatus();
}

EsiEncoding declaredEncoding(std::string_view xml) {
  if (!startsWith(xml, 0, "<?xml")) return EsiEncoding::kUtf8;
  const std::string_view decl = xml.substr(0, xml.find("?>"));
  const std::size_t at = decl.find("encoding");
  if (at == std::string_view::npos) return EsiEncoding::kUtf8;
  std::string value;
  bool inQuote = false;
  for (std::size_t i = at + 8; i < decl.size(); ++i) {
    const char c = decl[i];
    if (c == '"' || c == '\'') {
      if (inQuote) break;
      inQuote = true;
    } else if (inQuote) {
      value += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    }
  }
  if (value == "iso-8859-1" || value == "latin1" || value == "iso8859-1" ||
      value == "windows-1252") {
    return EsiEncoding::kLatin1;
  }
  return EsiEncoding::kUtf8;
}

Status parseDocument(std::string_view xml, const Context& ctx, tinyxml2::XMLDocument& doc) {
  const tinyxml2::XMLError status = doc.Parse(xml.data(), xml.size());
  if (status != tinyxml2::XML_SUCCESS) {
    std::string message = doc.ErrorName();
    // ErrorStr() reads "Error=NAME ErrorID=n (0xn) Line number=n[: detail]".
    const std::string_view full = doc.ErrorStr() == nullptr ? "" : doc.ErrorStr();
    if (const std::size_t colon = full.find(": "); colon != std::string_view::npos) {
      message += " (" + std::string(full.substr(colon + 2)) + ")";
    }
    if (status == tinyxml2::XML_ERROR_MISMATCHED_ELEMENT) {
      message += ": the element opened on this line does not end with its own end tag";
    }
    return ctx.error(doc.ErrorLineNum(), message);
  }
  // tinyxml2 also accepts several top-level elements.
  if (const Element* root = doc.RootElement(); root != nullptr) {
    if (const Element* second = root->NextSiblingElement(); second != nullptr) {
      return ctx.error(second, "second top-level element <" + std::string(second->Name()) +
                                   "> (a document has one root)");
    }
  }
  return checkEntityReferences(xml, ctx);
}

}  // namespace ecsim::xml
