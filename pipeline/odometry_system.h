#pragma once
// OdometrySystem: the whole odometry, single-threaded and deterministic, as separable steps:
//
//   extract (FeatureExtractor) -> Tracker::track (reads its LocalMap snapshot)
//     -> KeyframeRequest -> LocalMapper::insertKeyframe (owns the Map, local BA, culling)
//     -> new LocalMap snapshot -> Tracker::setLocalMap
//   lost -> Relocalizer (stored keyframes) -> Tracker::resetAt; still lost after M frames -> a new
//   map segment starts from the current frame at the last known pose (the trajectory continues).
//
// processImage() runs every step for one frame; processFeatures() starts after extraction (for a
// runtime that extracts on another thread). The components are reachable for such a runtime.
// Output: finished frames (reference-keyframe relative, see OdometryTrajectory) and retired
// keyframes with their covariance, drained by the caller.
#include <cstdint>
#include <memory>

#include "pipeline/camera.h"
#include "pipeline/feature_extractor.h"
#include "pipeline/keyframe_request.h"
#include "pipeline/local_mapper.h"
#include "pipeline/odometry_options.h"
#include "pipeline/odometry_stats.h"
#include "pipeline/odometry_trajectory.h"
#include "pipeline/relocalizer.h"
#include "pipeline/rgbd_image.h"
#include "pipeline/tracker.h"

namespace plumb {

struct FrameOutput {
  uint64_t sequence = 0;
  double timestamp_s = 0;
  TrackingState state = TrackingState::kNotInitialized;
  bool has_pose = false;
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();  // as tracked
  bool keyframe = false;
  bool relocalized = false;
  bool new_map = false;
  TrackResult track;
  InsertResult insert;
  double extract_ms = 0, track_ms = 0, map_ms = 0;
};

struct SystemOptions {
  OdometryOptions odometry;
  // Output delay of the reference-keyframe-relative trajectory (frames); 0 = poses as tracked.
  int output_delay_frames = 60;
};

class OdometrySystem {
 public:
  OdometrySystem(const PinholeCamera& camera, const SystemOptions& options);
  ~OdometrySystem();
  OdometrySystem(const OdometrySystem&) = delete;
  OdometrySystem& operator=(const OdometrySystem&) = delete;

  const FrameOutput& processImage(const RgbdImage& image);
  const FrameOutput& processFeatures(const FrameFeatures& features, uint64_t sequence, double timestamp_s);

  // Frames whose output pose is final, oldest first; fn(const FinishedFrame&).
  template <typename Fn>
  void drainFinishedFrames(Fn fn) { trajectory_.popReady(mapper_->localMap(), fn); }
  // Retired keyframes (final pose + covariance); fn(const RetiredKeyframe&).
  template <typename Fn>
  void drainRetiredKeyframes(Fn fn) {
    for (const auto& kf : mapper_->retired()) fn(kf);
    mapper_->clearRetired();
  }
  // End of the run: every pending frame is finished and every keyframe retired.
  template <typename FrameFn, typename KeyframeFn>
  void finish(FrameFn frame_fn, KeyframeFn keyframe_fn) {
    trajectory_.flushAll(mapper_->localMap(), frame_fn);
    mapper_->retireAll();
    drainRetiredKeyframes(keyframe_fn);
  }

  const OdometryStats& stats() const { return stats_; }
  const MapperStats& mapperStats() const { return mapper_->stats(); }
  MapCounts mapCounts() const { return mapper_->map().counts(); }
  const FeatureExtractor& extractor() const { return *extractor_; }
  Tracker& tracker() { return *tracker_; }
  LocalMapper& mapper() { return *mapper_; }
  Relocalizer& relocalizer() { return *relocalizer_; }

 private:
  bool canStartMap(const FrameFeatures& features) const;
  void startMap(const FrameFeatures& features, uint64_t sequence, double timestamp_s,
                const Eigen::Isometry3d& T_world_cam);
  void insertKeyframe();
  void tryRelocalize(const FrameFeatures& features);
  void recordOutput();

  PinholeCamera camera_;
  SystemOptions options_;
  std::unique_ptr<FeatureExtractor> extractor_;
  std::unique_ptr<Tracker> tracker_;
  std::unique_ptr<LocalMapper> mapper_;
  std::unique_ptr<Relocalizer> relocalizer_;
  std::unique_ptr<FrameFeatures> features_;
  std::unique_ptr<KeyframeRequest> request_;
  OdometryTrajectory trajectory_;
  OdometryStats stats_;
  FrameOutput output_;
  bool map_started_ = false;
  bool lost_ = false;
  int lost_streak_ = 0;
  Eigen::Isometry3d T_world_last_good_ = Eigen::Isometry3d::Identity();
};

}  // namespace plumb
