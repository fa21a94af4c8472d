// EtherCAT frames and datagrams (ETG.1000.4 / ESC datasheet section I §2).
//
//   Ethernet header | EtherCAT header (2 B) | datagram... | padding
//   EtherCAT header: bits 0-10 length of the datagrams, bit 11 reserved, bits 12-15 type (1).
//   Datagram: cmd(1) idx(1) address(4) len(2: bits 0-10 length, 14 circulating, 15 more)
//             irq(2) data(len) wkc(2)
//
// DatagramView is a checked view over one datagram inside a frame buffer; it reads and writes
// fields in place (the simulator processes frames on the fly). DatagramHeader is the plain
// value. parseEtherCatFrame() checks a whole frame once, after which iteration cannot run past
// the buffer.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>
#include <type_traits>

#include "protocol/bytes.hpp"
#include "protocol/ethernet.hpp"
#include "protocol/result.hpp"

namespace ecsim {

enum class Command : std::uint8_t {
  kNop = 0,
  kAprd = 1,
  kApwr = 2,
  kAprw = 3,
  kFprd = 4,
  kFpwr = 5,
  kFprw = 6,
  kBrd = 7,
  kBwr = 8,
  kBrw = 9,
  kLrd = 10,
  kLwr = 11,
  kLrw = 12,
  kArmw = 13,
  kFrmw = 14,
};

constexpr std::uint8_t kCommandCount = 15;
constexpr bool isKnownCommand(std::uint8_t raw) {
  return raw < kCommandCount;
}
std::string_view toString(Command command);

enum class AddressMode : std::uint8_t { kNone, kAutoIncrement, kConfigured, kBroadcast, kLogical };
constexpr AddressMode addressMode(Command command) {
  switch (command) {
    case Command::kAprd:
    case Command::kApwr:
    case Command::kAprw:
    case Command::kArmw:
      return AddressMode::kAutoIncrement;
    case Command::kFprd:
    case Command::kFpwr:
    case Command::kFprw:
    case Command::kFrmw:
      return AddressMode::kConfigured;
    case Command::kBrd:
    case Command::kBwr:
    case Command::kBrw:
      return AddressMode::kBroadcast;
    case Command::kLrd:
    case Command::kLwr:
    case Command::kLrw:
      return AddressMode::kLogical;
    case Command::kNop:
      return AddressMode::kNone;
  }
  return AddressMode::kNone;
}
constexpr bool isLogical(Command c) {
  return addressMode(c) == AddressMode::kLogical;
}

// What the command does with memory at the addressed slave.
struct CommandAccess {
  bool read;
  bool write;
};
// ARMW/FRMW: read at the addressed slave, write at all others (datasheet Table 7).
constexpr CommandAccess commandAccess(Command command) {
  switch (command) {
    case Command::kAprd:
    case Command::kFprd:
    case Command::kBrd:
    case Command::kLrd:
      return {true, false};
    case Command::kApwr:
    case Command::kFpwr:
    case Command::kBwr:
    case Command::kLwr:
      return {false, true};
    case Command::kAprw:
    case Command::kFprw:
    case Command::kBrw:
    case Command::kLrw:
    case Command::kArmw:
    case Command::kFrmw:
      return {true, true};
    case Command::kNop:
      return {false, false};
  }
  return {false, false};
}

constexpr std::size_t kEtherCatHeaderSize = 2;
constexpr std::size_t kDatagramHeaderSize = 10;
constexpr std::size_t kWkcSize = 2;
constexpr std::size_t kDatagramOverhead = kDatagramHeaderSize + kWkcSize;
constexpr std::uint16_t kMaxDatagramLength = 0x7FF;  // 11-bit field
constexpr std::uint8_t kEtherCatTypeDlpdu = 1;

struct EtherCatHeader {
  std::uint16_t length{0};  // 11 bits
  std::uint8_t type{kEtherCatTypeDlpdu};

  static EtherCatHeader decode(std::uint16_t raw) {
    return {static_cast<std::uint16_t>(raw & 0x07FF), static_cast<std::uint8_t>(raw >> 12)};
  }
  std::uint16_t encode() const {
    return static_cast<std::uint16_t>((length & 0x07FF) | (type << 12));
  }
};

// The most slaves one segment can address: positions (auto-increment ADP 0, -1, ...) and
// station addresses are 16 bits, station address 0 meaning none. Topology and ENI files with
// more are refused.
constexpr std::size_t kMaxSlaves = 65'535;

struct DatagramHeader {
  Command command{Command::kNop};
  std::uint8_t index{0};
  std::uint32_t address{0};  // ADP in the low 16 bits, ADO in the high 16 bits, or logical
  std::uint16_t length{0};   // 11 bits
  bool circulating{false};
  bool more{false};
  std::uint16_t irq{0};

  std::uint16_t adp() const { return static_cast<std::uint16_t>(address); }
  std::uint16_t ado() const { return static_cast<std::uint16_t>(address >> 16); }
  static std::uint32_t physical(std::uint16_t adp, std::uint16_t ado) {
    return static_cast<std::uint32_t>(adp) | (static_cast<std::uint32_t>(ado) << 16);
  }
  std::size_t wireSize() const { return kDatagramOverhead + length; }

  static DatagramHeader decode(ConstBytes tenBytes);
  void encode(Bytes tenBytes) const;
  bool operator==(const DatagramHeader&) const = default;
};

// View over one datagram: bytes_ spans header, data and WKC exactly.
template <typename Byte>
class BasicDatagramView {
 public:
  using Span = std::span<Byte>;
  BasicDatagramView() = default;
  explicit BasicDatagramView(Span bytes) : bytes_(bytes) {}

  std::uint8_t rawCommand() const { return bytes_[0]; }
  Command command() const { return static_cast<Command>(bytes_[0]); }
  std::uint8_t index() const { return bytes_[1]; }
  std::uint32_t address() const { return readLe32(bytes_, 2); }
  std::uint16_t adp() const { return readLe16(bytes_, 2); }
  std::uint16_t ado() const { return readLe16(bytes_, 4); }
  std::uint16_t length() const { return static_cast<std::uint16_t>(readLe16(bytes_, 6) & 0x7FF); }
  bool circulating() const { return (readLe16(bytes_, 6) & 0x4000) != 0; }
  bool more() const { return (readLe16(bytes_, 6) & 0x8000) != 0; }
  std::uint16_t irq() const { return readLe16(bytes_, 8); }
  Span data() const { return bytes_.subspan(kDatagramHeaderSize, length()); }
  std::uint16_t wkc() const { return readLe16(bytes_, kDatagramHeaderSize + length()); }
  DatagramHeader header() const { return DatagramHeader::decode(bytes_.first(10)); }
  Span bytes() const { return bytes_; }

  void setAdp(std::uint16_t v) requires(!std::is_const_v<Byte>) { writeLe16(bytes_, 2, v); }
  void setAddress(std::uint32_t v) requires(!std::is_const_v<Byte>) { writeLe32(bytes_, 2, v); }
  void setIrq(std::uint16_t v) requires(!std::is_const_v<Byte>) { writeLe16(bytes_, 8, v); }
  void setCirculating(bool on) requires(!std::is_const_v<Byte>) {
    std::uint16_t raw = readLe16(bytes_, 6);
    raw = static_cast<std::uint16_t>(on ? (raw | 0x4000) : (raw & ~0x4000));
    writeLe16(bytes_, 6, raw);
  }
  void setWkc(std::uint16_t v) requires(!std::is_const_v<Byte>) {
    writeLe16(bytes_, kDatagramHeaderSize + length(), v);
  }

 private:
  Span bytes_{};
};

using DatagramView = BasicDatagramView<std::uint8_t>;
using ConstDatagramView = BasicDatagramView<const std::uint8_t>;

// A checked EtherCAT frame: Ethernet header, EtherCAT header and the chain of datagrams. After
// parse() succeeded, every datagram lies inside the buffer and the more-bits end the chain.
template <typename Byte>
class BasicEtherCatFrame {
 public:
  using Span = std::span<Byte>;
  using View = BasicDatagramView<Byte>;

  class Iterator {
   public:
    Iterator() = default;
    Iterator(Span payload, std::size_t offset, bool end)
        : payload_(payload), offset_(offset), end_(end) {}
    View operator*() const { return View(current()); }
    Iterator& operator++() {
      View v(current());
      if (!v.more()) {
        end_ = true;
      } else {
        offset_ += kDatagramOverhead + v.length();
      }
      return *this;
    }
    bool operator==(const Iterator& o) const {
      return end_ == o.end_ && (end_ || offset_ == o.offset_);
    }
    std::size_t offset() const { return offset_; }

   private:
    Span current() const {
      std::uint16_t len = static_cast<std::uint16_t>(readLe16(payload_, offset_ + 6) & 0x7FF);
      return payload_.subspan(offset_, kDatagramOverhead + len);
    }
    Span payload_{};
    std::size_t offset_{0};
    bool end_{true};
  };

  // Parses and checks the frame. Accepts an optional VLAN tag. Errors name the byte offset.
  static Result<BasicEtherCatFrame> parse(Span frame);

  const EthernetHeader& ethernet() const { return ethernet_; }
  EtherCatHeader etherCatHeader() const { return ecatHeader_; }
  std::size_t etherCatOffset() const { return ethernet_.size(); }
  // Byte offset of the first datagram within the frame.
  std::size_t datagramsOffset() const { return ethernet_.size() + kEtherCatHeaderSize; }
  std::size_t datagramCount() const { return datagramCount_; }
  // Bytes used by the datagram chain (sum of header + data + WKC).
  std::size_t datagramBytes() const { return datagramBytes_; }
  Span frame() const { return frame_; }

  Iterator begin() const { return Iterator(payload(), 0, datagramCount_ == 0); }
  Iterator end() const { return Iterator(payload(), 0, true); }

 private:
  Span payload() const { return frame_.subspan(datagramsOffset()); }
  Span frame_{};
  EthernetHeader ethernet_{};
  EtherCatHeader ecatHeader_{};
  std::size_t datagramCount_{0};
  std::size_t datagramBytes_{0};
};

using EtherCatFrame = BasicEtherCatFrame<std::uint8_t>;
using ConstEtherCatFrame = BasicEtherCatFrame<const std::uint8_t>;

extern template class BasicEtherCatFrame<std::uint8_t>;
extern template class BasicEtherCatFrame<const std::uint8_t>;

// Builds a frame into a caller-owned buffer (no allocation). add() returns an error and leaves
// the frame unchanged when the datagram would not fit within kMaxFrameSize; it never
// truncates. finish() fills in the EtherCAT length, pads to the Ethernet minimum and returns
// the frame length.
class FrameBuilder {
 public:
  FrameBuilder(Bytes buffer, const EthernetHeader& ethernet);

  // Appends a datagram with zeroed data and WKC 0; returns a view to fill in its data.
  Result<DatagramView> add(Command command, std::uint8_t index, std::uint32_t address,
                           std::uint16_t dataLength, std::uint16_t irq = 0);
  // Convenience: append with the given data bytes copied in.
  Result<DatagramView> add(Command command, std::uint8_t index, std::uint32_t address,
                           ConstBytes data, std::uint16_t irq = 0);

  std::size_t datagramCount() const { return count_; }
  // Space left for the data of one more datagram (0 if not even an empty datagram fits).
  std::size_t remainingDataCapacity() const;
  Result<std::size_t> finish();

 private:
  Bytes buffer_;
  std::size_t headerSize_{0};
  std::size_t used_{0};  // bytes after the EtherCAT header
  std::size_t lastOffset_{0};
  std::size_t count_{0};
  bool headerOk_{false};
};

}  // namespace ecsim
