#pragma once
// TraceLog: what the runner records for the Chrome trace, in buffers reserved before the run.
// One TraceTrack per stage (track 0 = source), each written by exactly one thread, so recording
// needs no synchronisation; the log is read only after the threads have joined.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace plumb::runtime {

struct TraceRecord {
  enum class Kind : uint8_t { kSpan, kDrop, kLate };  // kDrop: no free slot; kLate: source behind
  Kind kind = Kind::kSpan;
  uint64_t frame_index = 0;
  int64_t t_sensor_ns = 0;  // lets the last stage's records double as end-to-end spans
  int64_t t_start_ns = 0;
  int64_t t_end_ns = 0;  // == t_start_ns for a drop or late frame
};

class TraceTrack {
 public:
  TraceTrack(std::string name, std::size_t capacity) : name_(std::move(name)) {
    records_.reserve(capacity);
  }
  // Never allocates: a full track counts what it could not keep.
  void add(const TraceRecord& record) {
    if (records_.size() < records_.capacity()) {
      records_.push_back(record);
    } else {
      ++overflow_;
    }
  }
  const std::string& name() const { return name_; }
  const std::vector<TraceRecord>& records() const { return records_; }
  uint64_t overflow() const { return overflow_; }

 private:
  std::string name_;
  std::vector<TraceRecord> records_;
  uint64_t overflow_ = 0;
};

}  // namespace plumb::runtime
