// What an SDO read or write does to the object dictionary, with the checks a slave makes and
// the abort code for each refusal (CiA 301 §7.2.4.3.17, ETG.1000.6 Table 41):
//   object missing 0x06020000, subindex missing 0x06090011, read of write-only 0x06010001,
//   write of read-only 0x06010002, not in this state 0x08000022, length 0x06070010/12/13,
//   value above/below limits 0x06090031/32, PDO rules (below).
//
// PDO mapping (0x1600-0x17FF, 0x1A00-0x1BFF) and assignment (0x1C10-0x1C2F) objects follow the
// CiA 301 / ETG.1000.6 procedure: write sub 0 = 0, then the entries, then sub 0 = n.
//   - an entry written while sub 0 != 0: 0x06010003 (subindex cannot be written, SI0 not 0);
//   - sub 0 above the number of entries the object has: 0x06090031;
//   - mapping entry naming an object that does not exist, is not mappable in this direction
//     or has fewer bits than the mapping says: 0x06040041 (object cannot be mapped);
//   - assignment entry that is not a mapping object of the SM's direction: 0x06090030;
//   - assignment (sub 0 = n > 0) leaving out a Mandatory PDO of that SM, or combining PDOs
//     that exclude each other: 0x06040043 (general parameter incompatibility).
// Their write rights are PREOP only, so a change in SAFEOP/OP gets 0x08000022.
//
// Complete access (ETG.1000.6 §5.6.2.1.2): the object's entries from sub 0 (or 1) in subindex
// order, sub 0 taking 16 bits (8 value + 8 padding), the others their bit length, bit-packed.
#pragma once

#include <cstdint>
#include <vector>

#include "protocol/al_status.hpp"
#include "protocol/bytes.hpp"
#include "protocol/sdo.hpp"
#include "slavesim/coe/object_dictionary.hpp"

namespace ecsim::slavesim::coe {

// 0 = success, else an SDO abort code.
using SdoResult = std::uint32_t;
inline constexpr SdoResult kSdoOk = 0;
constexpr SdoResult abortCode(SdoAbortCode code) {
  return static_cast<SdoResult>(code);
}

// Finds a readable entry; on success *entry points to it.
SdoResult sdoRead(const ObjectDictionary& od, std::uint16_t index, std::uint8_t subindex,
                  AlState state, const Entry** entry);
// Writes data into an entry with every check above.
SdoResult sdoWrite(ObjectDictionary& od, std::uint16_t index, std::uint8_t subindex,
                   ConstBytes data, AlState state);
// Complete access from subindex 0 or 1 (anything else: 0x06090011).
SdoResult sdoReadComplete(const ObjectDictionary& od, std::uint16_t index, std::uint8_t subindex,
                          AlState state, std::vector<std::uint8_t>& out);
// Writes an object completely: all entries the data covers (at least up to the new sub 0
// value), then sub 0 last; nothing changes when any write is refused.
SdoResult sdoWriteComplete(ObjectDictionary& od, std::uint16_t index, std::uint8_t subindex,
                           ConstBytes data, AlState state);

// Bit copy, LSB first within bytes (the EtherCAT process-data bit order).
void copyBits(Bytes dst, std::size_t dstBit, ConstBytes src, std::size_t srcBit, std::size_t bits);

}  // namespace ecsim::slavesim::coe
