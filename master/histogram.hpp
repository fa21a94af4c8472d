// A fixed-bucket latency histogram for the cyclic path: record() is a few integer operations
// on a std::array, never allocates, and keeps min, max, sum and count exactly. Buckets are
// log-linear (the HdrHistogram idea): values below 2 * kSubBuckets nanoseconds have a bucket
// each; above, every power of two is split into kSubBuckets equal buckets, so a bucket is at
// most 1/32 (3 %) of its values wide. Values up to 2^40 ns (18 minutes) are kept; larger ones
// land in the last bucket.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "protocol/time.hpp"

namespace ecsim::master {

class LatencyHistogram {
 public:
  static constexpr unsigned kSubBucketBits = 5;
  static constexpr std::uint64_t kSubBuckets = 1u << kSubBucketBits;  // 32
  static constexpr unsigned kMaxBits = 40;
  static constexpr std::size_t kBucketCount = (kMaxBits - kSubBucketBits + 1) * kSubBuckets;

  // Negative values count as 0.
  void record(SimTime value);
  void clear() { *this = LatencyHistogram{}; }
  // Adds another histogram's samples.
  void merge(const LatencyHistogram& other);

  std::uint64_t count() const { return count_; }
  SimTime min() const { return count_ == 0 ? 0 : min_; }
  SimTime max() const { return max_; }
  SimTime mean() const { return count_ == 0 ? 0 : sum_ / static_cast<SimTime>(count_); }
  // The smallest value v such that at least `fraction` of the samples are <= v, to the
  // bucket's resolution (the bucket's upper bound, clamped to the exact max). 0 when empty.
  SimTime percentile(double fraction) const;
  SimTime p99() const { return percentile(0.99); }
  SimTime p999() const { return percentile(0.999); }

  static std::size_t bucketOf(std::uint64_t value);
  // The values bucket b holds: [lowest, highest].
  static std::uint64_t bucketLowest(std::size_t bucket);
  static std::uint64_t bucketHighest(std::size_t bucket);
  std::uint64_t bucketCount(std::size_t bucket) const { return buckets_[bucket]; }

 private:
  std::array<std::uint64_t, kBucketCount> buckets_{};
  std::uint64_t count_{0};
  SimTime min_{0};
  SimTime max_{0};
  SimTime sum_{0};
};

}  // namespace ecsim::master
