// A datagram the master wants carried: command, address, data and the working counter it
// expects back (EtherCrab's idea: the expectation travels with the command). The owner (a
// state machine) keeps the object; the Transport packs queued datagrams into frames, and when
// the answer arrives it copies the returned data and WKC back here (IgH's ec_datagram_t
// discipline). A Datagram is neither copied nor moved: the Transport holds its address while
// it is queued, and the destructor withdraws it.
#pragma once

#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

#include "protocol/bytes.hpp"
#include "protocol/frame.hpp"
#include "protocol/registers.hpp"
#include "protocol/result.hpp"
#include "protocol/time.hpp"

namespace ecsim::master {

class Transport;

enum class DatagramState : std::uint8_t {
  kIdle,      // prepared (or never used), not queued
  kQueued,    // waiting for room in a frame
  kSent,      // in a frame on the wire
  kReceived,  // answered: data() and wkc() hold what came back
  kTimedOut,  // no answer after every retry
  kError,     // could not be sent (too large for a frame, link refused it)
};

std::string_view toString(DatagramState state);

class Datagram {
 public:
  Datagram() = default;
  ~Datagram();
  Datagram(const Datagram&) = delete;
  Datagram& operator=(const Datagram&) = delete;

  // Prepares the datagram: data zeroed to `length` bytes (the buffer grows only when a longer
  // datagram is prepared, so a datagram reused every cycle never allocates), state kIdle.
  void prepare(Command command, std::uint32_t address, std::uint16_t length,
               std::uint16_t expectedWkc);
  void prepare(Command command, std::uint32_t address, ConstBytes data, std::uint16_t expectedWkc);

  // Shorthands (ADP/ADO as the command addresses them; expected WKC as for one slave).
  void fprd(std::uint16_t station, std::uint16_t ado, std::uint16_t length) {
    prepare(Command::kFprd, DatagramHeader::physical(station, ado), length, 1);
  }
  void fpwr(std::uint16_t station, std::uint16_t ado, ConstBytes data) {
    prepare(Command::kFpwr, DatagramHeader::physical(station, ado), data, 1);
  }
  // Typed register access (protocol/registers.hpp): the width comes from the register map,
  // never from the caller. `adp` is what `command` addresses (station, -position, 0 for
  // broadcast); expected WKC as for one slave unless given.
  template <typename T>
  void read(Command command, std::uint16_t adp, reg::Reg<T> r, std::uint16_t expectedWkc = 1) {
    prepare(command, DatagramHeader::physical(adp, r.address), r.width, expectedWkc);
  }
  // One read from `first` through `last` (values then taken with get()).
  template <typename T, typename U>
  void read(Command command, std::uint16_t adp, reg::Reg<T> first, reg::Reg<U> last,
            std::uint16_t expectedWkc = 1) {
    prepare(command, DatagramHeader::physical(adp, first.address), reg::spanWidth(first, last),
            expectedWkc);
  }
  template <typename T>
  void write(Command command, std::uint16_t adp, reg::Reg<T> r, std::type_identity_t<T> value,
             std::uint16_t expectedWkc = 1) {
    prepare(command, DatagramHeader::physical(adp, r.address), r.width, expectedWkc);
    reg::putIn(r, data(), r.address, value);
  }
  template <typename T>
  void fprd(std::uint16_t station, reg::Reg<T> r) {
    read(Command::kFprd, station, r);
  }
  template <typename T, typename U>
  void fprd(std::uint16_t station, reg::Reg<T> first, reg::Reg<U> last) {
    read(Command::kFprd, station, first, last);
  }
  template <typename T>
  void fpwr(std::uint16_t station, reg::Reg<T> r, std::type_identity_t<T> value) {
    write(Command::kFpwr, station, r, value);
  }
  // Register r in what came back; the datagram must have read it (its ADO through its end).
  template <typename T>
  T get(reg::Reg<T> r) const {
    if (r.address < ado() || r.end() > ado() + length_) return T{};  // not read: a caller's bug
    return reg::valueIn(r, data(), ado());
  }

  // Auto-increment address of the slave at `position` (0 = first): ADP = -position.
  static std::uint16_t autoIncrement(std::size_t position) {
    return static_cast<std::uint16_t>(0x10000 - (position & 0xFFFF));
  }

  Command command() const { return command_; }
  std::uint32_t address() const { return address_; }
  std::uint16_t adp() const { return static_cast<std::uint16_t>(address_); }
  std::uint16_t ado() const { return static_cast<std::uint16_t>(address_ >> 16); }
  std::uint16_t length() const { return length_; }
  Bytes data() { return Bytes(data_.data(), length_); }
  ConstBytes data() const { return ConstBytes(data_.data(), length_); }

  std::uint16_t expectedWkc() const { return expectedWkc_; }
  void setExpectedWkc(std::uint16_t wkc) { expectedWkc_ = wkc; }
  std::uint16_t wkc() const { return wkc_; }
  DatagramState state() const { return state_; }
  // Queued or on the wire: the owner waits.
  bool pending() const {
    return state_ == DatagramState::kQueued || state_ == DatagramState::kSent;
  }
  bool received() const { return state_ == DatagramState::kReceived; }
  bool wkcOk() const { return received() && wkc_ == expectedWkc_; }
  SimTime sentAt() const { return sentAt_; }
  SimTime receivedAt() const { return receivedAt_; }

  // kTimeout / kIo when no answer came, kWorkingCounter when it came with another WKC; the
  // context names command, address (and register) and both counters.
  Status check() const;
  // "FPRD 0x1001:0x0130 (AL Status) 6 bytes"
  std::string describe() const;

 private:
  friend class Transport;

  Command command_{Command::kNop};
  std::uint32_t address_{0};
  std::uint16_t length_{0};
  std::uint16_t expectedWkc_{0};
  std::uint16_t wkc_{0};
  DatagramState state_{DatagramState::kIdle};
  SimTime sentAt_{0};
  SimTime receivedAt_{0};
  std::vector<std::uint8_t> data_;
  // Transport bookkeeping: the owner while queued or sent, the intrusive queue links (both
  // ways, so that withdrawing a queued datagram does not walk the queue).
  Transport* owner_{nullptr};
  Datagram* prev_{nullptr};
  Datagram* next_{nullptr};
};

}  // namespace ecsim::master
