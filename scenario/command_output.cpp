#include "scenario/command_output.hpp"

#include <fcntl.h>
#include <fmt/core.h>
#include <re2/re2.h>
#include <unistd.h>

#include <algorithm>
#include <array>

namespace ecsim::scenario {
namespace {

constexpr std::size_t kFirstExcerpt = 100;  // bytes of the first line found kept for the report

}  // namespace

Result<OutputPattern> OutputPattern::compile(std::string_view pattern) {
  if (pattern.size() > kMaxPatternLength) {
    return makeError(ErrorCode::kInvalidArgument,
                     fmt::format("the pattern is {} characters long, at most {} are allowed",
                                 pattern.size(), kMaxPatternLength));
  }
  RE2::Options options;
  options.set_log_errors(false);  // the error goes into our message, not to stderr
  OutputPattern p;
  p.re_ = std::make_unique<RE2>(re2::StringPiece(pattern.data(), pattern.size()), options);
  if (!p.re_->ok()) {
    return makeError(ErrorCode::kInvalidArgument,
                     "it is not a regular expression (RE2 syntax): " + p.re_->error());
  }
  return p;
}

OutputPattern::OutputPattern(OutputPattern&&) noexcept = default;
OutputPattern& OutputPattern::operator=(OutputPattern&&) noexcept = default;
OutputPattern::~OutputPattern() = default;

bool OutputPattern::foundIn(std::string_view line) const {
  return RE2::PartialMatch(re2::StringPiece(line.data(), line.size()), *re_);
}

Result<CommandOutput> CommandOutput::open(std::filesystem::path path,
                                          const std::vector<Expectation>& expectations,
                                          std::size_t tailLines) {
  CommandOutput out;
  out.path_ = std::move(path);
  out.expectations_ = &expectations;
  out.tailLines_ = tailLines;
  out.tallies_.resize(expectations.size());
  out.patterns_.resize(expectations.size());
  for (std::size_t i = 0; i < expectations.size(); ++i) {
    const auto& x = expectations[i];
    if (x.kind != ExpectKind::kOutput || !x.isRegex) continue;
    auto p = OutputPattern::compile(x.text);
    if (!p.ok()) return p.error();
    out.patterns_[i].emplace(std::move(*p));
  }
  out.pending_.reserve(kMaxOutputLine);
  return out;
}

void CommandOutput::poll(SimTime now, SimTime zero) { read(now, zero, kMaxOutputReadPerPoll); }

void CommandOutput::finish(SimTime now, SimTime zero) {
  while (read(now, zero, kMaxOutputReadPerPoll) > 0) {
  }
  endLine(now, zero);
}

std::size_t CommandOutput::read(SimTime now, SimTime zero, std::size_t limit) {
  if (!fd_.valid()) {
    fd_ = UniqueFd(::open(path_.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK));
    if (!fd_.valid()) return 0;
  }
  std::array<char, 4096> chunk{};
  std::size_t total = 0;
  while (total < limit) {
    const ssize_t n = ::read(fd_.get(), chunk.data(), std::min(chunk.size(), limit - total));
    if (n <= 0) break;
    total += static_cast<std::size_t>(n);
    for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) {
      const char c = chunk[i];
      if (c == '\n' || c == '\r') {
        endLine(now, zero);
        pendingIsPiece_ = false;
        continue;
      }
      if (pending_.size() == kMaxOutputLine) {  // cut: this piece is judged as a line
        if (!pendingIsPiece_) ++cut_;
        endLine(now, zero);
        pendingIsPiece_ = true;
      }
      pending_ += c;
    }
  }
  return total;
}

void CommandOutput::endLine(SimTime now, SimTime zero) {
  if (pending_.empty()) return;
  ++lines_;
  const auto& xs = *expectations_;
  for (std::size_t i = 0; i < xs.size(); ++i) {
    const auto& x = xs[i];
    if (x.kind != ExpectKind::kOutput) continue;
    if (x.afterTime && (zero == kNoTimeZero || now - zero < *x.afterTime ||
                        now - zero > *x.afterTime + x.within)) {
      continue;
    }
    const bool found = patterns_[i] ? patterns_[i]->foundIn(pending_)
                                    : pending_.find(x.text) != std::string::npos;
    if (!found) continue;
    auto& tally = tallies_[i];
    if (tally.found++ == 0) {
      std::string text = pending_.substr(0, kFirstExcerpt);
      if (pending_.size() > kFirstExcerpt) text += "...";
      tally.first = StampedLine{now, std::move(text)};
    }
  }
  if (tailLines_ > 0) {
    if (tail_.size() == tailLines_) tail_.pop_front();
    tail_.push_back(pending_);
  }
  pending_.clear();
}

}  // namespace ecsim::scenario
