#include "runtime/latency_histogram.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "platform/allocation_counter.h"

namespace plumb::runtime {
namespace {

// Nearest-rank percentile of the raw samples: the oracle.
int64_t oraclePercentile(std::vector<int64_t> samples, double p) {
  std::sort(samples.begin(), samples.end());
  const auto rank = static_cast<std::size_t>(std::ceil(p * static_cast<double>(samples.size())));
  return samples[std::max<std::size_t>(rank, 1) - 1];
}

TEST(LatencyHistogram, BinsAreLogSpacedFrom10usTo10s) {
  EXPECT_EQ(LatencyHistogram::binOf(0), 0);
  EXPECT_EQ(LatencyHistogram::binOf(9'999), 0);
  EXPECT_EQ(LatencyHistogram::binOf(10'000), 1);
  EXPECT_EQ(LatencyHistogram::binLowerNs(1), 10'000);
  EXPECT_EQ(LatencyHistogram::binUpperNs(LatencyHistogram::kLogBins), 10'000'000'000);
  EXPECT_EQ(LatencyHistogram::binOf(10'000'000'000), LatencyHistogram::kBinCount - 1);
  for (int b = 1; b <= LatencyHistogram::kLogBins; ++b) {
    const double ratio = static_cast<double>(LatencyHistogram::binUpperNs(b)) /
                         static_cast<double>(LatencyHistogram::binLowerNs(b));
    EXPECT_NEAR(ratio, std::pow(10.0, 1.0 / LatencyHistogram::kBinsPerDecade), 1e-3) << b;
    // Every value falls in the bin whose edges contain it.
    const int64_t mid = (LatencyHistogram::binLowerNs(b) + LatencyHistogram::binUpperNs(b)) / 2;
    EXPECT_EQ(LatencyHistogram::binOf(mid), b);
    EXPECT_EQ(LatencyHistogram::binOf(LatencyHistogram::binUpperNs(b) - 1), b);
  }
}

TEST(LatencyHistogram, PercentilesMatchASortedArrayOracleToTheBin) {
  std::mt19937_64 rng(42);
  // Log-normal around 5 ms with a heavy tail, plus a few out-of-range values.
  std::lognormal_distribution<double> latency(std::log(5e6), 0.8);
  std::vector<int64_t> samples;
  LatencyHistogram histogram;
  for (int i = 0; i < 20'000; ++i) {
    const auto ns = static_cast<int64_t>(latency(rng));
    samples.push_back(ns);
    histogram.add(ns);
  }
  for (int64_t extreme : {int64_t{500}, int64_t{20'000'000'000}}) {
    samples.push_back(extreme);
    histogram.add(extreme);
  }
  EXPECT_EQ(histogram.count(), samples.size());
  EXPECT_EQ(histogram.maxNs(), *std::max_element(samples.begin(), samples.end()));
  EXPECT_EQ(histogram.minNs(), *std::min_element(samples.begin(), samples.end()));
  for (double p : {0.01, 0.5, 0.9, 0.99, 0.999, 1.0}) {
    const int64_t exact = oraclePercentile(samples, p);
    // The reported value is the upper edge of the oracle's bin (capped at the max): exact.
    const int64_t expected =
        std::min(LatencyHistogram::binUpperNs(LatencyHistogram::binOf(exact)), histogram.maxNs());
    EXPECT_EQ(histogram.percentileNs(p), expected) << "p=" << p;
    EXPECT_GE(histogram.percentileNs(p), exact);
  }
}

TEST(LatencyHistogram, SmallSampleEdgeCases) {
  LatencyHistogram histogram;
  EXPECT_EQ(histogram.percentileNs(0.5), 0);
  histogram.add(3'000'000);
  EXPECT_EQ(histogram.percentileNs(0.5), 3'000'000);  // capped at the only sample
  EXPECT_EQ(histogram.percentileNs(0.99), 3'000'000);
  histogram.add(-5);  // clamped, never indexes out of the table
  EXPECT_EQ(histogram.minNs(), 0);
}

TEST(LatencyHistogram, MergeEqualsAddingEverythingToOne) {
  LatencyHistogram a, b, all;
  for (int i = 1; i <= 1000; ++i) {
    const int64_t ns = static_cast<int64_t>(i) * 37'000;
    (i % 3 ? a : b).add(ns);
    all.add(ns);
  }
  a.merge(b);
  EXPECT_EQ(a.count(), all.count());
  EXPECT_EQ(a.maxNs(), all.maxNs());
  EXPECT_EQ(a.minNs(), all.minNs());
  EXPECT_DOUBLE_EQ(a.meanNs(), all.meanNs());
  for (double p : {0.5, 0.9, 0.99}) EXPECT_EQ(a.percentileNs(p), all.percentileNs(p));
}

TEST(LatencyHistogram, AddingNeverAllocates) {
  LatencyHistogram histogram;
  histogram.add(1);  // first use builds the static edge table
  AllocationScope scope;
  for (int i = 0; i < 10'000; ++i) histogram.add(i * 1'000);
  EXPECT_EQ(scope.count(), 0u);
}

}  // namespace
}  // namespace plumb::runtime
