// KeyframeDatabase (pipeline/loop/): queries against an independent brute-force scorer, place
// recognition under bit noise, removal, capacity errors, enumeration round trip, and the
// allocation-free contract of insert / query / remove.
#include "pipeline/loop/keyframe_database.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <set>
#include <vector>

#include "platform/allocation_counter.h"

namespace plumb::loop {
namespace {

Descriptor256 randomDescriptor(std::mt19937_64& rng) {
  Descriptor256 d;
  for (uint64_t& w : d.words) w = rng();
  return d;
}

// Flips each of the 256 bits with probability p.
Descriptor256 flipBits(const Descriptor256& d, double p, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  Descriptor256 out = d;
  for (int b = 0; b < 256; ++b)
    if (u(rng) < p) out.words[b >> 6] ^= uint64_t(1) << (b & 63);
  return out;
}

struct TestKeyframe {
  uint64_t id = 0;
  std::vector<Descriptor256> points, lines;
  PlaceDescriptors view() const { return {points.data(), points.size(), lines.data(), lines.size()}; }
};

// The oracle: scores straight from the definition in keyframe_database.h, with ordinary maps and
// no inverted index. Word values are read bit by bit here, not through descriptorWordValue().
class BruteForceScorer {
 public:
  BruteForceScorer(int bits, double line_weight) : bits_(bits), line_weight_(line_weight) {}

  uint32_t word(const Descriptor256& d, int kind) const {
    uint32_t value = 0;
    for (int k = 0; k < bits_; ++k) {
      const int b = wordBitOrder()[k];
      if (d.words[b / 64] & (uint64_t(1) << (b % 64))) value += uint32_t(1) << k;
    }
    return value + (uint32_t(kind) << bits_);
  }
  std::map<uint32_t, int> histogram(const TestKeyframe& kf) const {
    std::map<uint32_t, int> h;
    for (const auto& d : kf.points) ++h[word(d, 0)];
    for (const auto& d : kf.lines) ++h[word(d, 1)];
    return h;
  }

  // All keyframes with a non-zero score, best first, ties by id.
  std::vector<PlaceCandidate> rank(const std::vector<TestKeyframe>& db, const TestKeyframe& query) const {
    std::map<uint32_t, int> keyframes_with_word;
    std::vector<std::map<uint32_t, int>> histograms;
    for (const TestKeyframe& kf : db) {
      histograms.push_back(histogram(kf));
      for (const auto& [w, c] : histograms.back()) ++keyframes_with_word[w];
    }
    const std::map<uint32_t, int> q = histogram(query);
    const double q_total[2] = {double(query.points.size()), double(query.lines.size())};
    auto idf = [&](uint32_t w) {
      const auto it = keyframes_with_word.find(w);
      const double n_w = it == keyframes_with_word.end() ? 1.0 : it->second;
      return std::log(1.0 + double(db.size()) / n_w);
    };
    double self[2] = {0, 0};
    for (const auto& [w, c] : q) self[w >> bits_] += idf(w) * (c / q_total[w >> bits_]);
    std::vector<PlaceCandidate> out;
    for (std::size_t k = 0; k < db.size(); ++k) {
      const double d_total[2] = {double(db[k].points.size()), double(db[k].lines.size())};
      double sum[2] = {0, 0};
      bool shares = false;
      for (const auto& [w, c] : q) {  // ascending words, like the database
        const auto it = histograms[k].find(w);
        if (it == histograms[k].end()) continue;
        shares = true;
        const int kind = int(w >> bits_);
        sum[kind] += idf(w) * std::min(c / q_total[kind], it->second / d_total[kind]);
      }
      if (!shares) continue;
      PlaceCandidate c;
      c.keyframe_id = db[k].id;
      c.point_score = self[0] > 0 ? sum[0] / self[0] : 0;
      c.line_score = self[1] > 0 ? sum[1] / self[1] : 0;
      c.score = (c.point_score + line_weight_ * c.line_score) / (1 + line_weight_);
      if (c.score > 0) out.push_back(c);
    }
    std::sort(out.begin(), out.end(), [](const PlaceCandidate& a, const PlaceCandidate& b) {
      return a.score != b.score ? a.score > b.score : a.keyframe_id < b.keyframe_id;
    });
    return out;
  }

 private:
  int bits_;
  double line_weight_;
};

// Keyframes drawn from a shared pool of descriptors (with repeats), so that they share words in
// varying amounts and the scores are spread out.
std::vector<TestKeyframe> makePoolKeyframes(int count, uint64_t first_id, std::mt19937_64& rng) {
  std::vector<Descriptor256> pool(1500);
  for (auto& d : pool) d = randomDescriptor(rng);
  std::uniform_int_distribution<int> pick(0, int(pool.size()) - 1), n_points(50, 400), n_lines(0, 60);
  std::vector<TestKeyframe> keyframes(count);
  for (int k = 0; k < count; ++k) {
    keyframes[k].id = first_id + uint64_t(k) * 3;  // ids need not be dense
    for (int i = n_points(rng); i > 0; --i) keyframes[k].points.push_back(pool[pick(rng)]);
    for (int i = n_lines(rng); i > 0; --i) keyframes[k].lines.push_back(pool[pick(rng)]);
  }
  return keyframes;
}

void expectSameRanking(const std::vector<PlaceCandidate>& expected, const PlaceCandidates& got, std::size_t n,
                       const char* what) {
  ASSERT_EQ(got.size(), std::min(n, expected.size())) << what;
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].keyframe_id, expected[i].keyframe_id) << what << " rank " << i;
    EXPECT_NEAR(got[i].score, expected[i].score, 1e-12) << what << " rank " << i;
    EXPECT_NEAR(got[i].point_score, expected[i].point_score, 1e-12) << what << " rank " << i;
    EXPECT_NEAR(got[i].line_score, expected[i].line_score, 1e-12) << what << " rank " << i;
  }
}

TEST(KeyframeDatabase, WordsAreTheChosenBits) {
  const auto& order = wordBitOrder();
  std::set<int> distinct(order.begin(), order.end());
  EXPECT_EQ(distinct.size(), 256u) << "a permutation of the 256 bits";
  std::mt19937_64 rng(5);
  BruteForceScorer oracle(16, 0.5);
  for (int i = 0; i < 200; ++i) {
    const Descriptor256 d = randomDescriptor(rng);
    EXPECT_EQ(wordId(DescriptorKind::kPoint, descriptorWordValue(d, 16), 16), oracle.word(d, 0));
    EXPECT_EQ(wordId(DescriptorKind::kLine, descriptorWordValue(d, 16), 16), oracle.word(d, 1));
  }
  // Flipping a bit outside the first K of the order leaves the word unchanged; inside, changes it.
  Descriptor256 d = randomDescriptor(rng), outside = d, inside = d;
  outside.words[order[200] >> 6] ^= uint64_t(1) << (order[200] & 63);
  inside.words[order[3] >> 6] ^= uint64_t(1) << (order[3] & 63);
  EXPECT_EQ(descriptorWordValue(d, 16), descriptorWordValue(outside, 16));
  EXPECT_EQ(descriptorWordValue(d, 16) ^ 8u, descriptorWordValue(inside, 16));
}

TEST(KeyframeDatabase, QueriesMatchBruteForce) {
  for (int bits : {10, 16}) {  // 10 bits: many shared words and counts > 1
    std::mt19937_64 rng(100 + bits);
    KeyframeDatabaseOptions options;
    options.max_keyframes = 80;
    options.bits_per_word = bits;
    options.max_postings = 80 * 460;
    KeyframeDatabase db(options);
    BruteForceScorer oracle(bits, options.line_weight);
    std::vector<TestKeyframe> held = makePoolKeyframes(60, 1000, rng);
    for (const TestKeyframe& kf : held) ASSERT_TRUE(db.insert(kf.id, kf.view()).ok());
    // Remove a third, then add fresh ones into the freed slots and postings.
    for (int k = 0; k < 20; ++k) {
      const std::size_t victim = std::size_t(rng() % held.size());
      ASSERT_TRUE(db.remove(held[victim].id).ok());
      held.erase(held.begin() + std::ptrdiff_t(victim));
    }
    for (const TestKeyframe& kf : makePoolKeyframes(15, 5000, rng)) {
      ASSERT_TRUE(db.insert(kf.id, kf.view()).ok());
      held.push_back(kf);
    }
    ASSERT_EQ(db.size(), held.size());

    for (int q = 0; q < 10; ++q) {
      const TestKeyframe query = makePoolKeyframes(1, 0, rng)[0];
      const std::vector<PlaceCandidate> expected = oracle.rank(held, query);
      ASSERT_GT(expected.size(), 12u);
      PlaceCandidates got;
      PlaceQueryOptions qo;
      qo.max_results = 12;
      db.query(query.view(), qo, &got);
      expectSameRanking(expected, got, 12, bits == 10 ? "10 bits" : "16 bits");
      // A query never drops a candidate that a larger N would rank higher.
      qo.max_results = kMaxPlaceCandidates;
      db.query(query.view(), qo, &got);
      expectSameRanking(expected, got, kMaxPlaceCandidates, "all");

      // Exclusions: an id bound, and a predicate (odd ids out).
      qo.max_results = 8;
      qo.max_candidate_id = 4000;
      qo.exclude = [](uint64_t id, const void*) { return id % 2 == 1; };
      std::vector<PlaceCandidate> allowed;
      for (const PlaceCandidate& c : expected)
        if (c.keyframe_id <= 4000 && c.keyframe_id % 2 == 0) allowed.push_back(c);
      db.query(query.view(), qo, &got);
      expectSameRanking(allowed, got, 8, "excluded");
    }
  }
}

// The intended use: a keyframe seen again, its descriptors a few bits off and some features new.
TEST(KeyframeDatabase, ReobservedKeyframeRanksFirst) {
  std::mt19937_64 rng(7);
  KeyframeDatabase db(KeyframeDatabaseOptions{});
  std::vector<TestKeyframe> keyframes(150);
  for (std::size_t k = 0; k < keyframes.size(); ++k) {
    keyframes[k].id = k;
    for (int i = 0; i < 1000; ++i) keyframes[k].points.push_back(randomDescriptor(rng));
    for (int i = 0; i < 150; ++i) keyframes[k].lines.push_back(randomDescriptor(rng));
    ASSERT_TRUE(db.insert(k, keyframes[k].view()).ok());
  }
  for (uint64_t target : {3u, 77u, 149u}) {
    TestKeyframe query;
    std::uniform_real_distribution<double> u(0, 1);
    // 8% of the bits flipped (~20 of 256), 30% of the features replaced by unseen ones.
    for (const auto& d : keyframes[target].points)
      query.points.push_back(u(rng) < 0.3 ? randomDescriptor(rng) : flipBits(d, 0.08, rng));
    for (const auto& d : keyframes[target].lines)
      query.lines.push_back(u(rng) < 0.3 ? randomDescriptor(rng) : flipBits(d, 0.08, rng));
    PlaceCandidates got;
    PlaceQueryOptions qo;
    db.query(query.view(), qo, &got);
    ASSERT_GE(got.size(), 2u);
    EXPECT_EQ(got[0].keyframe_id, target);
    EXPECT_GT(got[0].point_score, 0.1);
    EXPECT_GT(got[0].line_score, 0.1);
    EXPECT_GT(got[0].score, 5 * got[1].score) << "the true place stands out";
    std::printf("target %llu: score %.3f (points %.3f lines %.3f), runner-up %.4f\n",
                (unsigned long long)target, got[0].score, got[0].point_score, got[0].line_score,
                got[1].score);

    // The local window excluded: the true keyframe is not returned.
    qo.max_candidate_id = target - 1;
    db.query(query.view(), qo, &got);
    for (const PlaceCandidate& c : got) EXPECT_LT(c.keyframe_id, target);
  }
}

TEST(KeyframeDatabase, RemoveForgetsTheKeyframe) {
  std::mt19937_64 rng(11);
  KeyframeDatabaseOptions options;
  options.max_keyframes = 40;
  KeyframeDatabase db(options);
  const std::size_t all_postings = db.freePostings();
  std::vector<TestKeyframe> keyframes = makePoolKeyframes(30, 10, rng);
  for (const TestKeyframe& kf : keyframes) ASSERT_TRUE(db.insert(kf.id, kf.view()).ok());
  const TestKeyframe& gone = keyframes[12];
  PlaceCandidates got;
  db.query(gone.view(), PlaceQueryOptions{}, &got);
  ASSERT_FALSE(got.empty());
  EXPECT_EQ(got[0].keyframe_id, gone.id);
  EXPECT_NEAR(got[0].score, 1.0, 1e-12) << "a keyframe matches itself completely";

  ASSERT_TRUE(db.remove(gone.id).ok());
  EXPECT_FALSE(db.contains(gone.id));
  EXPECT_EQ(db.size(), 29u);
  EXPECT_FALSE(db.remove(gone.id).ok()) << "twice";
  EXPECT_EQ(db.numKeyframeWords(gone.id), 0u);
  db.query(gone.view(), PlaceQueryOptions{}, &got);
  for (const PlaceCandidate& c : got) EXPECT_NE(c.keyframe_id, gone.id);
  // The rest still ranks as brute force says.
  std::vector<TestKeyframe> rest = keyframes;
  rest.erase(rest.begin() + 12);
  expectSameRanking(BruteForceScorer(16, options.line_weight).rank(rest, gone), got, 10, "after remove");

  for (const TestKeyframe& kf : rest) ASSERT_TRUE(db.remove(kf.id).ok());
  EXPECT_EQ(db.size(), 0u);
  EXPECT_EQ(db.freePostings(), all_postings) << "every posting returned";
  db.query(gone.view(), PlaceQueryOptions{}, &got);
  EXPECT_TRUE(got.empty());
  ASSERT_TRUE(db.insert(gone.id, gone.view()).ok()) << "an id can come back";
}

TEST(KeyframeDatabase, FullIsAnErrorNotACrash) {
  std::mt19937_64 rng(13);
  KeyframeDatabaseOptions options;
  options.max_keyframes = 3;
  options.max_point_descriptors = 400;
  options.max_line_descriptors = 60;
  options.max_postings = 3000;
  KeyframeDatabase db(options);
  std::vector<TestKeyframe> keyframes = makePoolKeyframes(5, 1, rng);
  for (int k = 0; k < 3; ++k) ASSERT_TRUE(db.insert(keyframes[k].id, keyframes[k].view()).ok());
  Status st = db.insert(keyframes[3].id, keyframes[3].view());
  EXPECT_FALSE(st.ok());
  EXPECT_NE(st.message().find("full"), std::string::npos) << st.message();
  EXPECT_EQ(db.size(), 3u);
  EXPECT_FALSE(db.insert(keyframes[0].id, keyframes[0].view()).ok()) << "duplicate id";

  ASSERT_TRUE(db.remove(keyframes[0].id).ok());
  TestKeyframe big = keyframes[4];
  while (big.points.size() <= 400) big.points.push_back(randomDescriptor(rng));
  st = db.insert(big.id, big.view());
  EXPECT_NE(st.message().find("descriptors"), std::string::npos) << st.message();

  // Postings: a keyframe with more distinct words than are free is refused, nothing changes.
  TestKeyframe many;
  many.id = 99;
  for (int i = 0; i < 400; ++i) many.points.push_back(randomDescriptor(rng));
  KeyframeDatabaseOptions tight = options;
  tight.max_postings = 300;
  KeyframeDatabase small(tight);
  st = small.insert(many.id, many.view());
  EXPECT_NE(st.message().find("out of postings"), std::string::npos) << st.message();
  EXPECT_EQ(small.size(), 0u);
  EXPECT_EQ(small.freePostings(), 300u);

  // Bad re-insertion word lists.
  const WordCount unsorted[2] = {{5, 1}, {4, 1}};
  EXPECT_FALSE(db.insertWords(50, unsorted, 2).ok());
  const WordCount out_of_range[1] = {{uint32_t(2) << 16, 1}};
  EXPECT_FALSE(db.insertWords(50, out_of_range, 1).ok());
  EXPECT_FALSE(db.contains(50));

  KeyframeDatabaseOptions bad;
  bad.bits_per_word = 24;
  EXPECT_FALSE(validate(bad).ok());
  bad = KeyframeDatabaseOptions{};
  bad.max_keyframes = 0;
  EXPECT_FALSE(validate(bad).ok());
  EXPECT_TRUE(validate(KeyframeDatabaseOptions{}).ok());
}

TEST(KeyframeDatabase, EnumerateAndReinsertGivesTheSameDatabase) {
  std::mt19937_64 rng(17);
  KeyframeDatabaseOptions options;
  options.max_keyframes = 50;
  options.max_postings = 50 * 460;
  KeyframeDatabase original(options);
  std::vector<TestKeyframe> keyframes = makePoolKeyframes(40, 7, rng);
  for (const TestKeyframe& kf : keyframes) ASSERT_TRUE(original.insert(kf.id, kf.view()).ok());
  for (int k = 0; k < 40; k += 4) ASSERT_TRUE(original.remove(keyframes[k].id).ok());

  KeyframeDatabase copy(options);
  std::vector<uint64_t> ids(64);
  ids.resize(original.keyframeIds(ids.data(), ids.size()));
  ASSERT_EQ(ids.size(), 30u);
  EXPECT_TRUE(std::is_sorted(ids.begin(), ids.end()));
  const BruteForceScorer oracle(16, options.line_weight);
  for (uint64_t id : ids) {
    std::vector<WordCount> words(original.numKeyframeWords(id));
    std::size_t n = 0;
    ASSERT_TRUE(original.keyframeWords(id, words.data(), words.size(), &n).ok());
    ASSERT_EQ(n, words.size());
    // The words are the keyframe's histogram.
    const auto it =
        std::find_if(keyframes.begin(), keyframes.end(), [id](const TestKeyframe& k) { return k.id == id; });
    const std::map<uint32_t, int> h = oracle.histogram(*it);
    ASSERT_EQ(h.size(), n);
    std::size_t i = 0;
    for (const auto& [w, c] : h) {
      EXPECT_EQ(words[i].word, w);
      EXPECT_EQ(words[i].count, uint32_t(c));
      ++i;
    }
    ASSERT_TRUE(copy.insertWords(id, words.data(), n).ok());
  }
  EXPECT_EQ(copy.freePostings(), original.freePostings());
  for (int q = 0; q < 5; ++q) {
    const TestKeyframe query = makePoolKeyframes(1, 0, rng)[0];
    PlaceCandidates a, b;
    PlaceQueryOptions qo;
    qo.max_results = kMaxPlaceCandidates;
    original.query(query.view(), qo, &a);
    copy.query(query.view(), qo, &b);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].keyframe_id, b[i].keyframe_id);
      EXPECT_EQ(a[i].score, b[i].score) << "bit-identical";
    }
  }
}

TEST(KeyframeDatabase, InsertQueryRemoveAllocateNothing) {
  std::mt19937_64 rng(19);
  std::vector<TestKeyframe> keyframes(40);
  for (std::size_t k = 0; k < keyframes.size(); ++k) {
    keyframes[k].id = k;
    for (int i = 0; i < 1000; ++i) keyframes[k].points.push_back(randomDescriptor(rng));
    for (int i = 0; i < 150; ++i) keyframes[k].lines.push_back(randomDescriptor(rng));
  }
  std::vector<WordCount> words(2000);
  auto db = std::make_unique<KeyframeDatabase>(KeyframeDatabaseOptions{});
  auto got = std::make_unique<PlaceCandidates>();
  uint64_t ids[64];
  PlaceQueryOptions qo;
  qo.max_candidate_id = 1000;
  qo.exclude = [](uint64_t id, const void* context) { return id == *static_cast<const uint64_t*>(context); };
  const uint64_t excluded = 5;
  qo.exclude_context = &excluded;

  AllocationScope scope;
  for (const TestKeyframe& kf : keyframes) {
    if (!db->insert(kf.id, kf.view()).ok()) ADD_FAILURE();
    db->query(kf.view(), qo, got.get());
  }
  for (std::size_t k = 0; k < keyframes.size(); k += 2)
    if (!db->remove(keyframes[k].id).ok()) ADD_FAILURE();
  std::size_t n = 0;
  const std::size_t num_ids = db->keyframeIds(ids, 64);
  if (!db->keyframeWords(ids[0], words.data(), words.size(), &n).ok()) ADD_FAILURE();
  if (!db->remove(ids[0]).ok()) ADD_FAILURE();
  if (!db->insertWords(ids[0], words.data(), n).ok()) ADD_FAILURE();
  db->query(keyframes[1].view(), qo, got.get());
  const uint64_t allocations = scope.count();
  EXPECT_EQ(allocations, 0u);
  EXPECT_EQ(num_ids, 20u);
  ASSERT_FALSE(got->empty());
  EXPECT_EQ((*got)[0].keyframe_id, 1u);
}

TEST(KeyframeDatabase, MemoryIsFixedAndReported) {
  const KeyframeDatabaseOptions defaults;
  const uint64_t before = allocatedBytes();
  auto db = std::make_unique<KeyframeDatabase>(defaults);
  const uint64_t allocated = allocatedBytes() - before;
  EXPECT_EQ(db->memoryBytes(), KeyframeDatabase::memoryBytesFor(defaults));
  // What construction really allocated (vectors sized exactly) is what memoryBytes() reports:
  // operator new for everything but the postings, which come from calloc (zero pages, made
  // resident later; the hook counts operator new only).
  KeyframeDatabaseOptions one_fewer = defaults;
  one_fewer.max_postings -= 1;
  const std::size_t posting_bytes = db->memoryBytes() - KeyframeDatabase::memoryBytesFor(one_fewer);
  EXPECT_EQ(posting_bytes, 16u);
  EXPECT_EQ(allocated + std::size_t(defaults.max_postings) * posting_bytes, db->memoryBytes());
  std::printf("default KeyframeDatabase: %zu bytes (%.2f MiB); posting %zu bytes\n", db->memoryBytes(),
              db->memoryBytes() / 1048576.0, (db->memoryBytes() - KeyframeDatabase::memoryBytesFor([] {
                                                KeyframeDatabaseOptions o;
                                                o.max_postings -= 1;
                                                return o;
                                              }())));
}

}  // namespace
}  // namespace plumb::loop
