#include "master/sii_reader.hpp"

#include <algorithm>

#include "protocol/registers.hpp"
#include "protocol/sii.hpp"

namespace ecsim::master {
namespace {

// One status read covers 0x0502 (control/status), 0x0504 (address) and 0x0508 (data, 8 bytes).
constexpr std::uint16_t kStatusReadLength = static_cast<std::uint16_t>(
    reg::kSiiData.address + reg::kSiiData.width - reg::kSiiControlStatus.address);
constexpr std::size_t kDataOffset = reg::kSiiData.address - reg::kSiiControlStatus.address;

std::string hex4(std::size_t v) {
  static constexpr char kDigits[] = "0123456789ABCDEF";
  std::string s = "0x0000";
  for (int i = 0; i < 4; ++i) s[static_cast<std::size_t>(5 - i)] = kDigits[(v >> (4 * i)) & 0xF];
  return s;
}

}  // namespace

SiiReader::SiiReader(Transport& transport, std::uint16_t station, bool eightByteReads,
                     SiiReaderOptions options)
    : transport_(transport),
      station_(station),
      wordsPerRead_(eightByteReads ? 4 : 2),
      options_(options) {}

void SiiReader::start(SimTime now) {
  image_.assign(sii::kHeaderBytes, 0xFF);
  have_.assign(sii::kHeaderWords, false);
  status_ = okStatus();
  reads_ = 0;
  auto first = nextMissingWord();
  issueRead(now, first.value_or(0));
}

std::uint16_t SiiReader::word(std::size_t w) const {
  return readLe16(image_, 2 * w);
}

std::optional<std::size_t> SiiReader::nextMissingWord() const {
  for (std::size_t w = 0; w < sii::kHeaderWords; ++w) {
    if (!have(w)) return w;
  }
  // The EEPROM size the header states bounds the category walk.
  const std::size_t bytes =
      std::clamp(siiBytesForSizeField(word(sii::kWordSize)), sii::kHeaderBytes, kMaxBytes);
  const std::size_t limit = bytes / 2;
  std::size_t w = sii::kWordFirstCategory;
  while (w + 1 < limit) {
    if (!have(w)) return w;
    if (!have(w + 1)) return w + 1;
    if (word(w) == static_cast<std::uint16_t>(SiiCategoryType::kEnd)) return std::nullopt;
    const std::size_t end = std::min(limit, w + 2 + word(w + 1));
    for (std::size_t i = w + 2; i < end; ++i) {
      if (!have(i)) return i;
    }
    w += 2 + word(w + 1);
  }
  return std::nullopt;
}

void SiiReader::issueRead(SimTime now, std::size_t w) {
  current_ = w;
  retriesLeft_ = options_.retries;
  std::array<std::uint8_t, 6> command{};
  writeLe16(command, 0, reg::sii::kCommandRead);
  writeLe32(command, 2, static_cast<std::uint32_t>(w));
  datagram_.fpwr(station_, reg::kSiiControlStatus.address, command);
  transport_.queue(datagram_);
  commandAt_ = now;
  wakeAt_.reset();
  state_ = State::kCommand;
  ++reads_;
}

void SiiReader::fail(Status status) {
  status_ = std::move(status);
  state_ = State::kFailed;
  wakeAt_.reset();
}

bool SiiReader::sendAgainIfLost(const Status& status, SimTime now) {
  if (status.error().code != ErrorCode::kTimeout || now - commandAt_ > options_.busyTimeout) {
    return false;
  }
  ++framesSentAgain_;
  transport_.queue(datagram_);  // its bytes are as built: a lost frame changed nothing here
  return true;
}

bool SiiReader::step(SimTime now) {
  switch (state_) {
    case State::kIdle:
    case State::kDone:
    case State::kFailed:
      return false;
    case State::kCommand:
    case State::kClearError: {
      if (datagram_.pending()) return true;
      if (auto s = datagram_.check(); !s.ok()) {
        if (sendAgainIfLost(s, now)) return true;
        fail(makeError(s.error().code, "SII read of word " + hex4(current_) + " at station " +
                                           hex4(station_) + ": " + s.error().context));
        return false;
      }
      if (state_ == State::kClearError) {  // error cleared: issue the read again
        const unsigned left = retriesLeft_;
        issueRead(now, current_);
        retriesLeft_ = left;
        return true;
      }
      state_ = State::kStatus;
      if (options_.busyPollInterval > 0) {
        wakeAt_ = now + options_.busyPollInterval;  // the read takes the EEPROM a while
      } else {
        datagram_.fprd(station_, reg::kSiiControlStatus.address, kStatusReadLength);
        transport_.queue(datagram_);
      }
      return true;
    }
    case State::kStatus: {
      if (wakeAt_ && now < *wakeAt_) return true;
      if (wakeAt_) {  // poll interval over: read the status again
        wakeAt_.reset();
        datagram_.fprd(station_, reg::kSiiControlStatus.address, kStatusReadLength);
        transport_.queue(datagram_);
        return true;
      }
      if (datagram_.pending()) return true;
      if (auto s = datagram_.check(); !s.ok()) {
        if (sendAgainIfLost(s, now)) return true;
        fail(makeError(s.error().code,
                       "SII status of station " + hex4(station_) + ": " + s.error().context));
        return false;
      }
      const std::uint16_t status = readLe16(datagram_.data(), 0);
      if ((status & reg::sii::kBusy) != 0) {
        if (now - commandAt_ > options_.busyTimeout) {
          fail(makeError(ErrorCode::kTimeout,
                         "SII of station " + hex4(station_) + " still busy reading word " +
                             hex4(current_) + " after " +
                             std::to_string(options_.busyTimeout / kNsPerMs) + " ms"));
          return false;
        }
        if (options_.busyPollInterval > 0) {
          wakeAt_ = now + options_.busyPollInterval;
        } else {
          datagram_.fprd(station_, reg::kSiiControlStatus.address, kStatusReadLength);
          transport_.queue(datagram_);
        }
        return true;
      }
      if ((status & (reg::sii::kCommandError | reg::sii::kWriteEnableError)) != 0) {
        if (retriesLeft_ == 0) {
          fail(makeError(ErrorCode::kIo, "SII of station " + hex4(station_) + ": read of word " +
                                             hex4(current_) + " failed, status " + hex4(status)));
          return false;
        }
        --retriesLeft_;
        std::array<std::uint8_t, 2> nop{};  // a NOP command clears the error bits
        writeLe16(nop, 0, reg::sii::kCommandNop);
        datagram_.fpwr(station_, reg::kSiiControlStatus.address, nop);
        transport_.queue(datagram_);
        state_ = State::kClearError;
        return true;
      }
      // The ESC says how many bytes a read yields; trust it over what the scan assumed.
      const std::size_t words = (status & reg::sii::kReadSize8Bytes) != 0 ? 4 : wordsPerRead_;
      const std::size_t last = std::min(current_ + words, kMaxBytes / 2);
      if (image_.size() < 2 * last) image_.resize(2 * last, 0xFF);
      if (have_.size() < last) have_.resize(last, false);
      for (std::size_t w = current_; w < last; ++w) {
        image_[2 * w] = datagram_.data()[kDataOffset + 2 * (w - current_)];
        image_[2 * w + 1] = datagram_.data()[kDataOffset + 2 * (w - current_) + 1];
        have_[w] = true;
      }
      auto next = nextMissingWord();
      if (!next) {
        state_ = State::kDone;
        return false;
      }
      issueRead(now, *next);
      return true;
    }
  }
  return false;
}

}  // namespace ecsim::master
