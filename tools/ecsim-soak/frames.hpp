// The frames of the soak: valid frames whose answers are known in advance from the ESC
// datasheet (not from running the simulator), and malformed frames that no ESC may execute.
//
// Every frame carries its identity in the source MAC address: byte 0 0x02 (locally
// administered, which an ESC sets anyway), byte 1 a marker (valid or malformed), bytes 2-5 a
// sequence number of that kind. An answer is matched by these bytes, never by the one-byte
// datagram index.
//
// What the soak relies on (ESC datasheet section I, ET1100/ET1200/LAN9252 alike):
//   - BRD: every slave ORs its memory into the data and increments the WKC and the ADP;
//     BWR: every slave writes and increments the WKC.
//   - APxx: addressed where ADP is 0, every slave increments the ADP.
//   - FPxx: addressed by the configured station address (0x0010), which the soak sets
//     to kStationBase + position before it starts.
//   - A read datagram nobody addresses comes back with its data and WKC unchanged; so does NOP.
//   - Process RAM starts at 0x1000; without SyncManagers it is plain memory.
//   - Logical: an FMMU with write access adds 2 to an LRW's WKC, one with read access 1.
//   - A frame whose datagram chain runs past the frame end, or whose EtherCAT type is not 1,
//     is not executed.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <random>
#include <string>

#include "protocol/ethernet.hpp"
#include "protocol/frame.hpp"

namespace ecsim::soak {

// The soak's layout of each slave (set up before the run, see setupFrames()).
inline constexpr std::uint16_t kStationBase = 0x1000;    // station address of position p
inline constexpr std::uint16_t kAbsentStation = 0xBEEF;  // never given to a slave
inline constexpr std::uint32_t kLogicalBase = 0x00010000;
inline constexpr std::uint16_t kBytesPerSlave = 8;       // logical image per slave
inline constexpr std::uint16_t kRamWindow = 0x400;       // size of each RAM area below
// Process RAM areas (offsets from the start of process RAM at 0x1000).
inline constexpr std::uint16_t kWriteReadArea = 0x000;   // FPWR then FPRD
inline constexpr std::uint16_t kBroadcastArea = 0x400;   // BWR then BRD
inline constexpr std::uint16_t kOutputArea = 0x800;      // FMMU0: LRW writes here
inline constexpr std::uint16_t kInputArea = 0x900;       // FMMU1: LRW reads here
inline constexpr std::uint8_t kValidMarker = 0x51;
inline constexpr std::uint8_t kMalformedMarker = 0x4D;
// Largest frame the soak builds (oversized frames go past kMaxFrameSize).
inline constexpr std::size_t kMaxSoakFrame = 2048;
inline constexpr std::size_t kMaxOps = 64;

enum class OpKind : std::uint8_t {
  kTypeRead,        // BRD 0x0000
  kAprdStation,     // APRD of position p's station address
  kFprdStation,     // FPRD of position p's station address
  kNobody,          // FPRD of an absent station or APRD past the last slave
  kNop,             // NOP
  kWriteRead,       // FPWR then FPRD of position p's RAM
  kBroadcastWrite,  // BWR then BRD of RAM
  kLogical,         // BWR of the input area, LRW of the whole image, BRD of the output area
  kSetup,           // a set-up write: WKC 1 (never chosen at random)
};
inline constexpr std::size_t kOpKinds = 8;  // the kinds chosen at random

struct Op {
  OpKind kind{OpKind::kNop};
  std::uint8_t first{0};  // index of its first datagram in the frame
  std::uint16_t slave{0};
};

enum class Malformation : std::uint8_t {
  kNone,
  kTruncated,       // cut inside the datagram chain
  kLengthPastEnd,   // the last datagram's length runs past the frame end
  kBrokenChain,     // the last datagram says another follows, and none fits
  kWrongType,       // EtherCAT header type other than 1
  kRandom,          // random bytes, first datagram length past the end
  kWrongEtherType,  // a valid frame with another EtherType
  kOversized,       // a valid chain padded past 1514 bytes
};
inline constexpr std::size_t kMalformations = 8;
std::string_view toString(Malformation m);

struct SoakFrame {
  std::array<std::uint8_t, kMaxSoakFrame> bytes{};
  std::size_t length{0};
  Malformation malformation{Malformation::kNone};
  std::uint32_t sequence{0};
  std::array<Op, kMaxOps> ops{};
  std::size_t opCount{0};
};

struct Network {
  std::uint16_t slaves{0};
  std::uint8_t escType{0x11};
};

// Builds the frames of one run from one seed: the same seed gives the same frames.
class FrameSource {
 public:
  FrameSource(std::uint64_t seed, const Network& network, unsigned malformedPercent);

  // The next frame of the run into `out` (valid or malformed, as the mix decides).
  void next(SoakFrame& out);
  // A valid frame of the given single op (set-up checks and readiness probes).
  void single(SoakFrame& out, OpKind kind, std::uint16_t slave);

 private:
  void buildValid(SoakFrame& out, std::size_t maxOps);
  bool addOp(FrameBuilder& b, SoakFrame& out, OpKind kind, std::uint16_t slave);
  void malform(SoakFrame& out, Malformation m);
  std::uint32_t below(std::uint32_t n) { return static_cast<std::uint32_t>(rng_() % n); }

  std::mt19937_64 rng_;
  Network network_;
  unsigned malformedPercent_;
  std::uint32_t validCount_{0};
  std::uint32_t malformedCount_{0};
};

// Checks an answer to a valid frame against the datasheet expectations: no error flag and an
// empty `what` when everything holds, else the first difference.
struct CheckResult {
  bool wkcError{false};
  bool dataError{false};
  std::string what;
};
CheckResult checkAnswer(const SoakFrame& request, ConstBytes answer, const Network& network);

// The identity an answer carries: marker and sequence from the source MAC. False when the
// frame is too short or not one of ours.
bool answerIdentity(ConstBytes answer, std::uint8_t& marker, std::uint32_t& sequence);

// Set-up frames, sent and checked one by one before the run: the station address of each
// position (APWR), then FMMU0 (write, output area) and FMMU1 (read, input area) of each
// station mapping kLogicalBase + kBytesPerSlave * p. Each expects WKC 1.
void stationAddressFrame(SoakFrame& out, std::uint16_t position);
void fmmuFrame(SoakFrame& out, std::uint16_t position);

}  // namespace ecsim::soak
