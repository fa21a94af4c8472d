// libFuzzer target: arbitrary bytes as SyncManager (8-byte) and FMMU (16-byte) channels
// (protocol/esc_blocks.hpp). Properties, each a trap when broken:
//  - parse rejects exactly the inputs shorter than a channel;
//  - parse then emit gives the channel's bytes back, every reserved bit included;
//  - a block made field by field from the input (values out of range and reserved fields that
//    overlap defined bits included) emits bytes that parse to a block emitting the same bytes.
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "protocol/esc_blocks.hpp"
#include "tests/fuzz/mailbox_checks.hpp"

namespace {

using ecsim::ConstBytes;
using ecsim::fuzz::require;

// Input bytes consumed one at a time, 0 once they run out.
class Reader {
 public:
  explicit Reader(ConstBytes in) : in_(in) {}
  std::uint8_t u8() { return at_ < in_.size() ? in_[at_++] : 0; }
  std::uint16_t u16() { return static_cast<std::uint16_t>(u8() | (u8() << 8)); }
  std::uint32_t u32() { return static_cast<std::uint32_t>(u16() | (u16() << 16)); }
  bool flag() { return (u8() & 1) != 0; }

 private:
  ConstBytes in_;
  std::size_t at_{0};
};

template <typename Block, std::size_t N>
void roundTrip(ConstBytes in) {
  auto block = Block::parse(in);
  require(block.ok() == (in.size() >= N));
  if (!block) return;
  const std::array<std::uint8_t, N> out = block->bytes();
  require(std::memcmp(out.data(), in.data(), N) == 0);
}

template <typename Block>
void stable(const Block& made) {
  const auto bytes = made.bytes();
  auto again = Block::parse(bytes);
  require(again.ok() && again->bytes() == bytes);
}

ecsim::SyncManagerBlock smFrom(Reader& r) {
  ecsim::SyncManagerBlock s;
  s.start = r.u16();
  s.length = r.u16();
  s.control.mode = static_cast<ecsim::SmMode>(r.u8());
  s.control.direction = static_cast<ecsim::SmDirection>(r.u8());
  s.control.ecatEvent = r.flag();
  s.control.pdiEvent = r.flag();
  s.control.watchdogTrigger = r.flag();
  s.control.reserved = r.u8();
  s.status.interruptWrite = r.flag();
  s.status.interruptRead = r.flag();
  s.status.mailboxFull = r.flag();
  s.status.lastBuffer = r.u8();
  s.status.readBufferOpen = r.flag();
  s.status.writeBufferOpen = r.flag();
  s.status.reserved = r.u8();
  s.activate.enable = r.flag();
  s.activate.repeatRequest = r.flag();
  s.activate.latchEcat = r.flag();
  s.activate.latchPdi = r.flag();
  s.activate.reserved = r.u8();
  s.pdiControl.deactivate = r.flag();
  s.pdiControl.repeatAck = r.flag();
  s.pdiControl.reserved = r.u8();
  return s;
}

ecsim::FmmuBlock fmmuFrom(Reader& r) {
  ecsim::FmmuBlock f;
  f.logicalStart = r.u32();
  f.length = r.u16();
  f.logicalStartBit = r.u8();
  f.logicalStopBit = r.u8();
  f.physicalStart = r.u16();
  f.physicalStartBit = r.u8();
  f.read = r.flag();
  f.write = r.flag();
  f.typeReserved = r.u8();
  f.enable = r.flag();
  f.activateReserved = r.u8();
  for (auto& b : f.reserved) b = r.u8();
  return f;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const ConstBytes in(data, size);
  roundTrip<ecsim::SyncManagerBlock, ecsim::reg::kSmSize>(in);
  roundTrip<ecsim::FmmuBlock, ecsim::reg::kFmmuSize>(in);
  // Every channel of a 0x0800/0x0600 area read in one datagram, as the ESC decodes it.
  for (std::size_t at = 0; at + ecsim::reg::kSmSize <= size; at += ecsim::reg::kSmSize) {
    roundTrip<ecsim::SyncManagerBlock, ecsim::reg::kSmSize>(in.subspan(at));
  }
  Reader r(in);
  stable(smFrom(r));
  stable(fmmuFrom(r));
  return 0;
}
