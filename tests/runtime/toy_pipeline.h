#pragma once
// A deterministic toy pipeline for runner tests: a source of numbered frames at a fixed period,
// and stages whose outputs depend on every earlier frame (running state), so any reordering,
// loss or duplication changes the final outputs.
#include <cstdint>
#include <string>
#include <vector>

#include "runtime/clock.h"
#include "runtime/stage.h"

namespace plumb::runtime::testing {

struct ToyFrame {
  uint64_t value = 0;
  uint64_t mixed = 0;
  uint64_t state_after = 0;
};

class ToySource final : public Source<ToyFrame> {
 public:
  // frame_count frames, recorded period_ns apart. fail_at: read() of that frame fails. With a
  // clock, each read() takes read_cost_ns of virtual time.
  ToySource(uint64_t frame_count, int64_t period_ns, int64_t fail_at = -1,
            VirtualClock* clock = nullptr, int64_t read_cost_ns = 0)
      : frame_count_(frame_count), period_ns_(period_ns), fail_at_(fail_at), clock_(clock),
        read_cost_ns_(read_cost_ns) {}

  bool peekNext(int64_t* t_recorded_ns) override {
    if (next_ >= frame_count_) return false;
    *t_recorded_ns = static_cast<int64_t>(next_) * period_ns_;
    return true;
  }
  Status read(ToyFrame& frame, const FrameStamps&) override {
    const uint64_t n = next_++;
    if (clock_ != nullptr) clock_->advanceNs(read_cost_ns_);
    if (static_cast<int64_t>(n) == fail_at_) return Status::Error("frame " + std::to_string(n) + " unreadable");
    frame = ToyFrame{};
    frame.value = n * 0x9E3779B97F4A7C15ull + 1;
    return Status::Ok();
  }
  void skip() override { ++next_; }
  uint64_t consumed() const { return next_; }

 private:
  uint64_t frame_count_;
  int64_t period_ns_;
  int64_t fail_at_;
  VirtualClock* clock_;
  int64_t read_cost_ns_;
  uint64_t next_ = 0;
};

// Stage 1: a pure function of the frame. Optionally "slow" on a virtual clock.
class MixStage final : public Stage<ToyFrame> {
 public:
  explicit MixStage(VirtualClock* clock = nullptr, int64_t cost_ns = 0)
      : clock_(clock), cost_ns_(cost_ns) {}
  const char* name() const override { return "mix"; }
  Status process(ToyFrame& frame, const FrameStamps&) override {
    if (clock_ != nullptr) clock_->advanceNs(cost_ns_);
    uint64_t x = frame.value;
    for (int i = 0; i < 32; ++i) x = (x ^ (x >> 29)) * 0xBF58476D1CE4E5B9ull;
    frame.mixed = x;
    return Status::Ok();
  }

 private:
  VirtualClock* clock_;
  int64_t cost_ns_;
};

// Stage 2: folds every frame into a running state (order-dependent) and records the outputs in a
// preallocated array. fail_at: process() of that frame index fails.
class FoldStage final : public Stage<ToyFrame> {
 public:
  explicit FoldStage(std::size_t capacity, int64_t fail_at = -1, VirtualClock* clock = nullptr,
                     int64_t cost_ns = 0)
      : fail_at_(fail_at), clock_(clock), cost_ns_(cost_ns) {
    outputs_.reserve(capacity);
    frame_indices_.reserve(capacity);
  }
  const char* name() const override { return "fold"; }
  Status process(ToyFrame& frame, const FrameStamps& stamps) override {
    if (clock_ != nullptr) clock_->advanceNs(cost_ns_);
    if (static_cast<int64_t>(stamps.frame_index) == fail_at_) {
      return Status::Error("fold refuses frame " + std::to_string(stamps.frame_index));
    }
    state_ = state_ * 1099511628211ull ^ frame.mixed;
    frame.state_after = state_;
    if (outputs_.size() < outputs_.capacity()) {
      outputs_.push_back(state_);
      frame_indices_.push_back(stamps.frame_index);
    }
    return Status::Ok();
  }
  void finish() override { finished_ = true; }

  const std::vector<uint64_t>& outputs() const { return outputs_; }
  const std::vector<uint64_t>& frameIndices() const { return frame_indices_; }
  bool finished() const { return finished_; }

 private:
  int64_t fail_at_;
  VirtualClock* clock_;
  int64_t cost_ns_;
  uint64_t state_ = 1469598103934665603ull;
  std::vector<uint64_t> outputs_;
  std::vector<uint64_t> frame_indices_;
  bool finished_ = false;
};

}  // namespace plumb::runtime::testing
