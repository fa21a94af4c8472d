// EoE behind a slave's mailbox (ETG.1000.6 §5.7; wire format in protocol/eoe.hpp), as an
// EoE device with its own small IP stack (a switch port terminal's management stack, a drive's
// web server):
//
//   - Set IP Parameter (type 2): the fields the request includes replace the device's (MAC,
//     IP, subnet mask, gateway, DNS server, DNS name); answered with type 3, result 0. The
//     settings outlive a master going away (they live until the slave object does).
//   - Get IP Parameter (type 6): answered with type 7, the flags saying which fields are set.
//   - Set/Get Address Filter (4/8): answered (5/9) with result 0x0401 "no filter support".
//   - Fragment data (type 0): fragments are put back together (EoeReassembler; a broken
//     sequence drops the frame and is counted). A complete frame goes to the device's stack:
//     an ARP request for its IP gets an ARP reply, an ICMP echo request to its IP an echo
//     reply (IPv4 and ICMP checksums computed, payload kept). Other frames go out of the
//     device's Ethernet port: to the frame sink when one is set (a bridge), back to the master
//     when the port is looped back (the SOES test slave SOEM's eoe_test v1.4 expects), else
//     nowhere.
//   - Frames to the master are split into fragments that fit SM1 and sent one frame at a time
//     (the next frame's fragments only when the previous ones have left the mailbox).
// Until a master sets one, the device's MAC is the locally administered 02:00:00:00:HH:LL
// with HH:LL its station address.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <vector>

#include "protocol/eoe.hpp"
#include "slavesim/mailbox_protocol.hpp"

namespace ecsim::slavesim::eoe {

struct EoeServerOptions {
  bool loopback{false};              // frames not for the device's stack return to the master
  std::size_t maxPendingFrames{32};  // frames waiting for the mailbox; more are dropped
};

struct EoeServerCounters {
  std::uint64_t setIpRequests{0};
  std::uint64_t getIpRequests{0};
  std::uint64_t filterRequests{0};
  std::uint64_t unsupportedRequests{0};
  std::uint64_t fragmentsReceived{0};
  std::uint64_t framesReceived{0};
  std::uint64_t reassemblyErrors{0};
  std::uint64_t arpReplies{0};
  std::uint64_t echoReplies{0};
  std::uint64_t framesForwarded{0};  // to the sink or looped back
  std::uint64_t framesIgnored{0};    // nowhere to go
  std::uint64_t framesSent{0};       // to the master
  std::uint64_t framesDropped{0};    // the pending queue was full
};

class EoeServer final : public MailboxProtocol {
 public:
  using FrameSink = std::function<void(ConstBytes frame)>;

  explicit EoeServer(EoeServerOptions options = {}) : options_(options) {}

  MailboxType type() const override { return MailboxType::kEoe; }
  void onMessage(Esc& esc, const MailboxMessage& message, MailboxReplies& replies,
                 SimTime now) override;
  void poll(Esc& esc, MailboxReplies& replies, SimTime now) override;
  void reset() override;

  const EoeIpParameters& ipParameters() const { return ip_; }
  // As a Set IP Parameter request would (fields `update` includes replace the device's).
  void setIpParameters(const EoeIpParameters& update) { ip_.merge(update); }
  // The MAC the device answers with (the configured one, else the station-derived one).
  MacAddress mac(const Esc& esc) const;

  void setLoopback(bool on) { options_.loopback = on; }

  // Frames leaving the device's Ethernet port (not taken by its own stack) go here.
  void setFrameSink(FrameSink sink) { sink_ = std::move(sink); }
  // A frame entering the device's Ethernet port: it is sent to the master.
  void sendFrame(std::vector<std::uint8_t> frame);

  const EoeServerCounters& counters() const { return counters_; }

 private:
  void answer(MailboxReplies& replies, EoeFrameType type, std::uint8_t port, EoeResult result,
              ConstBytes body = {});
  void handleFrame(const Esc& esc, std::vector<std::uint8_t> frame);
  bool answerArp(const Esc& esc, ConstBytes frame, const EthernetHeader& eth);
  bool answerEcho(const Esc& esc, ConstBytes frame, const EthernetHeader& eth);
  void flush(MailboxReplies& replies);

  EoeServerOptions options_;
  EoeIpParameters ip_;
  EoeReassembler reassembler_;
  std::deque<std::vector<std::uint8_t>> pending_;  // frames to the master
  std::uint8_t port_{0};                           // the port the master last used
  std::uint8_t frameNumber_{0};
  FrameSink sink_;
  EoeServerCounters counters_{};
};

}  // namespace ecsim::slavesim::eoe
