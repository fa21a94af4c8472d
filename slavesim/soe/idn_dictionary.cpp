#include "slavesim/soe/idn_dictionary.hpp"

#include <limits>

namespace ecsim::slavesim::soe {
namespace {

constexpr std::uint32_t kBitsPerByte = 8;
// The AT / MDT configuration lists when the dictionary does not give them: 16 IDNs, as the
// AX5021 dictionary's S-0-0016 / S-0-0024 (BitSize 288 = 4 + 32 bytes).
constexpr std::uint16_t kDefaultConfigListBytes = 32;

std::vector<std::uint8_t> leValue(std::int64_t v, std::size_t size) {
  std::vector<std::uint8_t> out(size);
  for (std::size_t i = 0; i < size; ++i)
    out[i] = static_cast<std::uint8_t>(static_cast<std::uint64_t>(v) >> (8 * i));
  return out;
}

bool fits(std::int64_t v, std::size_t size, bool isSigned) {
  if (size >= 8) return true;
  const unsigned bits = static_cast<unsigned>(size * kBitsPerByte);
  if (isSigned) {
    const std::int64_t lo = -(std::int64_t{1} << (bits - 1));
    const std::int64_t hi = (std::int64_t{1} << (bits - 1)) - 1;
    return v >= lo && v <= hi;
  }
  return v >= 0 && v <= static_cast<std::int64_t>((std::uint64_t{1} << bits) - 1);
}

class Builder {
 public:
  Builder(std::string_view file, std::vector<std::string>* warnings)
      : file_(file), warnings_(warnings) {}

  void warn(int line, const std::string& what) {
    if (warnings_ != nullptr) {
      warnings_->push_back(std::string(file_) + ", line " + std::to_string(line) + ": " + what);
    }
  }

  // A number of the object's Info for a fixed-length entry; nullopt (with a warning) when it
  // is no number or does not fit the element.
  std::optional<std::vector<std::uint8_t>> number(const EsiObject& o, const IdnEntry& e,
                                                  const std::optional<std::string>& text,
                                                  std::string_view what) {
    if (!text) return std::nullopt;
    auto v = parseEsiInteger(*text);
    const std::size_t size = e.attribute.elementSize();
    const bool isSigned = e.attribute.dataType() == SoeDataType::kSigned;
    if (!v.ok() || !fits(*v, size, isSigned)) {
      warn(o.line, formatIdn(e.idn) + " " + std::string(what) + " '" + *text +
                       "' is not a number that fits " + e.attribute.describe() +
                       "; the element is left out");
      return std::nullopt;
    }
    return leValue(*v, size);
  }

  std::optional<IdnEntry> entry(const EsiObject& o) {
    if (o.index > std::numeric_limits<std::uint16_t>::max()) {
      warn(o.line,
           "Index " + std::to_string(o.index) + " is no IDN (0-65535); the object is left out");
      return std::nullopt;
    }
    IdnEntry e;
    e.idn = static_cast<std::uint16_t>(o.index);
    if (!o.flags.soeAttribute) {
      warn(o.line, formatIdn(e.idn) + " has no <Flags><Attribute>; the object is left out");
      return std::nullopt;
    }
    e.name = o.name();
    e.attribute = SoeAttribute{*o.flags.soeAttribute};
    e.unit = o.unitName;
    e.inAt = o.flags.txMappable();
    e.inMdt = o.flags.rxMappable();
    if (e.attribute.isList()) {
      const std::uint32_t bytes = o.bitSize / kBitsPerByte;
      if (bytes < kSoeListHeaderSize) {
        warn(o.line, formatIdn(e.idn) + " is a list of BitSize " + std::to_string(o.bitSize) +
                         ", too small for its 4-byte length header; the object is left out");
        return std::nullopt;
      }
      e.maxListLength = static_cast<std::uint16_t>(
          std::min<std::uint32_t>(bytes - static_cast<std::uint32_t>(kSoeListHeaderSize),
                                  std::numeric_limits<std::uint16_t>::max()));
      if (o.info.defaultString) {
        e.value.assign(o.info.defaultString->begin(), o.info.defaultString->end());
        if (e.value.size() > e.maxListLength) e.value.resize(e.maxListLength);
      }
      return e;
    }
    const std::size_t size = e.attribute.elementSize();
    if (o.bitSize != size * kBitsPerByte) {
      warn(o.line, formatIdn(e.idn) + " BitSize " + std::to_string(o.bitSize) +
                       " differs from its attribute's " + std::to_string(size * kBitsPerByte) +
                       " bits; the attribute is taken");
    }
    e.minimum = number(o, e, o.info.minValue, "MinValue");
    e.maximum = number(o, e, o.info.maxValue, "MaxValue");
    e.defaultValue = number(o, e, o.info.defaultValue, "DefaultValue");
    e.value = e.defaultValue.value_or(e.minimum.value_or(std::vector<std::uint8_t>(size, 0)));
    return e;
  }

 private:
  std::string_view file_;
  std::vector<std::string>* warnings_;
};

IdnEntry standardList(std::uint16_t idn, std::string name, bool writable, std::uint16_t maxBytes) {
  IdnEntry e;
  e.idn = idn;
  e.name = std::move(name);
  e.attribute = SoeAttribute::make(2, true, false, SoeDataType::kIdn, !writable, true, true);
  e.maxListLength = maxBytes;
  return e;
}

}  // namespace

std::vector<std::uint8_t> IdnEntry::valueElement() const {
  if (!attribute.isList()) return value;
  return encodeSoeList(value, maxListLength);
}

IdnEntry* IdnDictionary::find(std::uint16_t idn) {
  auto it = entries_.find(idn);
  return it == entries_.end() ? nullptr : &it->second;
}

const IdnEntry* IdnDictionary::find(std::uint16_t idn) const {
  auto it = entries_.find(idn);
  return it == entries_.end() ? nullptr : &it->second;
}

void IdnDictionary::add(IdnEntry entry) {
  const std::uint16_t idn = entry.idn;
  entries_[idn] = std::move(entry);
}

std::vector<std::uint16_t> IdnDictionary::idns() const {
  std::vector<std::uint16_t> out;
  out.reserve(entries_.size());
  for (const auto& [idn, e] : entries_) out.push_back(idn);
  return out;
}

std::vector<std::uint16_t> IdnDictionary::idnList(std::uint16_t idn) const {
  std::vector<std::uint16_t> out;
  const IdnEntry* e = find(idn);
  if (e == nullptr || !e->attribute.isList() || e->attribute.elementSize() != 2) return out;
  for (std::size_t i = 0; i + 1 < e->value.size(); i += 2) out.push_back(readLe16(e->value, i));
  return out;
}

void IdnDictionary::setIdnList(std::uint16_t idn, const std::vector<std::uint16_t>& idns) {
  IdnEntry* e = find(idn);
  if (e == nullptr) return;
  const std::size_t count = std::min<std::size_t>(idns.size(), e->maxListLength / 2);
  e->value.assign(count * 2, 0);
  for (std::size_t i = 0; i < count; ++i) writeLe16(e->value, 2 * i, idns[i]);
}

IdnDictionary buildIdnDictionary(const EsiDictionary& dictionary, std::string_view file,
                                 std::vector<std::string>* warnings) {
  Builder builder(file, warnings);
  IdnDictionary out;
  for (const EsiObject& o : dictionary.objects) {
    if (auto e = builder.entry(o)) out.add(std::move(*e));
  }
  // The lists every drive derives from its dictionary (IEC 61800-7-204 §6.3), when missing.
  const std::size_t maxIdns = out.size() + 6;
  const auto allBytes = static_cast<std::uint16_t>(2 * maxIdns);
  if (out.find(idn::kAtConfiguration) == nullptr) {
    out.add(standardList(idn::kAtConfiguration, "Configuration list of AT", true,
                         kDefaultConfigListBytes));
  }
  if (out.find(idn::kMdtConfiguration) == nullptr) {
    out.add(standardList(idn::kMdtConfiguration, "Configuration list of MDT", true,
                         kDefaultConfigListBytes));
  }
  if (out.find(idn::kAllIdns) == nullptr) {
    out.add(standardList(idn::kAllIdns, "IDN-list of all operation data", false, allBytes));
  }
  if (out.find(idn::kProcedureCommands) == nullptr) {
    out.add(standardList(idn::kProcedureCommands, "IDN-list of all procedure commands", false,
                         allBytes));
  }
  if (out.find(idn::kConfigurableAt) == nullptr) {
    out.add(standardList(idn::kConfigurableAt, "IDN-list of configurable data in the AT", false,
                         allBytes));
  }
  if (out.find(idn::kConfigurableMdt) == nullptr) {
    out.add(standardList(idn::kConfigurableMdt, "IDN-list of configurable data in the MDT", false,
                         allBytes));
  }
  std::vector<std::uint16_t> commands;
  std::vector<std::uint16_t> at;
  std::vector<std::uint16_t> mdt;
  for (std::uint16_t i : out.idns()) {
    const IdnEntry* e = out.find(i);
    if (e->attribute.isProcedureCommand()) commands.push_back(i);
    if (e->inAt) at.push_back(i);
    if (e->inMdt) mdt.push_back(i);
  }
  const std::vector<std::uint16_t> all = out.idns();
  auto fill = [&](std::uint16_t list, const std::vector<std::uint16_t>& idns) {
    const IdnEntry* e = out.find(list);
    if (e->maxListLength / 2 < idns.size() && warnings != nullptr) {
      warnings->push_back(std::string(file) + ": " + formatIdn(list) + " holds " +
                          std::to_string(e->maxListLength / 2) + " IDNs, " +
                          std::to_string(idns.size()) + " would belong in it; the first are kept");
    }
    out.setIdnList(list, idns);
  };
  fill(idn::kAllIdns, all);
  fill(idn::kProcedureCommands, commands);
  fill(idn::kConfigurableAt, at);
  fill(idn::kConfigurableMdt, mdt);
  // Power-up telegram: the configurable data, less the status / control word that travel in
  // every AT / MDT outside the lists (SOEM ecx_readIDNmap counts them separately).
  auto withoutWord = [](std::vector<std::uint16_t> idns, std::uint16_t word) {
    std::erase(idns, word);
    return idns;
  };
  auto fitting = [&](std::uint16_t list, std::vector<std::uint16_t> idns) {
    idns.resize(std::min<std::size_t>(idns.size(), out.find(list)->maxListLength / 2));
    out.setIdnList(list, idns);
  };
  if (out.find(idn::kAtConfiguration)->value.empty()) {
    fitting(idn::kAtConfiguration, withoutWord(at, idn::kDriveStatusWord));
  }
  if (out.find(idn::kMdtConfiguration)->value.empty()) {
    fitting(idn::kMdtConfiguration, withoutWord(mdt, idn::kMasterControlWord));
  }
  return out;
}

}  // namespace ecsim::slavesim::soe
