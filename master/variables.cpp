#include "master/variables.hpp"

#include <bit>
#include <cstdio>
#include <map>

#include "protocol/closest_name.hpp"
#include "protocol/coe.hpp"

namespace ecsim::master {
namespace {

// How many of the nearest names an unknown variable's error lists.
constexpr std::size_t kClosestListed = 4;

std::string hexIndex(std::uint16_t index, std::uint8_t subindex) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%04X:%02X", static_cast<unsigned>(index),
                static_cast<unsigned>(subindex));
  return buf;
}

// The SII's order string ("ECS1008", "EL2004"): short, without spaces; else the device name.
std::string siiName(const SlaveInfo& slave) {
  const auto& general = slave.siiContents.general;
  if (general && general->orderIndex != 0) {
    const std::string_view order = slave.siiContents.string(general->orderIndex);
    if (!order.empty()) return std::string(order);
  }
  return slave.name;
}

bool isSigned(VariableType t) {
  return t == VariableType::kInt8 || t == VariableType::kInt16 || t == VariableType::kInt32 ||
         t == VariableType::kInt64;
}

}  // namespace

std::string_view toString(VariableType type) {
  switch (type) {
    case VariableType::kBool:
      return "BOOL";
    case VariableType::kInt8:
      return "SINT";
    case VariableType::kUint8:
      return "USINT";
    case VariableType::kInt16:
      return "INT";
    case VariableType::kUint16:
      return "UINT";
    case VariableType::kInt32:
      return "DINT";
    case VariableType::kUint32:
      return "UDINT";
    case VariableType::kInt64:
      return "LINT";
    case VariableType::kUint64:
      return "ULINT";
    case VariableType::kReal32:
      return "REAL";
    case VariableType::kReal64:
      return "LREAL";
    case VariableType::kBits:
      return "BITS";
  }
  return "?";
}

VariableType variableType(std::uint16_t dataType, std::uint8_t bitLength) {
  switch (dataType) {  // ETG.1000.6 Table 64
    case 0x0001:
      return VariableType::kBool;
    case 0x0002:
      return VariableType::kInt8;
    case 0x0003:
      return VariableType::kInt16;
    case 0x0004:
      return VariableType::kInt32;
    case 0x0005:
      return VariableType::kUint8;
    case 0x0006:
      return VariableType::kUint16;
    case 0x0007:
      return VariableType::kUint32;
    case 0x0008:
      return VariableType::kReal32;
    case 0x0011:
      return VariableType::kReal64;
    case 0x0015:
      return VariableType::kInt64;
    case 0x001B:
      return VariableType::kUint64;
    default:
      break;
  }
  switch (bitLength) {
    case 1:
      return VariableType::kBool;
    case 8:
      return VariableType::kUint8;
    case 16:
      return VariableType::kUint16;
    case 32:
      return VariableType::kUint32;
    case 64:
      return VariableType::kUint64;
    default:
      return VariableType::kBits;
  }
}

std::uint64_t readBits(ConstBytes image, std::uint32_t bitOffset, std::uint8_t bitLength) {
  std::uint64_t value = 0;
  for (unsigned done = 0; done < bitLength;) {
    const std::uint32_t bit = bitOffset + done;
    const std::size_t byte = bit / 8;
    if (byte >= image.size()) break;
    const unsigned shift = bit % 8;
    const unsigned take = std::min(8u - shift, static_cast<unsigned>(bitLength) - done);
    const std::uint64_t part = (static_cast<unsigned>(image[byte]) >> shift) & ((1u << take) - 1u);
    value |= part << done;
    done += take;
  }
  return value;
}

void writeBits(Bytes image, std::uint32_t bitOffset, std::uint8_t bitLength, std::uint64_t value) {
  for (unsigned done = 0; done < bitLength;) {
    const std::uint32_t bit = bitOffset + done;
    const std::size_t byte = bit / 8;
    if (byte >= image.size()) break;
    const unsigned shift = bit % 8;
    const unsigned take = std::min(8u - shift, static_cast<unsigned>(bitLength) - done);
    const unsigned mask = ((1u << take) - 1u) << shift;
    const auto part = static_cast<unsigned>((value >> done) & ((1u << take) - 1u)) << shift;
    image[byte] = static_cast<std::uint8_t>((image[byte] & ~mask) | part);
    done += take;
  }
}

std::uint64_t PdoVariable::raw() const {
  return readBits(ConstBytes(image_->data(), image_->size()), info_.bitOffset, info_.bitLength);
}

void PdoVariable::setRaw(std::uint64_t value) {
  writeBits(Bytes(image_->data(), image_->size()), info_.bitOffset, info_.bitLength, value);
}

std::int64_t PdoVariable::signedValue() const {
  const std::uint64_t v = raw();
  if (!isSigned(info_.type) || info_.bitLength == 0 || info_.bitLength >= 64) {
    return static_cast<std::int64_t>(v);
  }
  const std::uint64_t sign = std::uint64_t{1} << (info_.bitLength - 1);
  return static_cast<std::int64_t>((v ^ sign) - sign);
}

double PdoVariable::asDouble() const {
  if (info_.type == VariableType::kReal32) {
    return static_cast<double>(std::bit_cast<float>(static_cast<std::uint32_t>(raw())));
  }
  if (info_.type == VariableType::kReal64) return std::bit_cast<double>(raw());
  if (isSigned(info_.type)) return static_cast<double>(signedValue());
  return static_cast<double>(raw());
}

void PdoVariable::setDouble(double value) {
  if (info_.type == VariableType::kReal32) {
    setRaw(std::bit_cast<std::uint32_t>(static_cast<float>(value)));
  } else if (info_.type == VariableType::kReal64) {
    setRaw(std::bit_cast<std::uint64_t>(value));
  } else if (isSigned(info_.type)) {
    setRaw(static_cast<std::uint64_t>(static_cast<std::int64_t>(value)));
  } else {
    setRaw(static_cast<std::uint64_t>(value));
  }
}

std::string PdoVariable::format() const {
  char buf[40];
  switch (info_.type) {
    case VariableType::kReal32:
    case VariableType::kReal64:
      std::snprintf(buf, sizeof buf, "%g", asDouble());
      return buf;
    case VariableType::kBits:
      if (info_.bitLength > 1) {
        std::snprintf(buf, sizeof buf, "0x%llX", static_cast<unsigned long long>(raw()));
        return buf;
      }
      break;
    default:
      break;
  }
  if (isSigned(info_.type)) return std::to_string(signedValue());
  return std::to_string(raw());
}

std::vector<VariableInfo> nameVariables(const ProcessImageLayout& layout,
                                        const std::vector<SlaveInfo>& slaves) {
  // Slave names, made unique.
  std::vector<std::string> names(slaves.size());
  std::map<std::string, int> uses;
  for (std::size_t i = 0; i < slaves.size(); ++i) {
    names[i] = slaves[i].configuredName.empty() ? siiName(slaves[i]) : slaves[i].configuredName;
    if (names[i].empty()) names[i] = "Slave" + std::to_string(i);
    ++uses[names[i]];
  }
  for (std::size_t i = 0; i < slaves.size(); ++i) {
    if (uses[names[i]] > 1) names[i] += "_" + std::to_string(i);
  }
  std::vector<VariableInfo> out;
  for (const auto& sl : layout.slaves) {
    const std::size_t first = out.size();
    for (const auto& sm : sl.sms) {
      if (sm.setting.length == 0) continue;
      std::uint32_t bit = (sm.logicalStart - layout.logicalBase) * 8;
      for (const auto& pdo : sm.pdos) {
        for (const auto& e : pdo.entries) {
          if (!isPaddingEntry(e.index)) {
            VariableInfo v;
            v.slave = sl.position < names.size() ? names[sl.position]
                                                 : "Slave" + std::to_string(sl.position);
            v.entry = e.name.empty() ? hexIndex(e.index, e.subindex) : e.name;
            v.name = pdo.name;  // kept until the entry names are known to be unique
            v.position = sl.position;
            v.output = sm.outputs;
            v.bitOffset = bit;
            v.bitLength = e.bitLength;
            v.index = e.index;
            v.subindex = e.subindex;
            v.dataType = e.dataType;
            v.type = variableType(e.dataType, e.bitLength);
            out.push_back(std::move(v));
          }
          bit += e.bitLength;
        }
      }
    }
    finishVariableNames(std::span(out).subspan(first));
  }
  return out;
}

void finishVariableNames(std::span<VariableInfo> slaveVariables) {
  std::map<std::string, int> entryUses;
  for (const auto& v : slaveVariables) ++entryUses[v.entry];
  for (VariableInfo& v : slaveVariables) {
    if (entryUses[v.entry] > 1 && !v.name.empty()) v.entry = v.name + "." + v.entry;
    v.name = v.slave + "." + v.entry;
  }
}

Result<VariableInfo> findVariable(const std::vector<VariableInfo>& variables,
                                  std::string_view name) {
  for (const auto& v : variables) {
    if (v.name == name) return v;
  }
  // Aliases: "<position>.<entry>", "<slave>.0xIIII:SS", "<position>.0xIIII:SS".
  for (const auto& v : variables) {
    const std::string position = std::to_string(v.position);
    const std::string index = hexIndex(v.index, v.subindex);
    if (name == position + "." + v.entry || name == v.slave + "." + index ||
        name == position + "." + index) {
      return v;
    }
  }
  std::vector<std::string_view> names;
  names.reserve(variables.size());
  for (const auto& v : variables) names.push_back(v.name);
  std::string hint;
  for (std::string_view close : closestNames(name, names, kClosestListed)) {
    hint += (hint.empty() ? "; closest: " : ", ") + std::string(close);
  }
  return makeError(ErrorCode::kNotFound, "no process variable '" + std::string(name) + "'" + hint);
}

}  // namespace ecsim::master
