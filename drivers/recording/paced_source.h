#pragma once
// PacedSource: replays a recording or dataset at its recorded rate, as a live sensor would
// deliver it (or faster/slower by `speed`, or as fast as possible with speed 0). Frame i is due
// at due(i-1) + (timestamp_i - timestamp_{i-1}) / speed on the clock; next() sleeps until then.
// Due times are absolute, so sleep overshoot does not accumulate into drift. When the consumer
// is late, the frame is delivered at once and the schedule restarts from now (no burst of
// catch-up frames), the way a sensor's frames arrive after a slow consumer.
// t_sensor_ns is set to the delivery time, so latencies downstream look like a live sensor's.
#include <cstdint>
#include <memory>

#include "drivers/common/frame_source.h"
#include "drivers/fault/source_clock.h"

namespace plumb {

struct PacedSourceOptions {
  double speed = 1.0;       // 1 = recorded rate, 2 = twice as fast; <= 0: as fast as possible
  double max_gap_s = 1.0;   // longer timestamp jumps (a pause, skipped chunks) wait only this long
  int64_t late_tolerance_ns = 2'000'000;  // later than this counts as a late frame
};

struct PacingStats {
  uint64_t frames = 0;
  int64_t slept_ns = 0;
  uint64_t late_frames = 0;
  int64_t max_lateness_ns = 0;
  uint64_t clamped_gaps = 0;  // timestamp jumps longer than max_gap_s or backwards
};

class PacedSource : public FrameSource {
 public:
  PacedSource(std::unique_ptr<FrameSource> inner, const PacedSourceOptions& options,
              SourceClock& clock = steadyClock());

  SourceResult next(RgbdImage& out) override;
  const PinholeCamera& camera() const override { return inner_->camera(); }
  std::string describe() const override { return "paced(" + inner_->describe() + ")"; }
  const Status& lastError() const override { return inner_->lastError(); }
  Status reopen() override { return inner_->reopen(); }
  bool isLive() const override { return inner_->isLive(); }

  const PacingStats& stats() const { return stats_; }

 private:
  std::unique_ptr<FrameSource> inner_;
  PacedSourceOptions options_;
  SourceClock& clock_;
  PacingStats stats_;
  bool started_ = false;
  double previous_timestamp_s_ = 0;
  int64_t previous_due_ns_ = 0;
};

}  // namespace plumb
