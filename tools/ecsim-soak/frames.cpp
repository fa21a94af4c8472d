#include "tools/ecsim-soak/frames.hpp"

#include <algorithm>

#include "protocol/esc_blocks.hpp"
#include "protocol/registers.hpp"

namespace ecsim::soak {
namespace {

constexpr std::size_t kEcatHeaderAt = kEthernetHeaderSize;
constexpr std::size_t kChainAt = kEthernetHeaderSize + kEtherCatHeaderSize;
constexpr std::uint16_t kMoreBit = 0x8000;
constexpr std::size_t kMaxDatagrams = 128;
constexpr std::uint16_t kRamStart = reg::kRegisterSpaceEnd;
// IEEE 802.3: length/type values from 0x0600 are EtherTypes. Tags that may carry EtherCAT
// inside are never used as the "other" EtherType.
constexpr std::uint16_t kEtherTypeMinimum = 0x0600;
constexpr std::uint16_t kEtherTypeQinQ = 0x88A8;
constexpr std::uint16_t kEtherTypeVlanLegacy = 0x9100;

std::uint16_t station(std::uint16_t position) {
  return static_cast<std::uint16_t>(kStationBase + position);
}
std::uint16_t autoIncrement(std::uint16_t position) {
  return static_cast<std::uint16_t>(-static_cast<int>(position));
}

EthernetHeader header(std::uint8_t marker, std::uint32_t sequence) {
  return EthernetHeader{kBroadcastMac,
                        {0x02, marker, static_cast<std::uint8_t>(sequence >> 24),
                         static_cast<std::uint8_t>(sequence >> 16),
                         static_cast<std::uint8_t>(sequence >> 8),
                         static_cast<std::uint8_t>(sequence)},
                        std::nullopt,
                        kEtherTypeEtherCat};
}

// Offset of the last datagram of a frame built by FrameBuilder, and the end of its chain.
struct ChainShape {
  std::size_t lastAt{kChainAt};
  std::size_t end{kChainAt};
};
ChainShape chainShape(const SoakFrame& f) {
  ChainShape s;
  std::size_t at = kChainAt;
  while (at + kDatagramOverhead <= f.length) {
    const std::uint16_t lenField = readLe16(ConstBytes(f.bytes.data(), f.length), at + 6);
    s.lastAt = at;
    at += kDatagramOverhead + (lenField & kMaxDatagramLength);
    s.end = at;
    if ((lenField & kMoreBit) == 0) break;
  }
  return s;
}

}  // namespace

std::string_view toString(Malformation m) {
  switch (m) {
    case Malformation::kNone: return "valid";
    case Malformation::kTruncated: return "truncated";
    case Malformation::kLengthPastEnd: return "length past end";
    case Malformation::kBrokenChain: return "broken chain";
    case Malformation::kWrongType: return "EtherCAT type not 1";
    case Malformation::kRandom: return "random bytes";
    case Malformation::kWrongEtherType: return "other EtherType";
    case Malformation::kOversized: return "oversized";
  }
  return "?";
}

FrameSource::FrameSource(std::uint64_t seed, const Network& network, unsigned malformedPercent)
    : rng_(seed), network_(network), malformedPercent_(malformedPercent) {}

void FrameSource::next(SoakFrame& out) {
  if (below(100) < malformedPercent_) {
    out.sequence = malformedCount_++;
    out.malformation = static_cast<Malformation>(1 + below(kMalformations - 1));
    buildValid(out, 1 + below(8));
    malform(out, out.malformation);
    return;
  }
  out.sequence = validCount_++;
  out.malformation = Malformation::kNone;
  // Half the frames carry one operation (short frames, the common case of a master); the
  // others up to kMaxOps, as many as fit (up to the largest frame).
  buildValid(out, below(2) == 0 ? 1 : 2 + below(kMaxOps - 1));
}

void FrameSource::single(SoakFrame& out, OpKind kind, std::uint16_t slave) {
  out.sequence = validCount_++;
  out.malformation = Malformation::kNone;
  out.opCount = 0;
  FrameBuilder b(Bytes(out.bytes.data(), kMaxFrameSize), header(kValidMarker, out.sequence));
  addOp(b, out, kind, slave);
  out.length = b.finish().valueOr(0);
}

void FrameSource::buildValid(SoakFrame& out, std::size_t maxOps) {
  const std::uint8_t marker = out.malformation == Malformation::kNone ? kValidMarker
                                                                       : kMalformedMarker;
  FrameBuilder b(Bytes(out.bytes.data(), kMaxFrameSize), header(marker, out.sequence));
  out.opCount = 0;
  while (out.opCount < maxOps) {
    const auto kind = static_cast<OpKind>(below(kOpKinds));
    if (!addOp(b, out, kind, static_cast<std::uint16_t>(below(network_.slaves)))) break;
  }
  if (out.opCount == 0) addOp(b, out, OpKind::kTypeRead, 0);
  out.length = b.finish().valueOr(0);
}

// Appends the datagrams of one operation, or nothing (false) when they do not all fit.
bool FrameSource::addOp(FrameBuilder& b, SoakFrame& out, OpKind kind, std::uint16_t slave) {
  struct Part {
    Command command;
    std::uint32_t address;
    std::uint16_t length;
    bool random;  // random data; otherwise zeros
  };
  std::array<Part, 3> parts{};
  std::size_t n = 0;
  const std::uint16_t slaves = network_.slaves;
  switch (kind) {
    case OpKind::kTypeRead:
      parts[n++] = {Command::kBrd,
                    DatagramHeader::physical(static_cast<std::uint16_t>(rng_()), reg::kType.address),
                    static_cast<std::uint16_t>(1 + below(4)), false};
      break;
    case OpKind::kAprdStation:
      parts[n++] = {Command::kAprd,
                    DatagramHeader::physical(autoIncrement(slave),
                                             reg::kConfiguredStationAddress.address),
                    2, true};
      break;
    case OpKind::kFprdStation:
      parts[n++] = {Command::kFprd,
                    DatagramHeader::physical(station(slave), reg::kConfiguredStationAddress.address),
                    2, true};
      break;
    case OpKind::kNobody: {
      const auto len = static_cast<std::uint16_t>(1 + below(16));
      const auto ado = static_cast<std::uint16_t>(below(kRamStart - len));
      parts[n++] = below(2) == 0
                       ? Part{Command::kFprd, DatagramHeader::physical(kAbsentStation, ado), len, true}
                       : Part{Command::kAprd,
                              DatagramHeader::physical(autoIncrement(slaves), ado), len, true};
      break;
    }
    case OpKind::kNop:
      parts[n++] = {Command::kNop, static_cast<std::uint32_t>(rng_()),
                    static_cast<std::uint16_t>(below(17)), true};
      break;
    case OpKind::kWriteRead:
    case OpKind::kBroadcastWrite: {
      const auto len = static_cast<std::uint16_t>(1 + below(64));
      const bool fixed = kind == OpKind::kWriteRead;
      const auto ado = static_cast<std::uint16_t>(
          kRamStart + (fixed ? kWriteReadArea : kBroadcastArea) + below(kRamWindow - len));
      const std::uint32_t address = fixed ? DatagramHeader::physical(station(slave), ado)
                                          : DatagramHeader::physical(0, ado);
      parts[n++] = {fixed ? Command::kFpwr : Command::kBwr, address, len, true};
      // FPRD gets random data (the slave overwrites it); BRD zeros (slaves OR into it).
      parts[n++] = {fixed ? Command::kFprd : Command::kBrd, address, len, fixed};
      break;
    }
    case OpKind::kLogical: {
      const std::size_t image = std::size_t{kBytesPerSlave} * slaves;
      if (image > kMaxDatagramLength) return false;
      parts[n++] = {Command::kBwr,
                    DatagramHeader::physical(0, static_cast<std::uint16_t>(kRamStart + kInputArea)),
                    kBytesPerSlave, true};
      parts[n++] = {Command::kLrw, kLogicalBase, static_cast<std::uint16_t>(image), true};
      parts[n++] = {Command::kBrd,
                    DatagramHeader::physical(0, static_cast<std::uint16_t>(kRamStart + kOutputArea)),
                    kBytesPerSlave, false};
      break;
    }
    case OpKind::kSetup:
      return false;  // built by stationAddressFrame() and fmmuFrame()
  }
  std::size_t need = 0;
  for (std::size_t i = 0; i < n; ++i) need += kDatagramOverhead + parts[i].length;
  // remainingDataCapacity() is the room for one more datagram's data, 0 when not even an
  // empty datagram fits.
  const std::size_t room = b.remainingDataCapacity();
  if (out.opCount == kMaxOps || b.datagramCount() + n >= kMaxDatagrams || room == 0 ||
      need > room + kDatagramOverhead) {
    return false;
  }
  out.ops[out.opCount++] = Op{kind, static_cast<std::uint8_t>(b.datagramCount()), slave};
  for (std::size_t i = 0; i < n; ++i) {
    auto d = b.add(parts[i].command, static_cast<std::uint8_t>(rng_()), parts[i].address,
                   parts[i].length);
    if (!d.ok()) return false;  // cannot happen: the space was checked above
    if (parts[i].random) {
      for (auto& byte : d->data()) byte = static_cast<std::uint8_t>(rng_());
    }
  }
  return true;
}

void FrameSource::malform(SoakFrame& out, Malformation m) {
  Bytes bytes(out.bytes.data(), out.bytes.size());
  const ChainShape chain = chainShape(out);
  switch (m) {
    case Malformation::kNone:
      break;
    case Malformation::kTruncated:  // cut anywhere from the EtherCAT header to the chain's end
      out.length = kEcatHeaderAt + below(static_cast<std::uint32_t>(chain.end - kEcatHeaderAt));
      break;
    case Malformation::kLengthPastEnd: {
      const std::size_t room = out.length - chain.lastAt - kDatagramOverhead;
      const auto len = static_cast<std::uint16_t>(
          room + 1 + below(static_cast<std::uint32_t>(kMaxDatagramLength - room)));
      const std::uint16_t field = readLe16(bytes, chain.lastAt + 6);
      writeLe16(bytes, chain.lastAt + 6,
                static_cast<std::uint16_t>((field & ~kMaxDatagramLength) | len));
      break;
    }
    case Malformation::kBrokenChain: {
      const std::uint16_t field = readLe16(bytes, chain.lastAt + 6);
      writeLe16(bytes, chain.lastAt + 6, static_cast<std::uint16_t>(field | kMoreBit));
      // Less than a datagram header after the chain: the next datagram cannot be there.
      out.length = chain.end + below(kDatagramOverhead);
      for (std::size_t i = chain.end; i < out.length; ++i) bytes[i] = static_cast<std::uint8_t>(rng_());
      break;
    }
    case Malformation::kWrongType: {
      std::uint8_t type = static_cast<std::uint8_t>(below(15));
      if (type >= kEtherCatTypeDlpdu) ++type;  // 0, 2..15
      const std::uint16_t raw = readLe16(bytes, kEcatHeaderAt);
      writeLe16(bytes, kEcatHeaderAt, static_cast<std::uint16_t>((raw & 0x0FFF) | (type << 12)));
      break;
    }
    case Malformation::kRandom: {
      out.length = kChainAt + below(static_cast<std::uint32_t>(kMaxFrameSize - kChainAt + 1));
      for (std::size_t i = kEcatHeaderAt; i < out.length; ++i) {
        bytes[i] = static_cast<std::uint8_t>(rng_());
      }
      const auto ecat = static_cast<std::uint16_t>((readLe16(bytes, kEcatHeaderAt) & 0x0FFF) |
                                                   (kEtherCatTypeDlpdu << 12));
      writeLe16(bytes, kEcatHeaderAt, ecat);
      // The first datagram's 2047 bytes do not fit in any Ethernet frame.
      if (out.length >= kChainAt + 8) {
        writeLe16(bytes, kChainAt + 6,
                  static_cast<std::uint16_t>(readLe16(bytes, kChainAt + 6) | kMaxDatagramLength));
      }
      break;
    }
    case Malformation::kWrongEtherType: {
      static constexpr std::array<std::uint16_t, 6> kOthers{0x0800, 0x0806, 0x86DD,
                                                            0x88A5, 0x88B8, 0x88CD};
      std::uint16_t type = kOthers[below(kOthers.size())];
      if (below(2) == 0) {
        type = static_cast<std::uint16_t>(kEtherTypeMinimum + below(0x10000 - kEtherTypeMinimum));
        // Not EtherCAT and no VLAN tag (a tagged frame may carry EtherCAT inside).
        if (type == kEtherTypeEtherCat || type == kEtherTypeVlan || type == kEtherTypeQinQ ||
            type == kEtherTypeVlanLegacy)
          type = 0x88A5;
      }
      bytes[12] = static_cast<std::uint8_t>(type >> 8);
      bytes[13] = static_cast<std::uint8_t>(type);
      break;
    }
    case Malformation::kOversized: {
      const std::size_t length =
          kMaxFrameSize + 1 + below(static_cast<std::uint32_t>(kMaxSoakFrame - kMaxFrameSize));
      std::fill(bytes.begin() + static_cast<std::ptrdiff_t>(out.length),
                bytes.begin() + static_cast<std::ptrdiff_t>(length), std::uint8_t{0});
      out.length = length;
      break;
    }
  }
}

bool answerIdentity(ConstBytes answer, std::uint8_t& marker, std::uint32_t& sequence) {
  if (answer.size() < kEthernetHeaderSize || answer[6] != 0x02) return false;
  marker = answer[7];
  sequence = (static_cast<std::uint32_t>(answer[8]) << 24) |
             (static_cast<std::uint32_t>(answer[9]) << 16) |
             (static_cast<std::uint32_t>(answer[10]) << 8) | answer[11];
  return marker == kValidMarker || marker == kMalformedMarker;
}

void stationAddressFrame(SoakFrame& out, std::uint16_t position) {
  out = SoakFrame{};
  out.sequence = 0xFFFF0000u + position;
  FrameBuilder b(Bytes(out.bytes.data(), kMaxFrameSize), header(kValidMarker, out.sequence));
  std::array<std::uint8_t, 2> data{};
  writeLe16(data, 0, station(position));
  (void)b.add(Command::kApwr, 0,
              DatagramHeader::physical(autoIncrement(position),
                                       reg::kConfiguredStationAddress.address),
              data);
  out.ops[out.opCount++] = Op{OpKind::kSetup, 0, position};
  out.length = b.finish().valueOr(0);
}

void fmmuFrame(SoakFrame& out, std::uint16_t position) {
  out = SoakFrame{};
  out.sequence = 0xFFFE0000u + position;
  FrameBuilder b(Bytes(out.bytes.data(), kMaxFrameSize), header(kValidMarker, out.sequence));
  std::array<std::uint8_t, 2 * reg::kFmmuSize> data{};
  const std::uint32_t logical = kLogicalBase + std::uint32_t{kBytesPerSlave} * position;
  const std::array<std::pair<std::uint16_t, bool>, 2> fmmus{{  // physical start, outputs
      {static_cast<std::uint16_t>(kRamStart + kOutputArea), true},
      {static_cast<std::uint16_t>(kRamStart + kInputArea), false},
  }};
  for (std::size_t k = 0; k < fmmus.size(); ++k) {
    FmmuBlock f;
    f.logicalStart = logical;
    f.length = kBytesPerSlave;
    f.physicalStart = fmmus[k].first;
    f.write = fmmus[k].second;
    f.read = !fmmus[k].second;
    f.enable = true;
    f.emit(Bytes(data).subspan(k * reg::kFmmuSize));
  }
  (void)b.add(Command::kFpwr, 0, DatagramHeader::physical(station(position), reg::fmmuChannel(0)),
              data);
  out.ops[out.opCount++] = Op{OpKind::kSetup, 0, position};
  out.length = b.finish().valueOr(0);
}

}  // namespace ecsim::soak
