#include "protocol/frame.hpp"

#include <algorithm>
#include <string>

namespace ecsim {

std::string_view toString(Command command) {
  switch (command) {
    case Command::kNop:
      return "NOP";
    case Command::kAprd:
      return "APRD";
    case Command::kApwr:
      return "APWR";
    case Command::kAprw:
      return "APRW";
    case Command::kFprd:
      return "FPRD";
    case Command::kFpwr:
      return "FPWR";
    case Command::kFprw:
      return "FPRW";
    case Command::kBrd:
      return "BRD";
    case Command::kBwr:
      return "BWR";
    case Command::kBrw:
      return "BRW";
    case Command::kLrd:
      return "LRD";
    case Command::kLwr:
      return "LWR";
    case Command::kLrw:
      return "LRW";
    case Command::kArmw:
      return "ARMW";
    case Command::kFrmw:
      return "FRMW";
  }
  return "unknown";
}

DatagramHeader DatagramHeader::decode(ConstBytes b) {
  DatagramHeader h;
  h.command = static_cast<Command>(b[0]);
  h.index = b[1];
  h.address = readLe32(b, 2);
  std::uint16_t lenField = readLe16(b, 6);
  h.length = static_cast<std::uint16_t>(lenField & 0x7FF);
  h.circulating = (lenField & 0x4000) != 0;
  h.more = (lenField & 0x8000) != 0;
  h.irq = readLe16(b, 8);
  return h;
}

void DatagramHeader::encode(Bytes b) const {
  b[0] = static_cast<std::uint8_t>(command);
  b[1] = index;
  writeLe32(b, 2, address);
  std::uint16_t lenField = static_cast<std::uint16_t>(
      (length & 0x7FF) | (circulating ? 0x4000 : 0) | (more ? 0x8000 : 0));
  writeLe16(b, 6, lenField);
  writeLe16(b, 8, irq);
}

template <typename Byte>
Result<BasicEtherCatFrame<Byte>> BasicEtherCatFrame<Byte>::parse(Span frame) {
  auto eth = EthernetHeader::parse(frame);
  if (!eth) return eth.takeError();
  if (eth->etherType != kEtherTypeEtherCat) {
    return makeError(ErrorCode::kMalformed,
                     "byte " + std::to_string(eth->size() - 2) + ": EtherType is not 0x88A4");
  }
  BasicEtherCatFrame f;
  f.frame_ = frame;
  f.ethernet_ = *eth;
  std::size_t at = eth->size();
  if (frame.size() < at + kEtherCatHeaderSize) {
    return makeError(ErrorCode::kTruncated,
                     "byte " + std::to_string(at) + ": EtherCAT header truncated");
  }
  f.ecatHeader_ = EtherCatHeader::decode(readLe16(frame, at));
  if (f.ecatHeader_.type != kEtherCatTypeDlpdu) {
    return makeError(ErrorCode::kUnsupported,
                     "byte " + std::to_string(at + 1) + ": EtherCAT type " +
                         std::to_string(f.ecatHeader_.type) + " is not 1 (DLPDU)");
  }
  at += kEtherCatHeaderSize;
  const std::size_t start = at;
  while (true) {
    if (frame.size() < at + kDatagramOverhead) {
      return makeError(ErrorCode::kTruncated, "byte " + std::to_string(at) + ": datagram " +
                                                  std::to_string(f.datagramCount_) +
                                                  " header truncated");
    }
    std::uint16_t lenField = readLe16(frame, at + 6);
    std::size_t len = lenField & 0x7FF;
    if (frame.size() < at + kDatagramOverhead + len) {
      return makeError(ErrorCode::kTruncated, "byte " + std::to_string(at + 6) + ": datagram " +
                                                  std::to_string(f.datagramCount_) + " length " +
                                                  std::to_string(len) + " runs past frame end");
    }
    ++f.datagramCount_;
    at += kDatagramOverhead + len;
    if ((lenField & 0x8000) == 0) break;
  }
  f.datagramBytes_ = at - start;
  return f;
}

template class BasicEtherCatFrame<std::uint8_t>;
template class BasicEtherCatFrame<const std::uint8_t>;

FrameBuilder::FrameBuilder(Bytes buffer, const EthernetHeader& ethernet) : buffer_(buffer) {
  headerSize_ = ethernet.size() + kEtherCatHeaderSize;
  headerOk_ = buffer_.size() >= headerSize_ && ethernet.write(buffer_).ok();
}

std::size_t FrameBuilder::remainingDataCapacity() const {
  std::size_t limit = std::min(buffer_.size(), kMaxFrameSize);
  std::size_t usedTotal = headerSize_ + used_ + kDatagramOverhead;
  return usedTotal > limit ? 0 : limit - usedTotal;
}

Result<DatagramView> FrameBuilder::add(Command command, std::uint8_t index, std::uint32_t address,
                                       std::uint16_t dataLength, std::uint16_t irq) {
  if (!headerOk_) return makeError(ErrorCode::kTooLarge, "frame buffer too small for headers");
  if (dataLength > kMaxDatagramLength) {
    return makeError(ErrorCode::kTooLarge,
                     "datagram length " + std::to_string(dataLength) + " exceeds 11-bit field");
  }
  std::size_t limit = std::min(buffer_.size(), kMaxFrameSize);
  std::size_t need = headerSize_ + used_ + kDatagramOverhead + dataLength;
  if (need > limit) {
    return makeError(ErrorCode::kTooLarge, "datagram of " + std::to_string(dataLength) +
                                               " data bytes does not fit: frame would be " +
                                               std::to_string(need) + " bytes, limit " +
                                               std::to_string(limit));
  }
  if (count_ > 0) {  // chain: set the previous datagram's more bit
    std::size_t prev = headerSize_ + lastOffset_ + 6;
    writeLe16(buffer_, prev, static_cast<std::uint16_t>(readLe16(buffer_, prev) | 0x8000));
  }
  std::size_t at = headerSize_ + used_;
  DatagramHeader h;
  h.command = command;
  h.index = index;
  h.address = address;
  h.length = dataLength;
  h.irq = irq;
  h.encode(buffer_.subspan(at, kDatagramHeaderSize));
  std::fill_n(buffer_.begin() + static_cast<std::ptrdiff_t>(at + kDatagramHeaderSize),
              dataLength + kWkcSize, 0);
  lastOffset_ = used_;
  used_ += kDatagramOverhead + dataLength;
  ++count_;
  return DatagramView(buffer_.subspan(at, kDatagramOverhead + dataLength));
}

Result<DatagramView> FrameBuilder::add(Command command, std::uint8_t index, std::uint32_t address,
                                       ConstBytes data, std::uint16_t irq) {
  if (data.size() > kMaxDatagramLength) {
    return makeError(ErrorCode::kTooLarge,
                     "datagram length " + std::to_string(data.size()) + " exceeds 11-bit field");
  }
  auto view = add(command, index, address, static_cast<std::uint16_t>(data.size()), irq);
  if (!view) return view;
  std::copy(data.begin(), data.end(), view->data().begin());
  return view;
}

Result<std::size_t> FrameBuilder::finish() {
  if (!headerOk_) return makeError(ErrorCode::kTooLarge, "frame buffer too small for headers");
  if (count_ == 0) return makeError(ErrorCode::kInvalidArgument, "frame has no datagram");
  EtherCatHeader h{static_cast<std::uint16_t>(used_), kEtherCatTypeDlpdu};
  writeLe16(buffer_, headerSize_ - kEtherCatHeaderSize, h.encode());
  std::size_t total = headerSize_ + used_;
  if (total < kMinFrameSize) {
    if (buffer_.size() < kMinFrameSize) {
      return makeError(ErrorCode::kTooLarge, "buffer shorter than minimum Ethernet frame");
    }
    std::fill(buffer_.begin() + static_cast<std::ptrdiff_t>(total),
              buffer_.begin() + static_cast<std::ptrdiff_t>(kMinFrameSize), 0);
    total = kMinFrameSize;
  }
  return total;
}

}  // namespace ecsim
