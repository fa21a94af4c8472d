// FMMUs (datasheet section I §7): logical addressing of LRD/LWR/LRW onto physical memory.
#include "slavesim/esc.hpp"

#include <algorithm>
#include <cstring>

#include "slavesim/esc_internal.hpp"

namespace ecsim::slavesim {
using namespace esc_detail;
Esc::FmmuConfig Esc::fmmuConfig(unsigned n) const {
  return FmmuBlock::parse(ConstBytes(memory_).subspan(reg::fmmuChannel(n), reg::kFmmuSize)).value();
}

void Esc::prefetchForNextFrame(std::uint32_t address) const {
  prefetchFrameState();
  prefetchMemory(address);
  for (std::size_t i = 0; i < activeFmmuCount_; ++i) {
    prefetchMemory(activeFmmus_[i].physicalStartBit / 8);
  }
  if (!buffers_.empty()) __builtin_prefetch(buffers_.data());
}

void Esc::rebuildFmmuCache() {
  activeFmmuCount_ = 0;
  for (unsigned n = 0; n < type_.fmmus; ++n) {
    FmmuConfig f = fmmuConfig(n);
    if (!f.enable || f.length == 0 || (!f.read && !f.write)) continue;
    ActiveFmmu a;
    a.logicalStartBit = static_cast<std::uint64_t>(f.logicalStart) * 8 + (f.logicalStartBit & 7);
    a.logicalEndBit =
        (static_cast<std::uint64_t>(f.logicalStart) + f.length - 1) * 8 + (f.logicalStopBit & 7);
    if (a.logicalEndBit < a.logicalStartBit) continue;
    a.physicalStartBit = static_cast<std::uint32_t>(f.physicalStart) * 8 + (f.physicalStartBit & 7);
    a.type = static_cast<std::uint8_t>((f.read ? reg::fmmu::kTypeRead : 0) |
                                       (f.write ? reg::fmmu::kTypeWrite : 0));
    a.byteAligned = (f.logicalStartBit & 7) == 0 && (f.logicalStopBit & 7) == 7 &&
                    (f.physicalStartBit & 7) == 0;
    activeFmmus_[activeFmmuCount_++] = a;
  }
}

std::pair<bool, bool> Esc::processLogical(DatagramView d, bool doRead, bool doWrite) {
  bool readHit = false;
  bool writeHit = false;
  if (activeFmmuCount_ == 0) return {false, false};
  const std::uint64_t dStart = static_cast<std::uint64_t>(d.address()) * 8;
  const std::uint64_t dEnd = dStart + static_cast<std::uint64_t>(d.length()) * 8;  // exclusive
  Bytes data = d.data();
  // Writes first, from the incoming data, then reads: the result equals the ESC's on-the-fly
  // "read before write" for any mapping where input and output FMMUs map different physical
  // memory, including masters that overlap inputs and outputs in the logical image.
  for (int pass = 0; pass < 2; ++pass) {
    const bool writing = pass == 0;
    if (writing ? !doWrite : !doRead) continue;
    const std::uint8_t need = writing ? reg::fmmu::kTypeWrite : reg::fmmu::kTypeRead;
    for (std::uint8_t k = 0; k < activeFmmuCount_; ++k) {
      const ActiveFmmu& f = activeFmmus_[k];
      if ((f.type & need) == 0) continue;
      const std::uint64_t lo = std::max(dStart, f.logicalStartBit);
      const std::uint64_t hi = std::min(dEnd, f.logicalEndBit + 1);  // exclusive
      if (lo >= hi) continue;
      const std::uint64_t physBit = f.physicalStartBit + (lo - f.logicalStartBit);
      const std::uint64_t nBits = hi - lo;
      const std::size_t dOff = static_cast<std::size_t>((lo - dStart) / 8);
      if (f.byteAligned) {
        const auto phys = static_cast<std::uint32_t>(physBit / 8);
        const std::size_t nBytes = static_cast<std::size_t>(nBits / 8);
        bool ok = writing ? writeMemory(phys, ConstBytes(data.subspan(dOff, nBytes)))
                          : readMemory(phys, data.subspan(dOff, nBytes), false);
        (writing ? writeHit : readHit) |= ok;
        continue;
      }
      // Bit-granular mapping: gather the physical bytes covered, move bits, write back.
      const auto physFirst = static_cast<std::uint32_t>(physBit / 8);
      const auto physLast = static_cast<std::uint32_t>((physBit + nBits - 1) / 8);
      const std::size_t physBytes = physLast - physFirst + 1;
      if (physBytes > scratch_.size()) continue;
      Bytes tmp(scratch_.data(), physBytes);
      bool ok = readMemory(physFirst, tmp, false);
      if (!writing) {
        if (!ok) continue;
        for (std::uint64_t b = 0; b < nBits; ++b) {
          const std::uint64_t pb = physBit + b - static_cast<std::uint64_t>(physFirst) * 8;
          const std::uint64_t db = lo - dStart + b;
          const bool bit = (tmp[pb / 8] >> (pb % 8)) & 1;
          auto& out = data[db / 8];
          out =
              static_cast<std::uint8_t>(bit ? (out | (1u << (db % 8))) : (out & ~(1u << (db % 8))));
        }
        readHit = true;
      } else {
        for (std::uint64_t b = 0; b < nBits; ++b) {
          const std::uint64_t pb = physBit + b - static_cast<std::uint64_t>(physFirst) * 8;
          const std::uint64_t db = lo - dStart + b;
          const bool bit = (data[db / 8] >> (db % 8)) & 1;
          auto& out = tmp[pb / 8];
          out =
              static_cast<std::uint8_t>(bit ? (out | (1u << (pb % 8))) : (out & ~(1u << (pb % 8))));
        }
        writeHit |= writeMemory(physFirst, tmp);
      }
    }
  }
  return {readHit, writeHit};
}

// ---- PDI side -------------------------------------------------------------------------------

}  // namespace ecsim::slavesim
