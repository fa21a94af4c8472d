// Ethernet over EtherCAT (ETG.1000.6 §5.7): Ethernet frames and IP settings carried in
// mailboxes of type 2.
//
//   EoE header, 4 bytes after the mailbox header, two little-endian words:
//     word 1  bits 0-3 frame type, bits 4-7 port, bit 8 last fragment, bit 9 time appended,
//             bit 10 time requested
//     word 2  fragment data (type 0): bits 0-5 fragment number, bits 6-11 on fragment 0 the
//             complete frame size in 32-byte units (rounded up), on later fragments this
//             fragment's offset in the frame in 32-byte units, bits 12-15 frame number;
//             responses of types 3, 5 (and in SOEM/TwinCAT 7 and 9): the result code
//   Frame types: 0 fragment data, 1 init response with timestamp, 2 init request (Set IP
//   Parameter), 3 init response, 4 Set Address Filter request, 5 its response, 6 Get IP
//   Parameter request, 7 its response, 8 Get Address Filter request, 9 its response
//   (values as SOEM ethercateoe.h v1.4/ec_eoe.h v2, IgH fsm_eoe and Wireshark packet-ecatmb).
//   A fragment other than the last carries a multiple of 32 bytes; with "time appended" the
//   last fragment ends with a 4-byte timestamp that is not part of the frame.
//
//   IP parameter block (Set IP request, Get IP response), after the EoE header:
//     u32 flags (bit 0 MAC, 1 IP address, 2 subnet mask, 3 default gateway, 4 DNS server,
//     5 DNS name included), 6 bytes MAC, then IP, subnet, gateway, DNS server as UINT32
//     (little-endian: the last dotted octet first, as SOEM EOE_ip_uint32_to_byte and
//     Wireshark's ENC_LITTLE_ENDIAN IPv4 fields), 32 bytes DNS name. Every master seen sends
//     all fields (zero where not included); a block cut short after its last included field
//     is accepted.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/bytes.hpp"
#include "protocol/ethernet.hpp"
#include "protocol/ipv4.hpp"
#include "protocol/mailbox.hpp"
#include "protocol/result.hpp"

namespace ecsim {

enum class EoeFrameType : std::uint8_t {
  kFragment = 0,
  kInitResponseTimestamp = 1,
  kSetIpRequest = 2,
  kSetIpResponse = 3,
  kSetAddressFilterRequest = 4,
  kSetAddressFilterResponse = 5,
  kGetIpRequest = 6,
  kGetIpResponse = 7,
  kGetAddressFilterRequest = 8,
  kGetAddressFilterResponse = 9,
};

// "fragment", "set IP request", ...; "reserved" for 10..15.
std::string_view toString(EoeFrameType type);

// EoE result codes (ETG.1000.6 Table "EoE result", SOEM EOE_RESULT_*).
enum class EoeResult : std::uint16_t {
  kSuccess = 0x0000,
  kUnspecifiedError = 0x0001,
  kUnsupportedFrameType = 0x0002,
  kNoIpSupport = 0x0201,
  kNoDhcpSupport = 0x0202,
  kNoFilterSupport = 0x0401,
};
std::string_view eoeResultText(std::uint16_t result);

constexpr std::size_t kEoeHeaderSize = 4;
constexpr std::size_t kEoeFragmentUnit = 32;  // size and offset granularity
constexpr std::size_t kEoeTimestampSize = 4;
constexpr std::uint8_t kEoePortMax = 0x0F;
constexpr std::uint8_t kEoeFragmentNumberMax = 0x3F;
constexpr std::uint8_t kEoeOffsetUnitsMax = 0x3F;
constexpr std::uint8_t kEoeFrameNumberMax = 0x0F;
// The largest frame the 6-bit size field can describe.
constexpr std::size_t kEoeMaxFrameSize = kEoeOffsetUnitsMax * kEoeFragmentUnit;

struct EoeHeader {
  std::uint8_t type{0};  // an EoeFrameType value, kept raw (a reserved one is answered)
  std::uint8_t port{0};
  bool lastFragment{true};
  bool timeAppended{false};
  bool timeRequested{false};
  // Word 2 for fragment data.
  std::uint8_t fragmentNumber{0};
  std::uint8_t offsetUnits{0};  // fragment 0: complete size; later: offset (32-byte units)
  std::uint8_t frameNumber{0};
  // Word 2 as a whole: the result of a response.
  std::uint16_t result{0};

  EoeFrameType frameType() const { return static_cast<EoeFrameType>(type); }

  // Reads 4 bytes; both views of word 2 are filled.
  static Result<EoeHeader> decode(ConstBytes bytes);
  // Writes 4 bytes: word 2 from the fragment fields for type 0, from `result` otherwise.
  // Fails when a field does not fit its bits.
  Result<std::size_t> encode(Bytes out) const;

  bool operator==(const EoeHeader&) const = default;
};

constexpr std::size_t kEoeDnsNameSize = 32;
// Flags word + MAC + 4 addresses + DNS name.
constexpr std::size_t kEoeIpParameterSize = 4 + 6 + 4 * 4 + kEoeDnsNameSize;

struct EoeIpParameters {
  std::optional<MacAddress> mac;
  std::optional<Ipv4Address> ip;
  std::optional<Ipv4Address> subnetMask;
  std::optional<Ipv4Address> gateway;
  std::optional<Ipv4Address> dnsServer;
  std::optional<std::string> dnsName;  // up to 32 characters, NUL padding removed

  // The block after the EoE header. Errors name the byte offset within `body`.
  static Result<EoeIpParameters> decode(ConstBytes body);
  // The full kEoeIpParameterSize block (fields not included are zero).
  Result<std::vector<std::uint8_t>> encode() const;
  // Takes every field `update` includes.
  void merge(const EoeIpParameters& update);

  bool operator==(const EoeIpParameters&) const = default;
};

// A complete EoE mailbox message (mailbox header + EoE header + body); header.type and
// header.length are set here.
Result<std::vector<std::uint8_t>> encodeEoeMessage(const EoeHeader& eoe, ConstBytes body,
                                                   MailboxHeader header = {});

// Splits an Ethernet frame into the fragment messages (complete mailboxes) that fit a mailbox
// of `mailboxSize` bytes: every fragment but the last carries a multiple of 32 bytes.
// Fails when the frame is empty, larger than kEoeMaxFrameSize or needs more than 64 fragments,
// or when the mailbox cannot carry 32 bytes of data.
Result<std::vector<std::vector<std::uint8_t>>> fragmentEoeFrame(ConstBytes frame,
                                                                std::size_t mailboxSize,
                                                                std::uint8_t port,
                                                                std::uint8_t frameNumber);

// Puts fragments back together (SOEM ecx_EOEreadfragment's checks): fragment numbers count
// up from 0, each offset continues the previous one, the frame number stays, the data stays
// within the announced size. A fragment 0 always starts a new frame (the partial one is
// dropped); any other mismatch drops the partial frame and is reported.
class EoeReassembler {
 public:
  // A complete frame when `header` was the last fragment, nothing while one is in progress.
  Result<std::optional<std::vector<std::uint8_t>>> add(const EoeHeader& header, ConstBytes data);
  bool inProgress() const { return inProgress_; }
  void reset();

 private:
  std::vector<std::uint8_t> frame_;
  std::size_t announced_{0};
  std::uint8_t nextFragment_{0};
  std::uint8_t frameNumber_{0};
  bool inProgress_{false};
};

}  // namespace ecsim
