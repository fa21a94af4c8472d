// FoE client (ETG.1000.6 §5.7) over MailboxExchange, as a non-blocking state machine:
//
//   write  WRQ(password, name), wait for ACK 0; then DATA 1, 2, ... of (SM0 length - 12)
//          bytes, each answered by ACK n; the file ends with a packet shorter than that (an
//          empty one when its size is a multiple of it). BUSY from the slave: the same packet
//          is sent again (at most maxBusy times in a row).
//   read   RRQ(password, name); DATA n is answered with ACK n until a packet shorter than
//          (SM1 length - 12); the last ACK is sent without waiting for an answer.
//   An ERR from the slave ends the transfer with kAborted, its code, its text and the code's
//   meaning ("0x8001 (not found)"); an answer out of turn ends it with kMalformed.
// The slave's mailbox (SlaveInfo::mailbox) is used as it is: in BOOT, the bootstrap layout
// (Master::enterBootstrap).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "master/mailbox_exchange.hpp"
#include "protocol/foe.hpp"

namespace ecsim::master {

class FoeTask final : public Task {
 public:
  FoeTask(Transport& transport, SlaveInfo& slave, std::vector<ReceivedEmergency>* emergencies,
          MailboxOptions options = {});

  Status startWrite(const std::string& name, std::uint32_t password, ConstBytes data,
                    SimTime now);
  Status startRead(const std::string& name, std::uint32_t password, SimTime now);

  bool step(SimTime now) override;
  std::optional<SimTime> wakeAt() const override { return exchange_.wakeAt(); }
  bool done() const { return state_ == State::kDone; }
  const Status& status() const { return status_; }
  std::optional<std::uint32_t> errorCode() const { return errorCode_; }
  const std::vector<std::uint8_t>& data() const { return data_; }  // read: the file
  std::uint32_t packets() const { return packet_; }
  std::uint64_t busyAnswers() const { return busy_; }

  static constexpr unsigned kMaxBusyInARow = 1000;

 private:
  enum class State { kIdle, kWriteRequest, kWriteData, kRead, kFinalAck, kDone };

  bool fail(ErrorCode code, const std::string& what);
  bool sendPacket(SimTime now);
  bool onAnswer(const FoePacket& p, SimTime now);

  MailboxExchange exchange_;
  SlaveInfo& slave_;
  State state_{State::kIdle};
  Status status_;
  std::string name_;
  bool write_{true};
  std::vector<std::uint8_t> data_;
  std::size_t offset_{0};     // write: bytes acknowledged
  std::size_t inFlight_{0};   // write: bytes of the packet sent
  std::uint32_t packet_{0};   // write: last packet sent; read: last packet received
  std::optional<std::uint32_t> errorCode_;
  std::uint64_t busy_{0};
  unsigned busyInARow_{0};
  std::vector<std::uint8_t> message_;
};

}  // namespace ecsim::master
