// Reads one slave's SII EEPROM through the ESC's EEPROM interface (ESC datasheet section I
// §11.2; register use as notes/soem-interop.md §3.2 describes it), as a non-blocking state
// machine:
//
//   FPWR 0x0502 {u16 read command, u32 word address}   the ESC starts the read
//   (wait busyPollInterval)                            the EEPROM needs 0.5-0.8 ms
//   FPRD 0x0502..0x050F                                status, address and 4 or 8 data bytes
//     busy (0x0502 bit 15)       wait busyPollInterval, read again, up to `busyTimeout`
//     error bits (0x7800)        clear them with a NOP command and retry, `retries` times
//
// A frame of this handshake that the transport gave up (every try unanswered: a stall of the
// host, a disturbed wire) is sent again while the word's read is within `busyTimeout` of its
// command, as SOEM reads the status again until EC_TIMEOUTEEP whatever became of the last
// frame (ecx_eeprom_waitnotbusyFP: "wkc <= 0 || busy") and sends the command up to
// EC_DEFAULTRETRIES + 1 times (ecx_readeepromFP, v1.4.0 ethercatmain.c). A wrong working
// counter is an answer, not a loss: it fails the read at once.
//
// 0x0502 bit 6 tells whether a read yields 4 bytes (2 words) or 8 (4 words). The reader takes
// the fixed header (words 0x00-0x3F), then walks the category list (type, length, data) up to
// the END category, bounded by the EEPROM size the header states (at most kMaxBytes).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "master/bus.hpp"
#include "master/datagram.hpp"
#include "master/transport.hpp"
#include "protocol/result.hpp"

namespace ecsim::master {

struct SiiReaderOptions {
  SimTime busyTimeout{20 * kNsPerMs};  // SOEM's EC_TIMEOUTEEP
  unsigned retries{3};                 // SOEM's EC_DEFAULTRETRIES
  // Wait between the command and the first status read and between status reads while busy
  // (SOEM's EC_LOCALDELAY, 200 us, in ecx_readeepromFP/ecx_eeprom_waitnotbusyFP); a real
  // EEPROM is busy 530-796 us per read (../shared/pcap/replay-dc.pcapng frames 104-110), so
  // polling at once would only send frames. The wait is on the bus's clock: virtual time
  // passes while it lasts. 0: read the status again at once.
  SimTime busyPollInterval{200 * kNsPerUs};
};

class SiiReader final : public Task {
 public:
  static constexpr std::size_t kMaxBytes = 32 * 1024;  // a 256 kbit EEPROM

  SiiReader(Transport& transport, std::uint16_t station, bool eightByteReads,
            SiiReaderOptions options = {});

  // Starts reading the whole image (header and categories).
  void start(SimTime now);
  bool step(SimTime now) override;
  std::optional<SimTime> wakeAt() const override { return wakeAt_; }
  // The datagram the reader waits for when wakeAt() is empty (a caller stepping many readers
  // steps only those whose datagram came back or whose time came).
  const Datagram& datagram() const { return datagram_; }

  bool done() const { return state_ == State::kDone || state_ == State::kFailed; }
  const Status& status() const { return status_; }
  // The bytes read so far (words never read are 0xFFFF, as an erased EEPROM reads).
  const std::vector<std::uint8_t>& image() const { return image_; }
  std::vector<std::uint8_t> takeImage() { return std::move(image_); }
  std::uint64_t reads() const { return reads_; }
  // Frames of the handshake sent again after the transport had given them up.
  std::uint64_t framesSentAgain() const { return framesSentAgain_; }

 private:
  enum class State { kIdle, kCommand, kStatus, kClearError, kDone, kFailed };

  std::optional<std::size_t> nextMissingWord() const;
  bool have(std::size_t word) const { return word < have_.size() && have_[word]; }
  std::uint16_t word(std::size_t w) const;
  void issueRead(SimTime now, std::size_t word);
  void fail(Status status);
  // Queues the datagram again when `status` says its frame was lost and the read is young
  // enough (see above); false: the caller fails the read.
  bool sendAgainIfLost(const Status& status, SimTime now);

  Transport& transport_;
  std::uint16_t station_;
  std::size_t wordsPerRead_;
  SiiReaderOptions options_;
  State state_{State::kIdle};
  Status status_;
  Datagram datagram_;
  std::vector<std::uint8_t> image_;
  std::vector<bool> have_;
  std::size_t current_{0};
  unsigned retriesLeft_{0};
  SimTime commandAt_{0};
  std::optional<SimTime> wakeAt_;
  std::uint64_t reads_{0};
  std::uint64_t framesSentAgain_{0};
};

}  // namespace ecsim::master
