// Explicit little-endian (and, for Ethernet, big-endian) access to byte buffers. Wire formats
// are read and written only through these helpers: no packed structs, no reinterpret_cast.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace ecsim {

using Bytes = std::span<std::uint8_t>;
using ConstBytes = std::span<const std::uint8_t>;

inline std::uint8_t readU8(ConstBytes b, std::size_t at) {
  return b[at];
}
inline std::uint16_t readLe16(ConstBytes b, std::size_t at) {
  return static_cast<std::uint16_t>(b[at] | (b[at + 1] << 8));
}
inline std::uint32_t readLe32(ConstBytes b, std::size_t at) {
  return static_cast<std::uint32_t>(b[at]) | (static_cast<std::uint32_t>(b[at + 1]) << 8) |
         (static_cast<std::uint32_t>(b[at + 2]) << 16) |
         (static_cast<std::uint32_t>(b[at + 3]) << 24);
}
inline std::uint64_t readLe64(ConstBytes b, std::size_t at) {
  return static_cast<std::uint64_t>(readLe32(b, at)) |
         (static_cast<std::uint64_t>(readLe32(b, at + 4)) << 32);
}
inline std::uint16_t readBe16(ConstBytes b, std::size_t at) {
  return static_cast<std::uint16_t>((b[at] << 8) | b[at + 1]);
}

inline void writeU8(Bytes b, std::size_t at, std::uint8_t v) {
  b[at] = v;
}
inline void writeLe16(Bytes b, std::size_t at, std::uint16_t v) {
  b[at] = static_cast<std::uint8_t>(v);
  b[at + 1] = static_cast<std::uint8_t>(v >> 8);
}
inline void writeLe32(Bytes b, std::size_t at, std::uint32_t v) {
  for (std::size_t i = 0; i < 4; ++i) b[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}
inline void writeLe64(Bytes b, std::size_t at, std::uint64_t v) {
  for (std::size_t i = 0; i < 8; ++i) b[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}
// The low `count` bytes of `v`, little-endian, as a new buffer (a register write's data; not
// for the cyclic path, it allocates).
inline std::vector<std::uint8_t> leBytes(std::uint64_t v, std::size_t count) {
  std::vector<std::uint8_t> out(count);
  for (std::size_t i = 0; i < count && i < 8; ++i) out[i] = static_cast<std::uint8_t>(v >> (8 * i));
  return out;
}
inline void writeBe16(Bytes b, std::size_t at, std::uint16_t v) {
  b[at] = static_cast<std::uint8_t>(v >> 8);
  b[at + 1] = static_cast<std::uint8_t>(v);
}

}  // namespace ecsim
