#include "slavesim/coe/sdo_access.hpp"

#include <algorithm>

#include "slavesim/coe/standard_objects.hpp"

namespace ecsim::slavesim::coe {
namespace {

constexpr SdoResult kNoObject = abortCode(SdoAbortCode::kObjectDoesNotExist);
constexpr SdoResult kNoSubindex = abortCode(SdoAbortCode::kSubindexDoesNotExist);

SdoResult checkReadable(const Entry& e, AlState state) {
  if (!e.readableSomewhere()) return abortCode(SdoAbortCode::kReadOfWriteOnly);
  if (!e.readable(state)) return abortCode(SdoAbortCode::kDataCannotBeTransferredDeviceState);
  return kSdoOk;
}

SdoResult checkWritable(const Entry& e, AlState state) {
  if (!e.writableSomewhere()) return abortCode(SdoAbortCode::kWriteOfReadOnly);
  if (!e.writable(state)) return abortCode(SdoAbortCode::kDataCannotBeTransferredDeviceState);
  return kSdoOk;
}

std::uint8_t smTypeOf(const ObjectDictionary& od, unsigned sm) {
  const Entry* e = od.findEntry(kSmTypesIndex, static_cast<std::uint8_t>(sm + 1));
  return e == nullptr || e->value.empty() ? kSmTypeUnused : e->value[0];
}

SdoResult checkMappingEntry(const ObjectDictionary& od, std::uint16_t mappingIndex,
                            std::uint32_t raw) {
  const MappedObject m = MappedObject::fromRaw(raw);
  if (m.index == 0) return kSdoOk;  // a gap
  if (m.isPadding()) {  // a dummy entry: subindex 0 and exactly its type's length
    return m.subindex == 0 && m.bitLength == dummyEntryBits(m.index)
               ? kSdoOk
               : abortCode(SdoAbortCode::kObjectCannotBeMapped);
  }
  const Entry* e = od.findEntry(m.index, m.subindex);
  const bool rx = isRxPdoMappingIndex(mappingIndex);
  // A mapping may take fewer bits than the entry has (Beckhoff maps 64-bit latch times with 32
  // bits in alternative PDOs); never more.
  if (e == nullptr || (rx ? !e->rxMappable() : !e->txMappable()) || m.bitLength == 0 ||
      m.bitLength > e->bitLength) {
    return abortCode(SdoAbortCode::kObjectCannotBeMapped);
  }
  return kSdoOk;
}

SdoResult checkAssignEntry(const ObjectDictionary& od, unsigned sm, std::uint16_t pdo) {
  const std::uint8_t type = smTypeOf(od, sm);
  const bool ok = od.contains(pdo) && (type == kSmTypeOutputs  ? isRxPdoMappingIndex(pdo)
                                       : type == kSmTypeInputs ? isTxPdoMappingIndex(pdo)
                                                               : isPdoMappingIndex(pdo));
  return ok ? kSdoOk : abortCode(SdoAbortCode::kValueRangeExceeded);
}

// Sub 0 = n of a mapping or assignment object: every entry 1..n must be valid together.
SdoResult checkActivation(const ObjectDictionary& od, const Object& o, std::uint8_t n) {
  if (n > o.maxSubindex()) return abortCode(SdoAbortCode::kValueTooHigh);
  if (n == 0) return kSdoOk;
  std::vector<std::uint32_t> values;
  for (std::uint8_t i = 1; i <= n; ++i) {
    const Entry* e = o.entry(i);
    if (e == nullptr) return abortCode(SdoAbortCode::kValueTooHigh);
    values.push_back(static_cast<std::uint32_t>(readRawValue(e->value, e->bitLength)));
  }
  if (isPdoMappingIndex(o.index)) {
    for (std::uint32_t raw : values) {
      if (SdoResult r = checkMappingEntry(od, o.index, raw); r != kSdoOk) return r;
    }
    return kSdoOk;
  }
  const unsigned sm = o.index - kPdoAssignBase;
  for (std::uint32_t raw : values) {
    if (SdoResult r = checkAssignEntry(od, sm, static_cast<std::uint16_t>(raw)); r != kSdoOk) {
      return r;
    }
  }
  auto assigned = [&](std::uint16_t pdo) {
    return std::find(values.begin(), values.end(), pdo) != values.end();
  };
  for (std::uint32_t raw : values) {
    const PdoRules* rules = od.findPdoRules(static_cast<std::uint16_t>(raw));
    if (rules == nullptr) continue;
    for (std::uint16_t other : rules->excludes) {
      if (other != raw && assigned(other)) {
        return abortCode(SdoAbortCode::kGeneralParameterIncompatibility);
      }
    }
  }
  for (const auto& [pdo, rules] : od.allPdoRules()) {
    if (rules.mandatory && rules.defaultSm && *rules.defaultSm == sm && !assigned(pdo)) {
      return abortCode(SdoAbortCode::kGeneralParameterIncompatibility);
    }
  }
  return kSdoOk;
}

SdoResult checkPdoObjectWrite(const ObjectDictionary& od, const Object& o, std::uint8_t sub,
                              ConstBytes value) {
  if (sub == 0) return checkActivation(od, o, value.empty() ? 0 : value[0]);
  const Entry* sub0 = o.entry(0);
  if (sub0 != nullptr && !sub0->value.empty() && sub0->value[0] != 0) {
    return abortCode(SdoAbortCode::kSubindexCannotBeWritten);
  }
  const auto raw = static_cast<std::uint32_t>(readRawValue(value, 32));
  if (isPdoMappingIndex(o.index)) return checkMappingEntry(od, o.index, raw);
  return checkAssignEntry(od, o.index - kPdoAssignBase, static_cast<std::uint16_t>(raw));
}

std::size_t caBits(const Entry& e) {
  return e.subindex == 0 ? 16 : e.bitLength;
}

}  // namespace

void copyBits(Bytes dst, std::size_t dstBit, ConstBytes src, std::size_t srcBit, std::size_t bits) {
  if (dstBit % 8 == 0 && srcBit % 8 == 0) {
    const std::size_t whole = bits / 8;
    std::copy_n(src.begin() + static_cast<std::ptrdiff_t>(srcBit / 8), whole,
                dst.begin() + static_cast<std::ptrdiff_t>(dstBit / 8));
    dstBit += 8 * whole;
    srcBit += 8 * whole;
    bits -= 8 * whole;
  }
  for (std::size_t i = 0; i < bits; ++i) {
    const std::size_t s = srcBit + i;
    const std::size_t d = dstBit + i;
    const bool bit = ((src[s / 8] >> (s % 8)) & 1u) != 0;
    auto& byte = dst[d / 8];
    const auto mask = static_cast<std::uint8_t>(1u << (d % 8));
    byte = static_cast<std::uint8_t>(bit ? (byte | mask) : (byte & ~mask));
  }
}

SdoResult sdoRead(const ObjectDictionary& od, std::uint16_t index, std::uint8_t subindex,
                  AlState state, const Entry** entry) {
  const Object* o = od.find(index);
  if (o == nullptr) return kNoObject;
  const Entry* e = o->entry(subindex);
  if (e == nullptr) return kNoSubindex;
  if (SdoResult r = checkReadable(*e, state); r != kSdoOk) return r;
  *entry = e;
  return kSdoOk;
}

SdoResult sdoWrite(ObjectDictionary& od, std::uint16_t index, std::uint8_t subindex,
                   ConstBytes data, AlState state) {
  Object* o = od.find(index);
  if (o == nullptr) return kNoObject;
  Entry* e = o->entry(subindex);
  if (e == nullptr) return kNoSubindex;
  if (SdoResult r = checkWritable(*e, state); r != kSdoOk) return r;
  const std::size_t size = e->byteSize();
  if (data.size() > size) return abortCode(SdoAbortCode::kDataTypeLengthTooHigh);
  if (data.size() < size && !isStringType(e->dataType)) {
    return abortCode(SdoAbortCode::kDataTypeLengthTooLow);
  }
  std::vector<std::uint8_t> value(size, 0);
  std::copy(data.begin(), data.end(), value.begin());
  if (!isStringType(e->dataType)) {
    if (!e->maximum.empty() && compareValues(e->dataType, e->bitLength, value, e->maximum) > 0) {
      return abortCode(SdoAbortCode::kValueTooHigh);
    }
    if (!e->minimum.empty() && compareValues(e->dataType, e->bitLength, value, e->minimum) < 0) {
      return abortCode(SdoAbortCode::kValueTooLow);
    }
    if (e->bitLength < 8 * size && size > 0 &&
        readRawValue(value, 64) != readRawValue(value, e->bitLength)) {
      return abortCode(SdoAbortCode::kValueRangeExceeded);  // bits beyond a BITn/BOOL entry
    }
  }
  if (isPdoMappingIndex(index) || isPdoAssignIndex(index)) {
    if (SdoResult r = checkPdoObjectWrite(od, *o, subindex, value); r != kSdoOk) return r;
  }
  std::copy(value.begin(), value.end(), e->value.begin());
  return kSdoOk;
}

SdoResult sdoReadComplete(const ObjectDictionary& od, std::uint16_t index, std::uint8_t subindex,
                          AlState state, std::vector<std::uint8_t>& out) {
  const Object* o = od.find(index);
  if (o == nullptr) return kNoObject;
  if (subindex > 1) return kNoSubindex;
  if (o->code == ObjectCode::kVar) {
    const Entry* e = nullptr;
    if (SdoResult r = sdoRead(od, index, 0, state, &e); r != kSdoOk) return r;
    out = e->value;
    return kSdoOk;
  }
  std::size_t bits = 0;
  for (const Entry& e : o->entries) {
    if (e.subindex < subindex) continue;
    if (SdoResult r = checkReadable(e, state); r != kSdoOk) return r;
    bits += caBits(e);
  }
  out.assign((bits + 7) / 8, 0);
  std::size_t pos = 0;
  for (const Entry& e : o->entries) {
    if (e.subindex < subindex) continue;
    copyBits(out, pos, e.value, 0, e.subindex == 0 ? 8 : e.bitLength);
    pos += caBits(e);
  }
  return kSdoOk;
}

SdoResult sdoWriteComplete(ObjectDictionary& od, std::uint16_t index, std::uint8_t subindex,
                           ConstBytes data, AlState state) {
  Object* o = od.find(index);
  if (o == nullptr) return kNoObject;
  if (subindex > 1) return kNoSubindex;
  if (o->code == ObjectCode::kVar) return sdoWrite(od, index, 0, data, state);
  Entry* sub0 = o->entry(0);
  const bool withSub0 = subindex == 0 && sub0 != nullptr;
  if (withSub0 && data.size() < 2) return abortCode(SdoAbortCode::kDataTypeLengthTooLow);
  const std::uint8_t newCount =
      withSub0 ? data[0] : (sub0 != nullptr && !sub0->value.empty() ? sub0->value[0] : 0);
  // Which entries does the data cover?
  std::size_t pos = withSub0 ? 16 : 0;
  std::vector<std::pair<Entry*, std::size_t>> covered;  // entry, bit offset in data
  for (Entry& e : o->entries) {
    if (e.subindex == 0) continue;
    if (pos + e.bitLength > 8 * data.size()) break;
    covered.emplace_back(&e, pos);
    pos += e.bitLength;
  }
  if ((pos + 7) / 8 != data.size()) {
    std::size_t entries = 0;
    for (const Entry& e : o->entries) entries += e.subindex == 0 ? 0 : 1;
    // Longer than the whole object: too high; ending inside an entry: a mismatch.
    return abortCode(covered.size() == entries ? SdoAbortCode::kDataTypeLengthTooHigh
                                               : SdoAbortCode::kDataTypeMismatch);
  }
  if (!covered.empty() ? covered.back().first->subindex < newCount : newCount > 0) {
    return abortCode(SdoAbortCode::kDataTypeLengthTooLow);
  }
  // Apply in procedure order, undo everything on a refusal.
  std::vector<std::vector<std::uint8_t>> before;
  for (const Entry& e : o->entries) before.push_back(e.value);
  auto undo = [&](SdoResult r) {
    for (std::size_t i = 0; i < o->entries.size(); ++i) o->entries[i].value = before[i];
    return r;
  };
  const bool pdoObject = isPdoMappingIndex(index) || isPdoAssignIndex(index);
  if (withSub0 && pdoObject) {
    const std::uint8_t zero = 0;
    if (SdoResult r = sdoWrite(od, index, 0, ConstBytes(&zero, 1), state); r != kSdoOk) {
      return undo(r);
    }
  }
  for (auto [e, bit] : covered) {
    std::vector<std::uint8_t> value(e->byteSize(), 0);
    copyBits(value, 0, data, bit, e->bitLength);
    if (value == e->value && !e->writable(state)) continue;  // unchanged read-only entry
    if (SdoResult r = sdoWrite(od, index, e->subindex, value, state); r != kSdoOk) return undo(r);
  }
  if (withSub0) {
    const bool unchanged = pdoObject ? false : sub0->value[0] == newCount;
    if (!(unchanged && !sub0->writable(state))) {
      if (SdoResult r = sdoWrite(od, index, 0, ConstBytes(&newCount, 1), state); r != kSdoOk) {
        return undo(r);
      }
    }
  }
  return kSdoOk;
}

}  // namespace ecsim::slavesim::coe
