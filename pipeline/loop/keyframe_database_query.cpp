// KeyframeDatabase queries: word histograms and the inverted-index scoring (see keyframe_database.h).
#include <algorithm>
#include <cmath>

#include "pipeline/loop/keyframe_database.h"

namespace plumb::loop {

std::size_t KeyframeDatabase::histogram(const PlaceDescriptors& descriptors) {
  const int bits = options_.bits_per_word;
  std::size_t n = 0;
  for (std::size_t i = 0; i < descriptors.num_points; ++i)
    word_values_scratch_[n++] =
        wordId(DescriptorKind::kPoint, descriptorWordValue(descriptors.points[i], bits), bits);
  for (std::size_t i = 0; i < descriptors.num_lines; ++i)
    word_values_scratch_[n++] =
        wordId(DescriptorKind::kLine, descriptorWordValue(descriptors.lines[i], bits), bits);
  std::sort(word_values_scratch_.begin(), word_values_scratch_.begin() + std::ptrdiff_t(n));
  std::size_t distinct = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (distinct > 0 && words_scratch_[distinct - 1].word == word_values_scratch_[i]) {
      ++words_scratch_[distinct - 1].count;
    } else {
      words_scratch_[distinct++] = WordCount{word_values_scratch_[i], 1};
    }
  }
  return distinct;
}

double KeyframeDatabase::idf(uint32_t word) const {
  // n_w = the length of the word's list (a keyframe has at most one posting per word): counted
  // here rather than kept per word, which would cost 2^(K+1) counters (256 KB at K = 16).
  uint32_t n_w = 0;
  for (uint32_t p = word_head_[word]; p != kNone; p = postings_[p].next_in_word) ++n_w;
  return std::log(1.0 + double(num_keyframes_) / double(std::max<uint32_t>(n_w, 1u)));
}

void KeyframeDatabase::query(const PlaceDescriptors& descriptors, const PlaceQueryOptions& options,
                             PlaceCandidates* out) {
  out->clear();
  if (descriptors.num_points > std::size_t(options_.max_point_descriptors) ||
      descriptors.num_lines > std::size_t(options_.max_line_descriptors)) {
    // Score on the first descriptors only (the caller's order, usually by response): a query never
    // fails, and never writes past its scratch.
    PlaceDescriptors clipped = descriptors;
    clipped.num_points = std::min(clipped.num_points, std::size_t(options_.max_point_descriptors));
    clipped.num_lines = std::min(clipped.num_lines, std::size_t(options_.max_line_descriptors));
    query(clipped, options, out);
    return;
  }
  const std::size_t num_words = histogram(descriptors);
  const int bits = options_.bits_per_word;
  const double query_total[2] = {double(descriptors.num_points), double(descriptors.num_lines)};
  double self_score[2] = {0, 0};  // sum_w idf(w) q_w: the denominators
  std::size_t num_touched = 0;
  // Words in ascending order, so each slot's sums are added in one fixed order (deterministic,
  // and the same order a brute-force scorer over sorted words uses).
  for (std::size_t i = 0; i < num_words; ++i) {
    const WordCount& wc = words_scratch_[i];
    const std::size_t kind = std::size_t(wordKind(wc.word, bits));
    const double weight = idf(wc.word);
    const double q_w = wc.count / query_total[kind];
    self_score[kind] += weight * q_w;
    for (uint32_t p = word_head_[wc.word]; p != kNone; p = postings_[p].next_in_word) {
      const Posting& posting = postings_[p];
      const double d_w = posting.count / double(slots_[posting.slot].total_count[kind]);
      accumulator_[kind][posting.slot] += weight * std::min(q_w, d_w);
      if (!slot_touched_[posting.slot]) {
        slot_touched_[posting.slot] = 1;
        touched_slots_[num_touched++] = posting.slot;
      }
    }
  }

  std::size_t num_scored = 0;
  for (std::size_t t = 0; t < num_touched; ++t) {
    const uint32_t s = touched_slots_[t];
    const uint64_t id = slots_[s].id;
    const double point_score = self_score[0] > 0 ? accumulator_[0][s] / self_score[0] : 0.0;
    const double line_score = self_score[1] > 0 ? accumulator_[1][s] / self_score[1] : 0.0;
    accumulator_[0][s] = accumulator_[1][s] = 0.0;
    slot_touched_[s] = 0;
    if (id > options.max_candidate_id) continue;
    if (options.exclude != nullptr && options.exclude(id, options.exclude_context)) continue;
    const double score = (point_score + options_.line_weight * line_score) / (1.0 + options_.line_weight);
    if (!(score > options.min_score)) continue;
    scored_scratch_[num_scored++] = Scored{score, point_score, line_score, id};
  }
  const std::size_t keep = std::min({num_scored, options.max_results, kMaxPlaceCandidates});
  std::partial_sort(
      scored_scratch_.begin(), scored_scratch_.begin() + std::ptrdiff_t(keep),
      scored_scratch_.begin() + std::ptrdiff_t(num_scored),
      [](const Scored& a, const Scored& b) { return a.score != b.score ? a.score > b.score : a.id < b.id; });
  for (std::size_t i = 0; i < keep; ++i) {
    const Scored& c = scored_scratch_[i];
    (void)out->push_back(PlaceCandidate{c.id, c.score, c.point_score, c.line_score});
  }
}

}  // namespace plumb::loop
