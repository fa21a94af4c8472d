// ESI <Dictionary>: DataTypes (plain, arrays, records with SubItems) and Objects.
#include <cctype>

#include "config/esi_parts.hpp"

namespace ecsim::esi_detail {
namespace {

using xml::Children;
using xml::Element;

std::string lower(std::string_view s) {
  std::string out(s);
  for (auto& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

Result<EsiFlags> readFlags(const xml::Context& ctx, const Element* flags) {
  EsiFlags out;
  if (flags == nullptr) return out;
  if (const Element* access = flags->FirstChildElement("Access"); access != nullptr) {
    const std::string a = lower(xml::text(access));
    if (a == "ro") {
      out.access = EsiAccess::kReadOnly;
    } else if (a == "rw") {
      out.access = EsiAccess::kReadWrite;
    } else if (a == "wo") {
      out.access = EsiAccess::kWriteOnly;
    } else if (!a.empty()) {
      return ctx.error(access,
                       "Access '" + std::string(xml::text(access)) + "' is none of ro, rw, wo");
    }
    if (const char* r = access->Attribute("ReadRestrictions")) out.readRestrictions = r;
    if (const char* w = access->Attribute("WriteRestrictions")) out.writeRestrictions = w;
  }
  out.category = std::string(xml::childText(flags, "Category"));
  out.pdoMapping = std::string(xml::childText(flags, "PdoMapping"));
  ECSIM_ASSIGN_OR_RETURN(out.soeAttribute, xml::childNumber<std::uint32_t>(ctx, flags, "Attribute"));
  return out;
}

// DefaultData as hex bytes. A malformed one is a warning: the whole bytes before the fault are
// kept (an odd last digit, or a character that is no hex digit, ends the value there) and the
// object builder pads the rest with zeros, as for a short DefaultData.
std::vector<std::uint8_t> readDefaultData(const xml::Context& ctx, const Element* data) {
  const std::string_view raw = xml::text(data);
  auto bytes = parseEsiHexBinary(raw);
  if (bytes.ok()) return std::move(bytes).value();
  std::string digits;
  for (char c : raw) {
    if (c == ' ' || c == '\t' || c == '\r' || c == '\n') continue;
    if (std::isxdigit(static_cast<unsigned char>(c)) == 0) break;
    digits += c;
  }
  digits.resize(digits.size() / 2 * 2);
  auto kept = parseEsiHexBinary(digits);
  std::vector<std::uint8_t> out = kept.ok() ? std::move(kept).value() : std::vector<std::uint8_t>{};
  ctx.warn(data, "DefaultData '" + std::string(raw) + "': " + bytes.error().context + "; " +
                     std::to_string(out.size()) + " whole byte(s) kept");
  return out;
}

Result<EsiValueInfo> readValueInfo(const xml::Context& ctx, const Element* info) {
  EsiValueInfo out;
  if (info == nullptr) return out;
  if (const Element* data = info->FirstChildElement("DefaultData"); data != nullptr) {
    out.defaultData = readDefaultData(ctx, data);
  }
  auto optionalText = [&](const char* name) -> std::optional<std::string> {
    const Element* e = info->FirstChildElement(name);
    if (e == nullptr) return std::nullopt;
    return std::string(xml::text(e));
  };
  out.defaultValue = optionalText("DefaultValue");
  out.defaultString = optionalText("DefaultString");
  out.minValue = optionalText("MinValue");
  out.maxValue = optionalText("MaxValue");
  return out;
}

Result<EsiDataType> readDataType(const xml::Context& ctx, const Element* e) {
  EsiDataType out;
  out.name = std::string(xml::childText(e, "Name"));
  out.baseType = std::string(xml::childText(e, "BaseType"));
  ECSIM_ASSIGN_OR_RETURN(auto bitSize, xml::childNumber<std::uint32_t>(ctx, e, "BitSize"));
  out.bitSize = bitSize.value_or(0);
  for (const Element* a : Children(e, "ArrayInfo")) {
    EsiArrayInfo array;
    ECSIM_ASSIGN_OR_RETURN(auto lower_bound, xml::childNumber<std::int64_t>(ctx, a, "LBound"));
    ECSIM_ASSIGN_OR_RETURN(auto elements, xml::childNumber<std::uint32_t>(ctx, a, "Elements"));
    array.lowerBound = lower_bound.value_or(0);
    array.elements = elements.value_or(0);
    out.arrays.push_back(array);
  }
  for (const Element* s : Children(e, "SubItem")) {
    EsiSubItemType sub;
    ECSIM_ASSIGN_OR_RETURN(auto subIndex, xml::childNumber<std::uint8_t>(ctx, s, "SubIdx"));
    ECSIM_ASSIGN_OR_RETURN(auto subBits, xml::childNumber<std::uint32_t>(ctx, s, "BitSize"));
    ECSIM_ASSIGN_OR_RETURN(auto subOffset, xml::childNumber<std::uint32_t>(ctx, s, "BitOffs"));
    sub.subIndex = subIndex.value_or(0);
    sub.bitSize = subBits.value_or(0);
    sub.bitOffset = subOffset.value_or(0);
    sub.name = std::string(xml::childText(s, "Name"));
    sub.type = std::string(xml::childText(s, "Type"));
    ECSIM_ASSIGN_OR_RETURN(sub.flags, readFlags(ctx, s->FirstChildElement("Flags")));
    out.subItems.push_back(std::move(sub));
  }
  return out;
}

Result<EsiObject> readObject(const xml::Context& ctx, const Element* e) {
  EsiObject out;
  out.line = e->GetLineNum();
  ECSIM_ASSIGN_OR_RETURN(auto index, xml::childNumber<std::uint32_t>(ctx, e, "Index"));
  if (!index) return ctx.error(e, "Object without Index");
  out.index = *index;
  ECSIM_ASSIGN_OR_RETURN(out.dependOnSlot, xml::attrBool(ctx, e->FirstChildElement("Index"),
                                                         "DependOnSlot", false));
  out.names = xml::localTexts(e, "Name");
  out.type = std::string(xml::childText(e, "Type"));
  ECSIM_ASSIGN_OR_RETURN(auto bitSize, xml::childNumber<std::uint32_t>(ctx, e, "BitSize"));
  out.bitSize = bitSize.value_or(0);
  const Element* info = e->FirstChildElement("Info");
  ECSIM_ASSIGN_OR_RETURN(out.info, readValueInfo(ctx, info));
  for (const Element* s : Children(info, "SubItem")) {
    EsiSubItemInfo sub;
    sub.name = std::string(xml::childText(s, "Name"));
    ECSIM_ASSIGN_OR_RETURN(sub.info, readValueInfo(ctx, s->FirstChildElement("Info")));
    if (const Element* flags = s->FirstChildElement("Flags"); flags != nullptr) {
      ECSIM_ASSIGN_OR_RETURN(auto subFlags, readFlags(ctx, flags));
      sub.flags = std::move(subFlags);
    }
    out.subItems.push_back(std::move(sub));
  }
  ECSIM_ASSIGN_OR_RETURN(out.flags, readFlags(ctx, e->FirstChildElement("Flags")));
  for (const Element* p : Children(e->FirstChildElement("Properties"), "Property")) {
    if (xml::childText(p, "Name") != "UnitName") continue;
    const auto desc = xml::localTexts(p, "Desc");
    out.unitName = desc.empty() ? std::string(xml::childText(p, "Value"))
                                : std::string(pickLocalText(desc));
  }
  return out;
}

}  // namespace

Status readDictionary(const xml::Context& ctx, const Element* dictionary, EsiDictionary& out) {
  if (dictionary == nullptr) return okStatus();
  for (const Element* e : Children(dictionary->FirstChildElement("DataTypes"), "DataType")) {
    ECSIM_ASSIGN_OR_RETURN(auto type, readDataType(ctx, e));
    out.dataTypes.push_back(std::move(type));
  }
  for (const Element* e : Children(dictionary->FirstChildElement("Objects"), "Object")) {
    auto object = readObject(ctx, e);
    if (!object.ok()) {
      // One unreadable object (its Index, a number in its Info) costs that object only.
      ctx.warn(object.error().context + "; the object is left out");
      continue;
    }
    out.objects.push_back(std::move(object).value());
  }
  return okStatus();
}

}  // namespace ecsim::esi_detail
