// The descriptor scans of pipeline/frontend/descriptor_match.h (their bounds, the skip on a partial
// distance, the POPCNT copy picked at run time) against oracles written from the definitions: every
// distance computed bit by bit, the nearest found by sorting (distance, index), and the matching
// decisions of the loop verifier and the loop's context check as they were before the scans were
// bounded (full nearest-two loops, initial distances 256 and 257). The fast scans claim the same
// integers and the same decisions, so every comparison is for equality.
#include "pipeline/frontend/descriptor_match.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

namespace plumb {
namespace {

int bitDistance(const Descriptor256& a, const Descriptor256& b) {
  int n = 0;
  for (int w = 0; w < 4; ++w)
    for (int bit = 0; bit < 64; ++bit) n += int(((a.words[std::size_t(w)] ^ b.words[std::size_t(w)]) >> bit) & 1);
  return n;
}

// The distances of d to every one of others, bit by bit.
std::vector<int> bitDistances(const Descriptor256& d, const std::vector<Descriptor256>& others) {
  std::vector<int> out;
  for (const Descriptor256& o : others) out.push_back(bitDistance(d, o));
  return out;
}

// The two nearest below `bound` by sorting (distance, index): the definition, not a scan.
NearestTwo sortedNearestTwo(const std::vector<int>& distances, int bound) {
  std::vector<std::pair<int, int>> by_distance;
  for (std::size_t j = 0; j < distances.size(); ++j)
    if (distances[j] < bound) by_distance.emplace_back(distances[j], int(j));
  std::sort(by_distance.begin(), by_distance.end());
  NearestTwo r;
  r.best = r.second = bound;
  if (!by_distance.empty()) {
    r.best = by_distance[0].first;
    r.best_index = by_distance[0].second;
  }
  if (by_distance.size() > 1) {
    r.second = by_distance[1].first;
    r.second_index = by_distance[1].second;
  }
  return r;
}

// The loop as it was before the scans were bounded (initial distance `init`, strict updates).
NearestTwo plainNearestTwo(const Descriptor256& d, const std::vector<Descriptor256>& others, int init) {
  NearestTwo r;
  r.best = r.second = init;
  for (std::size_t j = 0; j < others.size(); ++j) {
    const int dist = bitDistance(d, others[j]);
    if (dist < r.best) {
      r.second = r.best;
      r.second_index = r.best_index;
      r.best = dist;
      r.best_index = int(j);
    } else if (dist < r.second) {
      r.second = dist;
      r.second_index = int(j);
    }
  }
  return r;
}

void expectSame(const NearestTwo& got, const NearestTwo& expected, const char* what, int trial) {
  ASSERT_EQ(got.best, expected.best) << what << " trial " << trial;
  ASSERT_EQ(got.best_index, expected.best_index) << what << " trial " << trial;
  ASSERT_EQ(got.second, expected.second) << what << " trial " << trial;
  ASSERT_EQ(got.second_index, expected.second_index) << what << " trial " << trial;
}

// Descriptor sets with small distances and many ties: copies of a few bases with a few bits flipped
// (sometimes none: exact duplicates), mixed with independent random descriptors.
class DescriptorSets {
 public:
  explicit DescriptorSets(uint32_t seed) : rng_(seed) {}
  Descriptor256 random() {
    Descriptor256 d;
    for (auto& w : d.words) w = (uint64_t(rng_()) << 32) ^ rng_();
    return d;
  }
  Descriptor256 near(const Descriptor256& base, int max_flips) {
    Descriptor256 d = base;
    const int flips = int(rng_() % uint32_t(max_flips + 1));
    for (int f = 0; f < flips; ++f) {
      const uint32_t bit = rng_() % 256;
      d.words[bit / 64] ^= uint64_t(1) << (bit % 64);
    }
    return d;
  }
  std::vector<Descriptor256> set(std::size_t n, const std::vector<Descriptor256>& bases, int max_flips) {
    std::vector<Descriptor256> out;
    for (std::size_t j = 0; j < n; ++j)
      out.push_back(rng_() % 4 == 0 || bases.empty() ? random() : near(bases[rng_() % bases.size()], max_flips));
    return out;
  }
  uint32_t next() { return rng_(); }

 private:
  std::mt19937 rng_;
};

const std::size_t kSizes[] = {0, 1, 2, 3, 4, 5, 7, 8, 15, 16, 17, 33, 64, 127, 500};

// Every build of the scans this CPU can run (kPortable always; kPopcnt and kAvx2 on x86-64).
std::vector<DescriptorScanPath> availablePaths() {
  std::vector<DescriptorScanPath> out;
  for (DescriptorScanPath p : {DescriptorScanPath::kPortable, DescriptorScanPath::kPopcnt, DescriptorScanPath::kAvx2})
    if (descriptorScanAvailable(p)) out.push_back(p);
  return out;
}

TEST(DescriptorMatch, NearestTwoBelowEqualsSortedDefinitionOnEveryPathAndBound) {
  std::printf("descriptor scan builds on this CPU: %zu, in use: %d\n", availablePaths().size(),
              int(descriptorScanPath()));
  DescriptorSets sets(7);
  int trial = 0, ties = 0;
  for (std::size_t n : kSizes) {
    for (int rep = 0; rep < 12; ++rep, ++trial) {
      std::vector<Descriptor256> bases;
      for (int b = 0; b < 1 + rep % 4; ++b) bases.push_back(sets.random());
      const int max_flips = rep % 3 == 0 ? 2 : 40;  // many exact ties, or spread distances
      const std::vector<Descriptor256> others = sets.set(n, bases, max_flips);
      const Descriptor256 d = rep % 5 == 0 ? sets.random() : sets.near(bases[0], max_flips);
      const std::vector<int> distances = bitDistances(d, others);
      for (int bound : {0, 1, 5, 20, 51, 63, 76, 100, 128, 200, 256, 257}) {
        const NearestTwo expected = sortedNearestTwo(distances, bound);
        expectSame(nearestTwoBelow(d, others.data(), n, bound), expected, "dispatched", trial);
        for (DescriptorScanPath path : availablePaths())
          expectSame(nearestTwoBelowOn(path, d, others.data(), n, bound), expected, "path", trial);
        ties += expected.second_index >= 0 && expected.best == expected.second;
      }
      // bound 256 is the unbounded scan: nearestTwo() as it always was.
      expectSame(nearestTwo(d, others.data(), n), plainNearestTwo(d, others, 256), "nearestTwo", trial);
    }
  }
  EXPECT_GT(ties, 50);  // the sets do exercise the first-on-ties rule
}

TEST(DescriptorMatch, RatioBoundIsTheSmallestSecondBestThatAlwaysPasses) {
  for (int t : {-3, 0, 1, 30, 50, 60, 62, 200, 254, 255, 256}) {
    for (float ratio : {0.f, -1.f, 0.5f, 0.7f, 0.8f, 0.9f, 0.99f, 1.f, 1.5f}) {
      for (int none : {256, 257}) {
        const int c = ratioBound(t, ratio, none);
        if (t < 0) {
          EXPECT_EQ(c, 0);
          continue;
        }
        if (t + 1 >= none) {  // no second best above t below `none`: the full scan's initial value
          EXPECT_EQ(c, none);
          continue;
        }
        ASSERT_GT(c, t);
        ASSERT_LE(c, none);
        if (c == none) {
          for (int s = t + 1; s < none; ++s) EXPECT_FALSE(float(t) < ratio * float(s)) << t << " " << ratio;
          continue;
        }
        EXPECT_TRUE(float(t) < ratio * float(c));
        if (c > t + 1) {
          EXPECT_FALSE(float(t) < ratio * float(c - 1));
        }
      }
    }
  }
  EXPECT_EQ(ratioBound(50, 0.8f), 63);  // the loop verifier's and the context check's defaults
  EXPECT_EQ(ratioBound(60, 0.8f), 76);  // LBD's
}

// The loop verifier's decision for one query point, from a nearest-two result: -1 (no match), or
// the matched index(es). Written as loop_verifier.cpp reads the result.
std::pair<int, int> verifierDecision(const NearestTwo& r, int threshold, float ratio, bool ambiguous_pairs) {
  if (r.best_index < 0 || r.best > threshold) return {-1, -1};
  const bool clear = passesRatio(r, ratio);
  const bool ambiguous = !clear && ambiguous_pairs && r.second <= threshold;
  if (!clear && !ambiguous) return {-1, -1};
  return {r.best_index, ambiguous ? r.second_index : -1};
}

TEST(DescriptorMatch, BoundedScanDecidesEveryMatchAsTheFullScan) {
  DescriptorSets sets(11);
  int trial = 0, matched = 0, ambiguous = 0, rejected = 0;
  for (std::size_t n : kSizes) {
    for (int rep = 0; rep < 20; ++rep, ++trial) {
      std::vector<Descriptor256> bases;
      for (int b = 0; b < 2 + rep % 3; ++b) bases.push_back(sets.random());
      const int max_flips = 10 + 10 * (rep % 6);
      const std::vector<Descriptor256> others = sets.set(n, bases, max_flips);
      const Descriptor256 d = sets.near(bases[std::size_t(rep) % bases.size()], max_flips);
      for (int threshold : {-1, 0, 20, 50, 60, 80, 255, 256}) {
        for (float ratio : {0.6f, 0.8f, 0.95f, 1.0f}) {
          const NearestTwo full = plainNearestTwo(d, others, 256);
          const int bound = ratioBound(threshold, ratio);
          const NearestTwo bounded = nearestTwoBelow(d, others.data(), n, bound);
          for (bool pairs : {false, true}) {
            const auto expected = verifierDecision(full, threshold, ratio, pairs);
            ASSERT_EQ(verifierDecision(bounded, threshold, ratio, pairs), expected) << "trial " << trial;
            for (DescriptorScanPath path : availablePaths()) {
              const NearestTwo on_path = nearestTwoBelowOn(path, d, others.data(), n, bound);
              ASSERT_EQ(verifierDecision(on_path, threshold, ratio, pairs), expected) << "trial " << trial;
            }
            matched += expected.first >= 0;
            ambiguous += expected.second >= 0;
            rejected += expected.first < 0;
          }
          const int expected_line = verifierDecision(full, threshold, ratio, false).first;
          ASSERT_EQ(bestRatioMatch(d, others.data(), n, threshold, ratio), expected_line) << "trial " << trial;
        }
      }
    }
  }
  EXPECT_GT(matched, 500);
  EXPECT_GT(ambiguous, 50);
  EXPECT_GT(rejected, 500);
}

// Both ways: rows against the sorted definition; columns: the first a[k] at the smallest distance,
// below the column bound.
TEST(DescriptorMatch, NearestBothWaysEqualsRowAndColumnDefinitions) {
  DescriptorSets sets(5);
  int trial = 0, columns_set = 0;
  const std::size_t sizes[] = {0, 1, 2, 3, 9, 16, 31, 64, 130};
  for (std::size_t na : sizes) {
    for (std::size_t nb : sizes) {
      for (int rep = 0; rep < 3; ++rep, ++trial) {
        std::vector<Descriptor256> bases;
        for (int b = 0; b < 1 + rep; ++b) bases.push_back(sets.random());
        const int max_flips = rep == 0 ? 3 : 30;
        const std::vector<Descriptor256> a = sets.set(na, bases, max_flips), b = sets.set(nb, bases, max_flips);
        std::vector<std::vector<int>> row_distances;  // [k][l]
        for (const Descriptor256& d : a) row_distances.push_back(bitDistances(d, b));
        for (auto [row_bound, col_bound] : {std::pair{257, 257}, std::pair{63, 51}, std::pair{76, 61},
                                            std::pair{20, 40}, std::pair{0, 0}, std::pair{5, 3}}) {
          for (DescriptorScanPath path : availablePaths()) {
            std::vector<NearestTwo> rows(na);
            std::vector<int> col_best(nb, -7), col_index(nb, -7);
            nearestBothWaysOn(path, a.data(), na, b.data(), nb, row_bound, col_bound, rows.data(), col_best.data(),
                              col_index.data());
            for (std::size_t k = 0; k < na; ++k)
              expectSame(rows[k], sortedNearestTwo(row_distances[k], row_bound), "rows", trial);
            for (std::size_t l = 0; l < nb; ++l) {
              int best = col_bound, index = -1;
              for (std::size_t k = 0; k < na; ++k) {
                const int dist = row_distances[k][l];
                if (dist < best) {
                  best = dist;
                  index = int(k);
                }
              }
              ASSERT_EQ(col_best[l], best) << "trial " << trial << " path " << int(path) << " column " << l;
              ASSERT_EQ(col_index[l], index) << "trial " << trial << " path " << int(path) << " column " << l;
              columns_set += index >= 0;
            }
          }
        }
      }
    }
  }
  EXPECT_GT(columns_set, 1000);
}

// The context check's mutual matches (loop_context_check.cpp) as they were computed before: full
// row and column scans from 257, the row's ratio test, the column's best index.
std::vector<std::pair<int, int>> mutualMatchesBefore(const std::vector<std::vector<int>>& distances, std::size_t nb,
                                                     int threshold, float ratio) {
  std::vector<int> best_j(nb, 257), index_j(nb, 0);
  std::vector<std::pair<int, int>> out;
  std::vector<NearestTwo> rows;
  for (std::size_t k = 0; k < distances.size(); ++k) {
    NearestTwo r;
    r.best = r.second = 257;
    for (std::size_t l = 0; l < nb; ++l) {
      const int d = distances[k][l];
      if (d < r.best) {
        r.second = r.best;
        r.second_index = r.best_index;
        r.best = d;
        r.best_index = int(l);
      } else if (d < r.second) {
        r.second = d;
        r.second_index = int(l);
      }
    }
    rows.push_back(r);
    for (std::size_t l = 0; l < nb; ++l) {
      const int d = distances[k][l];
      if (d < best_j[l]) {
        best_j[l] = d;
        index_j[l] = int(k);
      }
    }
  }
  for (std::size_t k = 0; k < distances.size(); ++k) {
    const int d = rows[k].best;
    if (d > threshold || float(d) >= ratio * float(rows[k].second)) continue;
    if (index_j[std::size_t(rows[k].best_index)] != int(k)) continue;
    out.emplace_back(int(k), rows[k].best_index);
  }
  return out;
}

TEST(DescriptorMatch, BoundedBothWaysGivesTheContextChecksMutualMatches) {
  DescriptorSets sets(3);
  int trial = 0, matches = 0;
  for (std::size_t na : {1, 2, 17, 100, 500}) {
    for (std::size_t nb : {1, 3, 64, 500}) {
      for (int rep = 0; rep < 3; ++rep, ++trial) {
        std::vector<Descriptor256> bases;
        for (int b = 0; b < 3 + 20 * rep; ++b) bases.push_back(sets.random());
        const int max_flips = 8 + 12 * rep;
        const std::vector<Descriptor256> a = sets.set(na, bases, max_flips), b = sets.set(nb, bases, max_flips);
        std::vector<std::vector<int>> distances;  // [k][l]
        for (const Descriptor256& d : a) distances.push_back(bitDistances(d, b));
        for (int threshold : {-1, 0, 30, 50, 256}) {
          for (float ratio : {0.8f, 0.9f}) {
            // The bounds loop_context_check.cpp passes.
            const int row_bound = ratioBound(threshold, ratio, 257);
            const int col_bound = std::min(std::max(threshold, -1) + 1, 257);
            const auto expected = mutualMatchesBefore(distances, nb, threshold, ratio);
            matches += int(expected.size());
            for (DescriptorScanPath path : availablePaths()) {
              std::vector<NearestTwo> rows(na);
              std::vector<int> col_best(nb), col_index(nb);
              nearestBothWaysOn(path, a.data(), na, b.data(), nb, row_bound, col_bound, rows.data(), col_best.data(),
                                col_index.data());
              std::vector<std::pair<int, int>> got;
              for (std::size_t k = 0; k < na; ++k) {
                const int d = rows[k].best;
                if (d > threshold || float(d) >= ratio * float(rows[k].second)) continue;
                if (col_index[std::size_t(rows[k].best_index)] != int(k)) continue;
                got.emplace_back(int(k), rows[k].best_index);
              }
              ASSERT_EQ(got, expected) << "trial " << trial << " threshold " << threshold << " path " << int(path);
            }
          }
        }
      }
    }
  }
  EXPECT_GT(matches, 1000);
}

}  // namespace
}  // namespace plumb
