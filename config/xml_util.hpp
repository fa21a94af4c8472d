// Small helpers over tinyxml2 shared by the XML readers: errors that name file and line,
// typed text/attribute access in ESI number syntax, the well-formedness checks tinyxml2 leaves
// out, and the names table each element of our own formats is checked against (checkNames).
// Used by config/ and by the scenario reader and JUnit writer.
#pragma once

#include <tinyxml2.h>

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "config/esi.hpp"
#include "protocol/result.hpp"

namespace ecsim::xml {

using Element = tinyxml2::XMLElement;

// Text or attribute value with &, <, > and " written as entities.
std::string escapeText(std::string_view text);

// Iterates the child elements named `name` (all children when name is null).
class Children {
 public:
  Children(const Element* parent, const char* name) : parent_(parent), name_(name) {}
  class Iterator {
   public:
    Iterator(const Element* e, const char* name) : e_(e), name_(name) {}
    const Element* operator*() const { return e_; }
    Iterator& operator++() {
      e_ = e_->NextSiblingElement(name_);
      return *this;
    }
    bool operator!=(const Iterator& other) const { return e_ != other.e_; }

   private:
    const Element* e_;
    const char* name_;
  };
  Iterator begin() const {
    return {parent_ == nullptr ? nullptr : parent_->FirstChildElement(name_), name_};
  }
  Iterator end() const { return {nullptr, name_}; }

 private:
  const Element* parent_;
  const char* name_;
};

// Error context: the file name used in messages ("<file>, line <n>: <what>"), and where the
// warnings of a tolerant reader go (values it replaced or left out; none kept when null).
class Context {
 public:
  explicit Context(std::string file, std::vector<std::string>* warnings = nullptr)
      : file_(std::move(file)), warnings_(warnings) {}
  const std::string& file() const { return file_; }

  void warn(const Element* e, std::string_view message) const { warn(error(e, message).context); }
  // A message that already names file and line (an Error's context).
  void warn(std::string located) const {
    if (warnings_ != nullptr) warnings_->push_back(std::move(located));
  }

  Error error(int line, std::string_view message) const {
    return makeError(ErrorCode::kParse,
                     file_ + ", line " + std::to_string(line) + ": " + std::string(message));
  }
  Error error(const Element* e, std::string_view message) const {
    return error(e == nullptr ? 0 : e->GetLineNum(), message);
  }

 private:
  std::string file_;
  std::vector<std::string>* warnings_;
};

// Element text (first text or CDATA child), trimmed; empty when absent.
std::string_view text(const Element* e);
// Text of the first child element `name`, trimmed; empty when absent.
std::string_view childText(const Element* parent, const char* name);
// All <Name LcId=".."> (or another tag) children as local texts.
std::vector<EsiLocalText> localTexts(const Element* parent, const char* name);

// Checks the value range of an integer parsed from `what` at element `e`.
template <typename T>
Result<T> narrow(const Context& ctx, const Element* e, std::string_view what, std::string_view raw,
                 std::int64_t value) {
  if (value < static_cast<std::int64_t>(std::numeric_limits<T>::min()) ||
      (value > 0 && static_cast<std::uint64_t>(value) >
                        static_cast<std::uint64_t>(std::numeric_limits<T>::max()))) {
    return ctx.error(e, std::string(what) + " value '" + std::string(raw) + "' out of range");
  }
  return static_cast<T>(value);
}

template <typename T>
Result<T> parseNumber(const Context& ctx, const Element* e, std::string_view what,
                      std::string_view raw) {
  auto value = parseEsiInteger(raw);
  if (!value.ok()) {
    return ctx.error(e, std::string(what) + ": " + value.error().context);
  }
  return narrow<T>(ctx, e, what, raw, *value);
}

// Number in the text of child `name`; nullopt when the child is absent or empty.
template <typename T>
Result<std::optional<T>> childNumber(const Context& ctx, const Element* parent, const char* name) {
  const Element* child = parent->FirstChildElement(name);
  if (child == nullptr || text(child).empty()) return std::optional<T>{};
  ECSIM_ASSIGN_OR_RETURN(T value, parseNumber<T>(ctx, child, name, text(child)));
  return std::optional<T>{value};
}

// Number in attribute `name`; nullopt when absent or empty.
template <typename T>
Result<std::optional<T>> attrNumber(const Context& ctx, const Element* e, const char* name) {
  const char* raw = e->Attribute(name);
  if (raw == nullptr || trimEsiText(raw).empty()) return std::optional<T>{};
  ECSIM_ASSIGN_OR_RETURN(T value, parseNumber<T>(ctx, e, std::string("attribute ") + name, raw));
  return std::optional<T>{value};
}

// Boolean attribute; `fallback` when absent.
Result<bool> attrBool(const Context& ctx, const Element* e, const char* name, bool fallback);

// Hex bytes in the text of child `name`; empty when absent.
Result<std::vector<std::uint8_t>> childHex(const Context& ctx, const Element* parent,
                                           const char* name);

// tinyxml2 accepts an '&' that starts no entity reference ("AB&T"); XML does not. Reports the
// first one (text and attribute values; comments, CDATA and processing instructions are
// skipped) with its line.
Status checkEntityReferences(std::string_view xml, const Context& ctx);

// Encoding named in the XML declaration (UTF-8 when absent).
EsiEncoding declaredEncoding(std::string_view xml);

// Parses `xml` into `doc` with the checks above; errors name file and line.
Status parseDocument(std::string_view xml, const Context& ctx, tinyxml2::XMLDocument& doc);

// What an element may hold: its attributes, its child elements, and which of those children
// may appear at most once. The one table per element of a reader.
struct Names {
  std::vector<std::string_view> attributes;
  std::vector<std::string_view> children{};
  std::vector<std::string_view> once{};
};

// Our own formats (topology, scenario, master configuration) are strict: the first attribute
// or child element of `e` that `names` does not list, or a second child listed in `once`, is an
// error naming the file, the line and the closest valid name ("s.xml, line 1: unknown attribute
// 'durationMS' on <Scenario>; did you mean 'durationMs'?"; an element: "unknown element <Lnik>
// in <Topology>; did you mean <Link>?").
Status checkNames(const Context& ctx, const Element* e, const Names& names);
// Vendor formats (ESI, ENI) are tolerant: the same findings are warnings (ctx's warning list),
// every one of them, and reading goes on.
void warnUnknownNames(const Context& ctx, const Element* e, const Names& names);

}  // namespace ecsim::xml
