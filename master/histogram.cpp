#include "master/histogram.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

namespace ecsim::master {

std::size_t LatencyHistogram::bucketOf(std::uint64_t value) {
  if (value < 2 * kSubBuckets) return static_cast<std::size_t>(value);
  const unsigned top = static_cast<unsigned>(std::bit_width(value)) - 1;  // >= kSubBucketBits+1
  if (top >= kMaxBits) return kBucketCount - 1;
  const unsigned shift = top - kSubBucketBits;
  return static_cast<std::size_t>((shift + 1) * kSubBuckets + ((value >> shift) - kSubBuckets));
}

std::uint64_t LatencyHistogram::bucketLowest(std::size_t bucket) {
  if (bucket < 2 * kSubBuckets) return bucket;
  const std::uint64_t shift = bucket / kSubBuckets - 1;
  return (kSubBuckets + bucket % kSubBuckets) << shift;
}

std::uint64_t LatencyHistogram::bucketHighest(std::size_t bucket) {
  if (bucket + 1 >= kBucketCount) return UINT64_MAX;
  return bucketLowest(bucket + 1) - 1;
}

void LatencyHistogram::record(SimTime value) {
  if (value < 0) value = 0;
  ++buckets_[bucketOf(static_cast<std::uint64_t>(value))];
  if (count_ == 0 || value < min_) min_ = value;
  max_ = std::max(max_, value);
  sum_ += value;
  ++count_;
}

void LatencyHistogram::merge(const LatencyHistogram& other) {
  if (other.count_ == 0) return;
  for (std::size_t b = 0; b < kBucketCount; ++b) buckets_[b] += other.buckets_[b];
  min_ = count_ == 0 ? other.min_ : std::min(min_, other.min_);
  max_ = std::max(max_, other.max_);
  sum_ += other.sum_;
  count_ += other.count_;
}

SimTime LatencyHistogram::percentile(double fraction) const {
  if (count_ == 0) return 0;
  fraction = std::clamp(fraction, 0.0, 1.0);
  auto rank = static_cast<std::uint64_t>(std::ceil(fraction * static_cast<double>(count_)));
  rank = std::clamp<std::uint64_t>(rank, 1, count_);
  std::uint64_t seen = 0;
  for (std::size_t b = 0; b < kBucketCount; ++b) {
    seen += buckets_[b];
    if (seen >= rank) {
      const std::uint64_t high = bucketHighest(b);
      const auto clamped = std::min<std::uint64_t>(high, static_cast<std::uint64_t>(max_));
      return std::max(static_cast<SimTime>(clamped), min_);
    }
  }
  return max_;
}

}  // namespace ecsim::master
