#pragma once
// RunReport: what a pipeline run measured, and the table `plumb run --profile` and
// `plumb profile` print from it.
#include <cstdint>
#include <string>
#include <vector>

#include "runtime/latency_histogram.h"

namespace plumb::runtime {

struct StageReport {
  std::string name;
  LatencyHistogram latency;  // t_done - t_start of this stage, per processed frame
};

struct RunReport {
  std::string mode;
  std::vector<StageReport> stages;  // [0] = source, then the stages in order
  LatencyHistogram end_to_end;      // t_done(end_to_end_stage) - t_sensor, per completed frame
  int end_to_end_stage = 0;         // index into stages whose completion ends end_to_end
  uint64_t frames_read = 0;         // frames the source put into slots
  uint64_t frames_completed = 0;    // frames every stage processed
  uint64_t frames_dropped = 0;      // real-time mode: frames that found no free slot
  uint64_t frames_late = 0;         // real-time mode: frames skipped because the source was more
                                    // than RunOptions::max_source_lag_ns behind their due time
  int64_t wall_ns = 0;              // first source step to last frame done (run clock)

  double framesPerSecond() const {
    return wall_ns > 0 ? static_cast<double>(frames_completed) * 1e9 / static_cast<double>(wall_ns)
                       : 0.0;
  }
};

// Multi-line table: one row per stage and one end-to-end row (frames, p50, p90, p99, max, mean in
// milliseconds), then frames, dropped frames and frames per second.
std::string formatRunReport(const RunReport& report);

}  // namespace plumb::runtime
