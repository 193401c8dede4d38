// KeyframeDatabase storage: construction, insert, remove, enumeration (queries in
// keyframe_database_query.cpp). See keyframe_database.h.
#include "pipeline/loop/keyframe_database.h"

#include <algorithm>
#include <cassert>
#include <string>

namespace plumb::loop {

Status validate(const KeyframeDatabaseOptions& o) {
  if (o.max_keyframes < 1 || o.max_keyframes > 65535)
    return Status::Error("keyframe database: max_keyframes must be in 1..65535");
  if (o.max_point_descriptors < 0 || o.max_line_descriptors < 0 ||
      o.max_point_descriptors + o.max_line_descriptors < 1 || o.max_point_descriptors > 65535 ||
      o.max_line_descriptors > 65535)
    return Status::Error("keyframe database: descriptor limits must be in 0..65535 and not both 0");
  if (o.max_postings < 1) return Status::Error("keyframe database: max_postings must be >= 1");
  if (o.bits_per_word < kMinWordBits || o.bits_per_word > kMaxWordBits)
    return Status::Error("keyframe database: bits_per_word must be in " + std::to_string(kMinWordBits) +
                         ".." + std::to_string(kMaxWordBits));
  if (!(o.line_weight >= 0) || !(o.line_weight <= 1e6))
    return Status::Error("keyframe database: line_weight must be a number >= 0");
  return Status::Ok();
}

KeyframeDatabase::KeyframeDatabase(const KeyframeDatabaseOptions& options) : options_(options) {
  assert(validate(options).ok());
  num_words_total_ = std::size_t(2) << options.bits_per_word;
  word_head_.assign(num_words_total_, kNone);
  postings_.resize(std::size_t(options.max_postings));  // zero pages, not written (header)
  // The first inserts take postings 0, 1, 2, ... in order; removed ones are chained for reuse.
  free_posting_head_ = kNone;
  fresh_postings_ = 0;
  free_postings_ = postings_.size();
  slots_.resize(std::size_t(options.max_keyframes));
  free_slots_.reserve(slots_.size());
  for (std::size_t i = slots_.size(); i-- > 0;) free_slots_.push_back(uint32_t(i));  // slot 0 on top
  const std::size_t max_descriptors =
      std::size_t(options.max_point_descriptors + options.max_line_descriptors);
  word_values_scratch_.resize(max_descriptors);
  words_scratch_.resize(max_descriptors);
  for (std::vector<double>& a : accumulator_) a.assign(slots_.size(), 0.0);
  touched_slots_.resize(slots_.size());
  slot_touched_.assign(slots_.size(), 0);
  scored_scratch_.resize(slots_.size());
}

int KeyframeDatabase::findSlot(uint64_t keyframe_id) const {
  // Linear: a few hundred slots, and only insert/remove/enumeration need it (not the query).
  for (std::size_t i = 0; i < slots_.size(); ++i)
    if (slots_[i].used && slots_[i].id == keyframe_id) return int(i);
  return -1;
}

Status KeyframeDatabase::insert(uint64_t keyframe_id, const PlaceDescriptors& descriptors) {
  if (descriptors.num_points > std::size_t(options_.max_point_descriptors) ||
      descriptors.num_lines > std::size_t(options_.max_line_descriptors))
    return Status::Error("keyframe database: keyframe " + std::to_string(keyframe_id) + " has " +
                         std::to_string(descriptors.num_points) + " point and " +
                         std::to_string(descriptors.num_lines) + " line descriptors (limits " +
                         std::to_string(options_.max_point_descriptors) + ", " +
                         std::to_string(options_.max_line_descriptors) + ")");
  const std::size_t num_words = histogram(descriptors);
  const uint32_t totals[2] = {uint32_t(descriptors.num_points), uint32_t(descriptors.num_lines)};
  return insertHistogram(keyframe_id, words_scratch_.data(), num_words, totals);
}

Status KeyframeDatabase::insertWords(uint64_t keyframe_id, const WordCount* words, std::size_t num_words) {
  uint64_t totals64[2] = {0, 0};
  for (std::size_t i = 0; i < num_words; ++i) {
    if (words[i].word >= num_words_total_ || words[i].count == 0 ||
        (i > 0 && words[i].word <= words[i - 1].word))
      return Status::Error("keyframe database: keyframe " + std::to_string(keyframe_id) +
                           ": word list not strictly ascending, out of range or with a zero count at entry " +
                           std::to_string(i));
    totals64[std::size_t(wordKind(words[i].word, options_.bits_per_word))] += words[i].count;
  }
  if (totals64[0] > uint64_t(options_.max_point_descriptors) ||
      totals64[1] > uint64_t(options_.max_line_descriptors))
    return Status::Error("keyframe database: keyframe " + std::to_string(keyframe_id) +
                         ": word counts exceed the descriptor limits");
  const uint32_t totals[2] = {uint32_t(totals64[0]), uint32_t(totals64[1])};
  return insertHistogram(keyframe_id, words, num_words, totals);
}

Status KeyframeDatabase::insertHistogram(uint64_t keyframe_id, const WordCount* words, std::size_t num_words,
                                         const uint32_t total_count[2]) {
  // Every check before any change: a refused keyframe leaves the database as it was.
  if (findSlot(keyframe_id) >= 0)
    return Status::Error("keyframe database: keyframe " + std::to_string(keyframe_id) + " is already in it");
  if (free_slots_.empty())
    return Status::Error("keyframe database: full (" + std::to_string(slots_.size()) + " keyframes)");
  if (num_words > free_postings_)
    return Status::Error("keyframe database: out of postings (keyframe " + std::to_string(keyframe_id) +
                         " needs " + std::to_string(num_words) + ", " + std::to_string(free_postings_) +
                         " free of " + std::to_string(postings_.size()) + ")");
  const uint32_t slot_index = free_slots_.back();
  free_slots_.pop_back();
  KeyframeSlot& slot = slots_[slot_index];
  slot.id = keyframe_id;
  slot.used = true;
  slot.first_posting = kNone;
  slot.num_postings = uint32_t(num_words);
  slot.total_count[0] = total_count[0];
  slot.total_count[1] = total_count[1];
  // Append in word order to the keyframe's chain (keyframeWords() then reads it sorted).
  uint32_t* link = &slot.first_posting;
  for (std::size_t i = 0; i < num_words; ++i) {
    uint32_t p = free_posting_head_;
    if (p != kNone) {
      free_posting_head_ = postings_[p].next_in_keyframe;
    } else {
      p = fresh_postings_++;  // free_postings_ >= num_words was checked: one is left
    }
    Posting& posting = postings_[p];
    posting.word = words[i].word;
    posting.count = uint16_t(words[i].count);  // <= the kind's descriptor limit (<= 65535)
    posting.slot = uint16_t(slot_index);
    posting.next_in_word = word_head_[posting.word];
    word_head_[posting.word] = p;
    posting.next_in_keyframe = kNone;
    *link = p;
    link = &posting.next_in_keyframe;
  }
  free_postings_ -= num_words;
  ++num_keyframes_;
  return Status::Ok();
}

Status KeyframeDatabase::remove(uint64_t keyframe_id) {
  const int slot_index = findSlot(keyframe_id);
  if (slot_index < 0)
    return Status::Error("keyframe database: no keyframe " + std::to_string(keyframe_id) + " to remove");
  KeyframeSlot& slot = slots_[std::size_t(slot_index)];
  for (uint32_t p = slot.first_posting; p != kNone;) {
    Posting& posting = postings_[p];
    const uint32_t next = posting.next_in_keyframe;
    // Unlink from the word's list: find the link that points at p (the head or a predecessor).
    uint32_t* link = &word_head_[posting.word];
    while (*link != p) link = &postings_[*link].next_in_word;
    *link = posting.next_in_word;
    posting.next_in_word = kNone;
    posting.next_in_keyframe = free_posting_head_;
    free_posting_head_ = p;
    p = next;
  }
  free_postings_ += slot.num_postings;
  slot = KeyframeSlot{};
  free_slots_.push_back(uint32_t(slot_index));  // capacity reserved at construction
  --num_keyframes_;
  return Status::Ok();
}

std::size_t KeyframeDatabase::keyframeIds(uint64_t* ids, std::size_t max_ids) const {
  std::size_t n = 0;
  for (const KeyframeSlot& slot : slots_)
    if (slot.used && n < max_ids) ids[n++] = slot.id;
  std::sort(ids, ids + n);
  return n;
}

std::size_t KeyframeDatabase::numKeyframeWords(uint64_t keyframe_id) const {
  const int slot_index = findSlot(keyframe_id);
  return slot_index < 0 ? 0 : slots_[std::size_t(slot_index)].num_postings;
}

Status KeyframeDatabase::keyframeWords(uint64_t keyframe_id, WordCount* words, std::size_t max_words,
                                       std::size_t* num_words) const {
  *num_words = 0;
  const int slot_index = findSlot(keyframe_id);
  if (slot_index < 0) return Status::Error("keyframe database: no keyframe " + std::to_string(keyframe_id));
  const KeyframeSlot& slot = slots_[std::size_t(slot_index)];
  if (slot.num_postings > max_words)
    return Status::Error("keyframe database: keyframe " + std::to_string(keyframe_id) + " has " +
                         std::to_string(slot.num_postings) + " words, room for " + std::to_string(max_words));
  for (uint32_t p = slot.first_posting; p != kNone; p = postings_[p].next_in_keyframe)
    words[(*num_words)++] = WordCount{postings_[p].word, postings_[p].count};
  return Status::Ok();
}

std::size_t KeyframeDatabase::memoryBytesFor(const KeyframeDatabaseOptions& o) {
  const std::size_t words = std::size_t(2) << o.bits_per_word;
  const std::size_t keyframes = std::size_t(o.max_keyframes);
  const std::size_t descriptors = std::size_t(o.max_point_descriptors + o.max_line_descriptors);
  return sizeof(KeyframeDatabase) + words * sizeof(uint32_t) +
         std::size_t(o.max_postings) * sizeof(Posting) +
         keyframes * (sizeof(KeyframeSlot) + sizeof(uint32_t) /*free_slots_*/ + 2 * sizeof(double) +
                      sizeof(uint32_t) + sizeof(uint8_t) + sizeof(Scored)) +
         descriptors * (sizeof(uint32_t) + sizeof(WordCount));
}

std::size_t KeyframeDatabase::memoryBytes() const {
  return sizeof(*this) + word_head_.capacity() * sizeof(uint32_t) +
         postings_.capacity() * sizeof(Posting) +
         slots_.capacity() * sizeof(KeyframeSlot) + free_slots_.capacity() * sizeof(uint32_t) +
         word_values_scratch_.capacity() * sizeof(uint32_t) + words_scratch_.capacity() * sizeof(WordCount) +
         (accumulator_[0].capacity() + accumulator_[1].capacity()) * sizeof(double) +
         touched_slots_.capacity() * sizeof(uint32_t) + slot_touched_.capacity() * sizeof(uint8_t) +
         scored_scratch_.capacity() * sizeof(Scored);
}

}  // namespace plumb::loop
