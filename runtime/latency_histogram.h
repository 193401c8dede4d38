#pragma once
// LatencyHistogram: fixed log-spaced bins from 10 us to 10 s (50 bins per decade, each bin ~4.7%
// wide), plus an underflow and an overflow bin. add() is O(log bins) and never allocates, so
// every stage thread can keep its own histogram on the hot path; merge them after the run.
//
// Percentiles use the nearest-rank definition (the smallest sample with at least p*n samples <= it)
// and are reported as the upper edge of the bin holding that sample, capped at the exact maximum:
// never below the true percentile, at most one bin width (~4.7%) above it.
#include <array>
#include <cstdint>

namespace plumb::runtime {

class LatencyHistogram {
 public:
  static constexpr int64_t kMinNs = 10'000;  // 10 us: lower edge of the first real bin
  static constexpr int kDecades = 6;         // up to 10 s
  static constexpr int kBinsPerDecade = 50;  // ~4.7 % per bin: a p99 against a 33 ms budget reads to ~1.5 ms
  static constexpr int kLogBins = kDecades * kBinsPerDecade;
  static constexpr int kBinCount = kLogBins + 2;  // [0] underflow, [kBinCount-1] overflow

  void add(int64_t latency_ns);
  void merge(const LatencyHistogram& other);
  void clear() { *this = LatencyHistogram(); }

  uint64_t count() const { return count_; }
  int64_t minNs() const { return count_ ? min_ns_ : 0; }
  int64_t maxNs() const { return count_ ? max_ns_ : 0; }
  double meanNs() const { return count_ ? static_cast<double>(sum_ns_) / count_ : 0.0; }
  // p in (0, 1]; 0 when empty.
  int64_t percentileNs(double p) const;

  uint64_t binCount(int bin) const { return bins_[bin]; }
  // Bin of a latency and the bin's edges: bin b holds [binLowerNs(b), binUpperNs(b)).
  static int binOf(int64_t latency_ns);
  static int64_t binLowerNs(int bin);
  static int64_t binUpperNs(int bin);  // overflow bin: INT64_MAX

 private:
  std::array<uint64_t, kBinCount> bins_{};
  uint64_t count_ = 0;
  int64_t sum_ns_ = 0;
  int64_t min_ns_ = 0;
  int64_t max_ns_ = 0;
};

}  // namespace plumb::runtime
