// `ecsim serve --status` / `--status-json FILE`: what the server and every slave are doing,
// taken as a snapshot (takeStatusSnapshot) and formatted as a terminal table or as JSON by
// pure functions, so the formatting is testable without a network. StatusReporter redraws /
// rewrites periodically from the server loop; the JSON file is replaced atomically (written
// to FILE.tmp, then renamed), so a script never reads half a file.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "protocol/al_status.hpp"
#include "protocol/result.hpp"
#include "protocol/time.hpp"
#include "topology/network_server.hpp"
#include "topology/segment.hpp"

namespace ecsim::tools {

struct ProcessValue {
  std::string name;  // "DO1.Output 8" (slave_variables.hpp)
  std::uint16_t index{0};
  std::uint8_t subindex{0};
  bool output{false};  // RxPDO (from the master) or TxPDO (to the master)
  std::int64_t value{0};
};

struct SlaveStatus {
  std::string name;
  AlState state{AlState::kInit};
  bool alError{false};  // AL status error flag (0x0130 bit 4)
  std::uint16_t alStatusCode{0};
  std::uint64_t frames{0};     // frames that passed this slave's ESC
  std::uint64_t datagrams{0};  // datagrams addressed to it (each one counts in a WKC)
  std::uint32_t rxErrors{0};   // invalid frame + RX error + forwarded RX error counters
  std::uint32_t lostLinks{0};  // lost link counters, all ports
  // System time difference (0x092C), sign-magnitude decoded: local copy minus received.
  std::int64_t dcDifferenceNs{0};
  std::vector<ProcessValue> values;  // the mapped process-data entries (up to maxValues)
};

struct StatusSnapshot {
  SimTime uptime{0};
  std::uint64_t framesReceived{0};
  std::uint64_t framesAnswered{0};
  std::uint64_t framesDropped{0};
  std::uint64_t framesLost{0};
  std::uint64_t receiveErrors{0};
  std::uint64_t sendErrors{0};
  double framesPerSecond{0.0};
  SimTime lastRoundTrip{0};
  std::vector<SlaveStatus> slaves;
};

// Decodes 0x092C: bit 31 set means the local copy is smaller than the received time.
std::int64_t decodeSystemTimeDifference(std::uint32_t raw);

// How many process-data entries per slave the terminal table shows.
inline constexpr std::size_t kTableValues = 4;

// Reads the server counters and every slave's registers and process data. maxValues limits
// the process-data entries listed per slave (the JSON status lists them all).
StatusSnapshot takeStatusSnapshot(topology::Segment& segment,
                                  const topology::ServerCounters& counters, SimTime uptime,
                                  double framesPerSecond,
                                  std::size_t maxValues = static_cast<std::size_t>(-1));

// A plain table (no terminal control codes), one line per slave with its first kTableValues
// process-data entries, ending in a newline.
std::string formatStatusTable(const StatusSnapshot& snapshot);
// The same content as one JSON object.
std::string formatStatusJson(const StatusSnapshot& snapshot);
// Writes `text` to path.tmp and renames it over path.
Status writeFileAtomically(const std::filesystem::path& path, const std::string& text);

// Called from the server loop; every `period` it takes a snapshot, redraws the terminal
// table (when `terminal`) and rewrites the JSON file (when a path is set).
class StatusReporter {
 public:
  StatusReporter(bool terminal, std::filesystem::path jsonPath, SimTime period = 500 * kNsPerMs)
      : terminal_(terminal), jsonPath_(std::move(jsonPath)), period_(period) {}

  bool enabled() const { return terminal_ || !jsonPath_.empty(); }
  // Reports when a period has passed since the last report (the first call only starts).
  void tick(SimTime now, topology::Segment& segment, const topology::ServerCounters& counters);
  // The last report's error writing the JSON file, if any.
  const Status& lastWrite() const { return lastWrite_; }

 private:
  bool terminal_;
  std::filesystem::path jsonPath_;
  SimTime period_;
  bool started_{false};
  SimTime start_{0};
  SimTime last_{0};
  std::uint64_t lastFrames_{0};
  Status lastWrite_;
};

}  // namespace ecsim::tools
