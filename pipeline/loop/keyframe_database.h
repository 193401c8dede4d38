#pragma once
// KeyframeDatabase: place recognition over ORB and LBD descriptors with no vocabulary file.
// Words are fixed descriptor bits (place_words.h); an inverted index maps each word to the
// keyframes that contain it; a query scores every keyframe sharing a word with the query and
// returns the best N. See docs/LOOP.md.
//
//   KeyframeDatabase db(KeyframeDatabaseOptions{});   // all memory allocated here
//   db.insert(id, PlaceDescriptors{orb, n_orb, lbd, n_lbd});
//   PlaceQueryOptions q;  q.max_candidate_id = id - 30;  // skip the local window
//   PlaceCandidates out;  db.query(descriptors, q, &out);
//   db.remove(culled_id);
//
// Score of keyframe d for query q, per descriptor kind (points, lines), with L1-normalised term
// frequencies q_w = c_q(w) / C_q, d_w = c_d(w) / C_d and idf(w) = ln(1 + N / max(n_w, 1))
// (N keyframes in the database, n_w of them contain w):
//
//   s_kind(q, d) = sum_w idf(w) min(q_w, d_w)  /  sum_w idf(w) q_w          in [0, 1]
//
// min(q_w, d_w) summed over words is the L1 score of DBoW2, 1 - |q - d|_1 / 2; the idf weights
// make frequent (uninformative) words count less, and the denominator (the query's score against
// itself) makes 1 mean "every weighted word of the query is in d". Per-keyframe weights do not
// depend on the rest of the database, so removing a keyframe only decrements n_w.
// Combined: s = (s_point + line_weight * s_line) / (1 + line_weight), line_weight 0.5 by default
// (a frame has ~150 lines against ~1000 points, so the line score is the noisier one; it still
// carries low-texture frames, where points are few).
//
// Memory: fixed at construction (memoryBytes()). insert(), insertWords(), remove() and query()
// allocate nothing; a full database or an oversized keyframe is an error Status (the error
// message is the only allocation), never a crash. Results are deterministic: the same sequence of
// calls gives bit-identical scores, ties are broken by ascending keyframe id.
// Not thread-safe: one owner (the loop stage).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pipeline/frontend/frame_features.h"
#include "pipeline/loop/place_words.h"
#include "platform/fixed_vector.h"
#include "platform/memory_residency.h"
#include "platform/status.h"
#include "solver/zero_page_allocator.h"

namespace plumb::loop {

struct KeyframeDatabaseOptions {
  // Keyframes held at once (a culled keyframe frees its slot). 512 covers a room-sized map whose
  // keyframe graph is kept bounded by culling.
  int max_keyframes = 512;
  // Descriptors one keyframe may bring (defaults: the front end's capacities kMaxKeypoints and
  // kMaxLines; at most 65535 each); a keyframe with more is refused.
  int max_point_descriptors = 1200;
  int max_line_descriptors = 200;
  // Postings (distinct words of a keyframe = one posting each) over all keyframes. A 1000-point,
  // 150-line keyframe has ~1100 distinct words, hence 512 x 1100.
  int max_postings = 512 * 1100;
  int bits_per_word = kDefaultWordBits;  // K, in [kMinWordBits, kMaxWordBits]
  double line_weight = 0.5;              // weight of the line score in the combined score
};

// Empty-OK or the first bad option.
Status validate(const KeyframeDatabaseOptions& options);

// Descriptors of one keyframe (or of a query view); the pointers may be null when the count is 0.
struct PlaceDescriptors {
  const Descriptor256* points = nullptr;
  std::size_t num_points = 0;
  const Descriptor256* lines = nullptr;
  std::size_t num_lines = 0;
};

struct PlaceCandidate {
  uint64_t keyframe_id = 0;
  double score = 0;        // combined score, in [0, 1]
  double point_score = 0;  // s_point
  double line_score = 0;   // s_line
};

constexpr std::size_t kMaxPlaceCandidates = 32;
using PlaceCandidates = FixedVector<PlaceCandidate, kMaxPlaceCandidates>;

// Which keyframes a query may return. Two ways to leave out the local window: an id bound (the
// keyframes are numbered in time, so `query_id - min_age` is a minimum age) and/or a predicate.
struct PlaceQueryOptions {
  std::size_t max_results = 10;            // <= kMaxPlaceCandidates
  uint64_t max_candidate_id = UINT64_MAX;  // keyframes with a larger id are skipped
  // Optional: keyframes for which exclude(id, exclude_context) is true are skipped. A plain
  // function pointer (not std::function) so that a query never allocates.
  bool (*exclude)(uint64_t keyframe_id, const void* context) = nullptr;
  const void* exclude_context = nullptr;
  double min_score = 0.0;  // candidates must score above this (> 0: they share at least a word)
};

class KeyframeDatabase {
 public:
  explicit KeyframeDatabase(const KeyframeDatabaseOptions& options);  // options must validate()

  // Adds a keyframe. Errors (nothing changed): duplicate id, too many descriptors, no free
  // keyframe slot, not enough free postings.
  Status insert(uint64_t keyframe_id, const PlaceDescriptors& descriptors);
  // Adds a keyframe from its word list as keyframeWords() gives it (re-insertion from a saved
  // map). Words must be valid ids for this database's bits_per_word, strictly ascending, counts
  // >= 1; the per-kind count totals must fit the descriptor limits.
  Status insertWords(uint64_t keyframe_id, const WordCount* words, std::size_t num_words);
  // Removes a keyframe (e.g. culled from the map). Error if the id is not in the database.
  Status remove(uint64_t keyframe_id);

  // Best candidates for a view, best first (score descending, then keyframe id ascending).
  void query(const PlaceDescriptors& descriptors, const PlaceQueryOptions& options, PlaceCandidates* out);

  bool contains(uint64_t keyframe_id) const { return findSlot(keyframe_id) >= 0; }
  std::size_t size() const { return num_keyframes_; }
  std::size_t freePostings() const { return free_postings_; }
  const KeyframeDatabaseOptions& options() const { return options_; }

  // Enumeration for a serialiser: the ids held, ascending (up to max_ids of them; returns how
  // many were written), and one keyframe's words, ascending by word id.
  std::size_t keyframeIds(uint64_t* ids, std::size_t max_ids) const;
  // Distinct words of a keyframe (0 if unknown): the size keyframeWords() needs.
  std::size_t numKeyframeWords(uint64_t keyframe_id) const;
  Status keyframeWords(uint64_t keyframe_id, WordCount* words, std::size_t max_words,
                       std::size_t* num_words) const;

  // Bytes held by the database (the object and every buffer it allocated at construction).
  std::size_t memoryBytes() const;
  // Queues the postings array (the part of memoryBytes() not written at construction).
  void queueReservedMemory(ResidencyQueue* queue) { queue->add(postings_.data(), postings_.size() * sizeof(Posting)); }
  // The same figure for given options, without building a database.
  static std::size_t memoryBytesFor(const KeyframeDatabaseOptions& options);

 private:
  static constexpr uint32_t kNone = UINT32_MAX;

  // One posting: keyframe `slot` contains `word` `count` times. Linked in its word's list and in
  // its keyframe's list, forward only: 16 bytes. Removing a keyframe finds each posting's
  // predecessor by walking its word's list from the head (at most one posting per keyframe held),
  // which costs a cull a few hundred thousand steps, about one query's worth.
  struct Posting {
    uint32_t word = 0;
    uint16_t count = 0;  // <= max descriptors of a kind (validate(): <= 65535)
    uint16_t slot = 0;   // < max_keyframes (<= 65535)
    uint32_t next_in_word = kNone;
    uint32_t next_in_keyframe = kNone;
  };
  static_assert(sizeof(uint16_t) == 2, "Posting packs to 16 bytes");
  struct KeyframeSlot {
    uint64_t id = 0;
    bool used = false;
    uint32_t first_posting = kNone;
    uint32_t num_postings = 0;
    uint32_t total_count[2] = {0, 0};  // descriptors per kind: the L1 norms C_d
  };
  // A candidate under construction during a query.
  struct Scored {
    double score, point_score, line_score;
    uint64_t id;
  };

  int findSlot(uint64_t keyframe_id) const;
  // Descriptors -> sorted distinct words with counts, into words_scratch_; returns how many.
  std::size_t histogram(const PlaceDescriptors& descriptors);
  Status insertHistogram(uint64_t keyframe_id, const WordCount* words, std::size_t num_words,
                         const uint32_t total_count[2]);
  double idf(uint32_t word) const;

  KeyframeDatabaseOptions options_;
  std::size_t num_words_total_ = 0;  // 2 * 2^K

  std::vector<uint32_t> word_head_;       // per word: first posting, kNone if empty
  // From kernel zero pages (solver/zero_page_allocator.h): a posting is assigned whole when it is
  // taken, so the array costs resident memory as it is used (or when the owner makes it resident,
  // queueReservedMemory), not at construction.
  std::vector<Posting, ZeroPageAllocator<Posting>> postings_;
  uint32_t free_posting_head_ = kNone;  // returned postings, chained through next_in_keyframe
  uint32_t fresh_postings_ = 0;         // postings [fresh_postings_, size) were never taken
  std::size_t free_postings_ = 0;
  std::vector<KeyframeSlot> slots_;
  std::vector<uint32_t> free_slots_;  // stack of free slot indices
  std::size_t num_keyframes_ = 0;

  // Query and insert scratch, sized at construction.
  std::vector<uint32_t> word_values_scratch_;  // one word id per descriptor
  std::vector<WordCount> words_scratch_;       // distinct words with counts
  std::vector<double> accumulator_[2];         // per slot: numerator of s_point, s_line
  std::vector<uint32_t> touched_slots_;
  std::vector<uint8_t> slot_touched_;
  std::vector<Scored> scored_scratch_;
};

}  // namespace plumb::loop
