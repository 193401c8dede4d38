#include "drivers/recording/paced_source.h"

#include <algorithm>

namespace plumb {

PacedSource::PacedSource(std::unique_ptr<FrameSource> inner, const PacedSourceOptions& options,
                         SourceClock& clock)
    : inner_(std::move(inner)), options_(options), clock_(clock) {}

SourceResult PacedSource::next(RgbdImage& out) {
  const SourceResult r = inner_->next(out);
  if (r != SourceResult::kFrame) return r;
  ++stats_.frames;
  if (options_.speed > 0) {
    int64_t due_ns = clock_.nowNs();
    if (started_) {
      double dt_s = out.timestamp_s - previous_timestamp_s_;
      if (dt_s < 0 || dt_s > options_.max_gap_s) {
        ++stats_.clamped_gaps;
        dt_s = std::clamp(dt_s, 0.0, options_.max_gap_s);
      }
      due_ns = previous_due_ns_ + static_cast<int64_t>(dt_s / options_.speed * 1e9);
    }
    const int64_t now_ns = clock_.nowNs();
    if (due_ns > now_ns) {
      clock_.sleepForNs(due_ns - now_ns);
      stats_.slept_ns += due_ns - now_ns;
    } else {
      const int64_t lateness_ns = now_ns - due_ns;
      if (lateness_ns > options_.late_tolerance_ns) {
        ++stats_.late_frames;
        stats_.max_lateness_ns = std::max(stats_.max_lateness_ns, lateness_ns);
        due_ns = now_ns;  // restart the schedule: no catch-up burst
      }
    }
    started_ = true;
    previous_timestamp_s_ = out.timestamp_s;
    previous_due_ns_ = due_ns;
  }
  out.t_sensor_ns = clock_.nowNs();
  return r;
}

}  // namespace plumb
