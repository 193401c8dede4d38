#include "runtime/latency_histogram.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace plumb::runtime {

namespace {

// edges[k] = kMinNs * 10^(k / kBinsPerDecade), k = 0..kLogBins, rounded to whole nanoseconds.
// Computed once; a table (instead of log10 per sample) keeps binOf and the edges consistent.
struct BinEdges {
  std::array<int64_t, LatencyHistogram::kLogBins + 1> ns{};
  BinEdges() {
    for (int k = 0; k <= LatencyHistogram::kLogBins; ++k) {
      ns[k] = std::llround(static_cast<double>(LatencyHistogram::kMinNs) *
                           std::pow(10.0, static_cast<double>(k) / LatencyHistogram::kBinsPerDecade));
    }
  }
};

const BinEdges& edges() {
  static const BinEdges table;
  return table;
}

}  // namespace

int LatencyHistogram::binOf(int64_t latency_ns) {
  const auto& e = edges().ns;
  // Number of edges <= latency: 0 -> underflow, kLogBins + 1 -> overflow.
  return static_cast<int>(std::upper_bound(e.begin(), e.end(), latency_ns) - e.begin());
}

int64_t LatencyHistogram::binLowerNs(int bin) {
  if (bin <= 0) return 0;
  return edges().ns[bin - 1];
}

int64_t LatencyHistogram::binUpperNs(int bin) {
  if (bin >= kBinCount - 1) return std::numeric_limits<int64_t>::max();
  return edges().ns[bin];
}

void LatencyHistogram::add(int64_t latency_ns) {
  if (latency_ns < 0) latency_ns = 0;  // clock quirks must not index outside the table
  ++bins_[binOf(latency_ns)];
  if (count_ == 0 || latency_ns < min_ns_) min_ns_ = latency_ns;
  if (count_ == 0 || latency_ns > max_ns_) max_ns_ = latency_ns;
  ++count_;
  sum_ns_ += latency_ns;
}

void LatencyHistogram::merge(const LatencyHistogram& other) {
  if (other.count_ == 0) return;
  for (int b = 0; b < kBinCount; ++b) bins_[b] += other.bins_[b];
  min_ns_ = count_ ? std::min(min_ns_, other.min_ns_) : other.min_ns_;
  max_ns_ = count_ ? std::max(max_ns_, other.max_ns_) : other.max_ns_;
  count_ += other.count_;
  sum_ns_ += other.sum_ns_;
}

int64_t LatencyHistogram::percentileNs(double p) const {
  if (count_ == 0) return 0;
  const double clamped = std::min(1.0, std::max(0.0, p));
  uint64_t rank = static_cast<uint64_t>(std::ceil(clamped * static_cast<double>(count_)));
  rank = std::max<uint64_t>(rank, 1);
  uint64_t seen = 0;
  for (int b = 0; b < kBinCount; ++b) {
    seen += bins_[b];
    if (seen >= rank) return std::min(binUpperNs(b), max_ns_);
  }
  return max_ns_;
}

}  // namespace plumb::runtime
