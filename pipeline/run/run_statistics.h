#pragma once
// RunStatistics: what `plumb run --stats` reports about a run, gathered from the runner's sink
// calls (pipeline/run/odometry_run.h) in fixed memory: per-stage milliseconds in fixed histograms
// (runtime/latency_histogram.h), optional RSS checkpoints, and at the end the system's counters
// and the options the run actually used. Formats JSON as a string; writing files is the caller's.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/odometry/odometry_system.h"
#include "pipeline/run/odometry_run.h"
#include "runtime/latency_histogram.h"

namespace plumb {

struct RssCheckpoint {
  uint64_t frame = 0;
  long peak_rss_kib = 0;
  long current_rss_kib = 0;
};

class RunStatistics {
 public:
  // rss_every > 0: a resident-memory checkpoint every that many frames (reserved up to
  // max_checkpoints, later ones are not kept).
  explicit RunStatistics(long rss_every = 0, std::size_t max_checkpoints = 4096);

  // A tracked or dropped frame (the sink's onFrame).
  void add(const FrameOutput& frame);

  uint64_t frames() const { return frames_; }
  uint64_t framesDropped() const { return frames_dropped_; }
  const runtime::LatencyHistogram& totalNs() const { return total_; }
  const runtime::LatencyHistogram& extractNs() const { return extract_; }
  const runtime::LatencyHistogram& trackNs() const { return track_; }
  const runtime::LatencyHistogram& mapNs() const { return map_; }
  // Depth registration (unregistered depth cameras): frames it ran on, and its milliseconds.
  uint64_t framesRegistered() const { return frames_registered_; }
  const runtime::LatencyHistogram& registerNs() const { return register_; }
  const std::vector<RssCheckpoint>& rss() const { return rss_; }

 private:
  long rss_every_;
  std::size_t max_checkpoints_;
  uint64_t frames_ = 0, frames_dropped_ = 0, frames_registered_ = 0;
  runtime::LatencyHistogram total_, extract_, track_, map_, register_;
  std::vector<RssCheckpoint> rss_;
};

// Everything --stats reports, as one JSON object. ate_rmse_m < 0: not evaluated (null).
struct RunSummary {
  std::string source;
  const RunStatistics* statistics = nullptr;
  const OdometryRunResult* run = nullptr;
  OdometryStats odometry;
  MapperStats mapper;
  SystemOptions system_options;
  OdometryRunOptions run_options;
  // The command line's options root (`plumb run`: every flag, given or default) as name -> JSON
  // value text, written as "command_options" when not empty.
  std::vector<std::pair<std::string, std::string>> command_options;
  double ate_rmse_m = -1;
  int stop_signal = 0;  // the signal that stopped the run early (0: it was not stopped by one)
  uint64_t damaged_regions = 0;  // input regions the source skipped as damaged
  std::string damage;            // the last damage it reported
  // Map files (--load-map / --save-map): a "map_file" object only when one was used, so the
  // statistics of other runs are unchanged. Milliseconds: reading + checking + decoding the file,
  // and filling the loop closer and relocalizer.
  bool map_loaded = false;
  double map_read_ms = 0;
  uint64_t map_keyframes = 0, map_loop_edges = 0;
  std::string map_saved_path;
  uint64_t map_saved_keyframes = 0, map_saved_bytes = 0;
  // Supervised live sources: their outages as one JSON object, written as "source_supervision"
  // when not empty (replays have none, so their statistics are unchanged).
  std::string source_supervision_json;
};
std::string runSummaryJson(const RunSummary& summary);

}  // namespace plumb
