// The output of an external master under test (docs/scenarios.md, "External masters"), read
// and judged in bounded memory whatever the program prints: its output file is read in chunks
// as it grows, a line longer than kMaxOutputLine bytes is cut into pieces of that size (each
// piece judged as a line of its own), each line is judged by every <Output> expectation as it
// comes, and only the last few lines are kept for the report. `matches=` patterns are RE2
// (linear in the line's length, bounded memory, no recursion per character or atom).
#pragma once

#include <climits>
#include <cstddef>
#include <deque>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "link/fd.hpp"
#include "protocol/result.hpp"
#include "scenario/scenario.hpp"

namespace re2 {
class RE2;
}

namespace ecsim::scenario {

inline constexpr std::size_t kMaxOutputLine = 64 * 1024;   // bytes; longer lines are cut
inline constexpr std::size_t kMaxPatternLength = 4096;     // characters of a matches= pattern
inline constexpr std::size_t kMaxOutputReadPerPoll = 1 << 20;  // bytes read by one poll()
inline constexpr SimTime kNoTimeZero = INT64_MIN;

// A matches= pattern compiled for matching anywhere in a line; an error (without file and
// line: the caller adds them) when it is longer than kMaxPatternLength, is not RE2 syntax or
// needs more than RE2's memory budget.
class OutputPattern {
 public:
  static Result<OutputPattern> compile(std::string_view pattern);
  OutputPattern(OutputPattern&&) noexcept;
  OutputPattern& operator=(OutputPattern&&) noexcept;
  ~OutputPattern();
  bool foundIn(std::string_view line) const;

 private:
  OutputPattern() = default;
  std::unique_ptr<re2::RE2> re_;
};

struct StampedLine {
  SimTime at{0};  // RealClock time the line was first seen complete
  std::string text;
};

// What one <Output> expectation found so far.
struct OutputTally {
  std::size_t found{0};
  std::optional<StampedLine> first;  // the first line found (its text at most 100 bytes + ...)
};

// Reads the command's output file while it grows, stamps each line with the time it was first
// seen and judges it at once. SOEM ends its cyclic lines with '\r', so '\r' ends a line too;
// empty lines are left out. A program that buffers its output shows its lines late (stdbuf
// -oL helps).
class CommandOutput {
 public:
  // `expectations` must outlive this object; those that are not kOutput are ignored.
  // Fails only when a matches= pattern does not compile (scenario files check at load).
  static Result<CommandOutput> open(std::filesystem::path path,
                                    const std::vector<Expectation>& expectations,
                                    std::size_t tailLines);
  // Reads at most kMaxOutputReadPerPoll bytes, so a program printing without end cannot keep
  // the caller from its other work. `zero` is time zero (kNoTimeZero when not yet reached):
  // lines before it never count for an afterMs window.
  void poll(SimTime now, SimTime zero);
  // Reads what is left; a last line without its end counts too.
  void finish(SimTime now, SimTime zero);

  std::size_t lineCount() const { return lines_; }
  std::size_t cutLines() const { return cut_; }  // lines longer than kMaxOutputLine
  const std::deque<std::string>& tail() const { return tail_; }
  // Index by expectation (the same order as `expectations`); empty tallies for the others.
  const std::vector<OutputTally>& tallies() const { return tallies_; }

 private:
  CommandOutput() = default;
  std::size_t read(SimTime now, SimTime zero, std::size_t limit);
  void endLine(SimTime now, SimTime zero);

  std::filesystem::path path_;
  const std::vector<Expectation>* expectations_{nullptr};
  std::vector<std::optional<OutputPattern>> patterns_;
  std::vector<OutputTally> tallies_;
  std::size_t tailLines_{0};
  UniqueFd fd_;
  std::string pending_;
  bool pendingIsPiece_{false};  // pending_ continues a line that was cut
  std::size_t lines_{0};
  std::size_t cut_{0};
  std::deque<std::string> tail_;
};

}  // namespace ecsim::scenario
