#pragma once
// One run of the odometry system over a FrameSource, shared by `plumb run` and `plumb demo`:
// frames in, trajectory (TUM file and/or memory), keyframe covariances, statistics, timings and
// memory checkpoints out. Nothing here changes what the system computes: same frames, same bytes.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "drivers/common/frame_source.h"
#include "drivers/synth/synthetic_scene.h"
#include "drivers/trajectory/evaluate.h"
#include "drivers/trajectory/trajectory_io.h"
#include "pipeline/odometry/odometry_system.h"
#include "platform/status.h"
#include "tools/staged_run.h"

namespace plumb::tools {

struct SessionOptions {
  SystemOptions system;
  std::string trajectory_path;  // TUM file, one line per frame ('' = none)
  std::string covariance_path;  // one line per keyframe ('' = none)
  long max_frames = -1;         // < 0: until the source ends
  bool keep_trajectory = true;  // keep poses in memory (for ATE); off for very long runs
  long rss_every = 0;           // > 0: sample the peak RSS every this many frames
  bool progress = false;        // a line per 100 frames on stderr
  bool trace = false;           // a line per frame on stderr (matches, inliers, keyframes, pose)
  // false: the single-threaded processImage() loop. true: capture -> extract -> odometry as runtime
  // stages (tools/staged_run.h) in staged.mode; the per-frame bookkeeping is the same either way.
  bool use_stages = false;
  StagedRunOptions staged;      // max_frames is taken from max_frames above
  // Count process-wide heap allocations from frame staged.warmup_frames (default 30) to the last.
  bool count_allocations = false;
};

// Per-frame cost in a fixed histogram (0.05 ms bins up to 500 ms), so long runs need no memory.
class MsHistogram {
 public:
  void add(double ms);
  double mean() const { return count_ ? sum_ / double(count_) : 0.0; }
  double percentile(double p) const;
  double max() const { return max_; }
  uint64_t count() const { return count_; }

 private:
  static constexpr int kBins = 10000;
  static constexpr double kBinMs = 0.05;
  std::vector<uint32_t> bins_ = std::vector<uint32_t>(kBins + 1, 0);
  uint64_t count_ = 0;
  double sum_ = 0, max_ = 0;
};

struct RssCheckpoint {
  long frame = 0;
  long peak_rss_kib = 0;
  long current_rss_kib = 0;
};

struct SessionResult {
  std::vector<StampedPose> trajectory;  // when keep_trajectory
  long frames = 0;
  long frames_dropped = 0;  // realtime mode: written as `# <timestamp> dropped`, not in `frames`
  MsHistogram total_ms, extract_ms, track_ms, map_ms;
  OdometryStats stats;
  MapperStats mapper;
  MapCounts final_counts;
  std::vector<RssCheckpoint> rss;
  std::string source;
  // count_allocations: operator new calls between the end of the warm-up frame and the end of the
  // last frame, over that many frames (0 when the run was not longer than the warm-up). Staged
  // runs end the window at the last frame finished before the input ended, because the stage
  // threads' exit allocates (OpenCV's thread-local cleanup): shutdown, not per-frame cost.
  uint64_t allocation_frames = 0;
  uint64_t allocations_after_warmup = 0;
  StagedRunResult staged;  // use_stages: latency report, extraction failures
};

Status runSession(FrameSource& source, const SessionOptions& options, SessionResult* result);

// Peak and current resident set size of this process (KiB), from /proc/self/status.
bool readRss(long* peak_kib, long* current_kib);

// The statistics as one JSON object (ate_rmse_m < 0: not evaluated).
std::string sessionJson(const SessionResult& result, const SessionOptions& options, double ate_rmse_m);


// Kinect-like sensor noise for synthetic runs: axial depth noise sigma = 0.0014 z^2, holes on the
// far side of depth edges, and 1 grey level of pixel noise.
void enableKinectNoise(SynthOptions* options);

// `spec` = synth:PRESET[:SEED[:FRAMES]] rendered with Kinect-like noise.
Status openNoisySynthetic(const std::string& spec, std::unique_ptr<SyntheticSource>* out);

// Exact ground truth of the frames a synthetic source rendered (first `frames` frames).
std::vector<StampedPose> syntheticGroundTruth(const SyntheticScene& scene, long frames);

// ATE RMSE of a trajectory, or a Status explaining why not.
Status ateRmse(const std::vector<StampedPose>& ground_truth, const std::vector<StampedPose>& estimate,
               double* rmse_m);

// Applies the line options shared by `run` and `demo`.
void setLineOptions(int line_samples, bool use_lines, SystemOptions* options);

}  // namespace plumb::tools
