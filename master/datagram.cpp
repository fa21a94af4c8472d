#include "master/datagram.hpp"

#include <algorithm>
#include <cstdio>

#include "master/transport.hpp"
#include "protocol/registers.hpp"

namespace ecsim::master {
namespace {

std::string hex(std::uint32_t value, int digits) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%0*X", digits, value);
  return buf;
}

}  // namespace

std::string_view toString(DatagramState state) {
  switch (state) {
    case DatagramState::kIdle:
      return "idle";
    case DatagramState::kQueued:
      return "queued";
    case DatagramState::kSent:
      return "sent";
    case DatagramState::kReceived:
      return "received";
    case DatagramState::kTimedOut:
      return "timed out";
    case DatagramState::kError:
      return "error";
  }
  return "unknown";
}

Datagram::~Datagram() {
  if (owner_ != nullptr) owner_->cancel(*this);
}

void Datagram::prepare(Command command, std::uint32_t address, std::uint16_t length,
                       std::uint16_t expectedWkc) {
  if (owner_ != nullptr) owner_->cancel(*this);
  command_ = command;
  address_ = address;
  length_ = length;
  expectedWkc_ = expectedWkc;
  wkc_ = 0;
  state_ = DatagramState::kIdle;
  if (data_.size() < length) data_.resize(length);
  std::fill_n(data_.begin(), length, std::uint8_t{0});
}

void Datagram::prepare(Command command, std::uint32_t address, ConstBytes data,
                       std::uint16_t expectedWkc) {
  const auto length = static_cast<std::uint16_t>(std::min<std::size_t>(data.size(), 0xFFFF));
  prepare(command, address, length, expectedWkc);
  std::copy_n(data.begin(), length, data_.begin());
}

std::string Datagram::describe() const {
  std::string s(toString(command_));
  switch (addressMode(command_)) {
    case AddressMode::kLogical:
      s += " logical " + hex(address_, 8);
      break;
    case AddressMode::kAutoIncrement:
    case AddressMode::kConfigured:
    case AddressMode::kBroadcast:
    case AddressMode::kNone: {
      s += " " + hex(adp(), 4) + ":" + hex(ado(), 4);
      if (auto r = reg::findRegister(ado()); r && addressMode(command_) != AddressMode::kNone) {
        s += " (" + std::string(r->name) + ")";
      }
      break;
    }
  }
  s += " " + std::to_string(length_) + " bytes";
  return s;
}

Status Datagram::check() const {
  switch (state_) {
    case DatagramState::kReceived:
      if (wkc_ == expectedWkc_) return okStatus();
      return makeError(ErrorCode::kWorkingCounter, describe() + ": working counter " +
                                                       std::to_string(wkc_) + ", expected " +
                                                       std::to_string(expectedWkc_));
    case DatagramState::kTimedOut:
      return makeError(ErrorCode::kTimeout, describe() + ": no answer (frame lost)");
    case DatagramState::kError:
      return makeError(ErrorCode::kIo, describe() + ": could not be sent");
    case DatagramState::kIdle:
    case DatagramState::kQueued:
    case DatagramState::kSent:
      break;
  }
  return makeError(ErrorCode::kState,
                   describe() + ": not answered yet (" + std::string(toString(state_)) + ")");
}

}  // namespace ecsim::master
