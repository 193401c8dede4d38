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
// runtime that extracts on another thread). processFeatures() is trackFeatures() then mapFrame(),
// and a staged runtime calls those two on separate threads (tracking and mapping stages):
//
//   trackFeatures (tracking thread): installs the newest LocalMap snapshot the mapping side
//     published (runtime::LatestSnapshot, newer versions only), tracks, and fills a TrackedFrame
//     (pose, reference keyframe, keyframe request) that travels with the frame to
//   mapFrame (mapping thread, frame order): LocalMapper::insertKeyframe + local BA for a request,
//     publishes the new snapshot, updates the relocalizer, statistics and the output trajectory.
//
// Rare events need the mapper and relocalizer synchronously: starting a map (segment) and
// relocalizing. Before them trackFeatures() calls MapperFence::waitForMapper(), which returns once
// every earlier frame has been through mapFrame() (the mapping thread is then idle until this frame
// reaches it), so the two threads never touch the mapper or relocalizer at the same time. In
// lock-step (and in processFeatures) the fence never waits and every frame sees exactly the
// single-threaded map; threaded runs track against the newest snapshot published so far, and while
// a keyframe request is still with the mapper the tracker makes no keyframe decision (ORB-SLAM's
// "local mapping busy"): it would judge against a map that lacks the pending keyframe and ask for
// near-duplicates. In lock-step a request is always done before the next frame, so this never
// applies there.
// Output: finished frames (reference-keyframe relative, see OdometryTrajectory) and retired
// keyframes with their covariance, drained by the caller on the mapping side.
#include <atomic>
#include <cstdint>
#include <memory>

#include "sensor/camera.h"
#include "pipeline/frontend/feature_extractor.h"
#include "pipeline/odometry/keyframe_request.h"
#include "pipeline/odometry/local_mapper.h"
#include "pipeline/odometry/odometry_options.h"
#include "pipeline/odometry/odometry_stats.h"
#include "pipeline/odometry/odometry_trajectory.h"
#include "pipeline/odometry/relocalizer.h"
#include "sensor/rgbd_image.h"
#include "pipeline/odometry/tracker.h"
#include "runtime/latest_snapshot.h"

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
  bool dropped = false;  // mapDroppedFrame(): the runtime dropped this frame, nothing else is set
  TrackResult track;
  InsertResult insert;
  double extract_ms = 0, track_ms = 0, map_ms = 0;
};

// What tracking hands to mapping for one frame. Large (the request holds a copy of the features),
// so a staged runtime allocates one per frame slot, once.
struct TrackedFrame {
  FrameOutput output;            // tracking's part: state, pose, flags, track result, track_ms
  uint32_t reference_id = 0;     // keyframe the output trajectory expresses the pose against
  Eigen::Isometry3d T_ref_cam = Eigen::Isometry3d::Identity();
  bool map_keyframe = false;     // `request` is to be inserted by mapFrame()
  bool relocalization_attempted = false;
  KeyframeRequest request;
};

// How the tracking side waits for the mapping side in a threaded run (see the header comment).
class MapperFence {
 public:
  virtual ~MapperFence() = default;
  // Returns once every frame tracked before the current one has been through mapFrame().
  virtual void waitForMapper() = 0;
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

  // The two halves of processFeatures() (header comment). fence may be nullptr (never waits).
  void trackFeatures(const FrameFeatures& features, uint64_t sequence, double timestamp_s, MapperFence* fence,
                     TrackedFrame* out);
  const FrameOutput& mapFrame(const TrackedFrame& tracked);
  // Mapping side: a frame the runtime dropped (real-time replay, no free slot) takes its place in
  // the output trajectory (FinishedFrame::dropped); call in frame order between mapFrame() calls.
  const FrameOutput& mapDroppedFrame(uint64_t sequence, double timestamp_s);

  // Mapping side (mapFrame's thread) from here on.
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
  // Tracking side.
  void installNewestSnapshot();
  bool canStartMap(const FrameFeatures& features) const;
  void startMap(const FrameFeatures& features, uint64_t sequence, double timestamp_s,
                const Eigen::Isometry3d& T_world_cam, MapperFence* fence, TrackedFrame* out);
  void tryRelocalize(const FrameFeatures& features, MapperFence* fence, TrackedFrame* out);
  // Mapping side.
  void insertKeyframe(const KeyframeRequest& request);
  void recordOutput(const TrackedFrame& tracked);

  PinholeCamera camera_;
  SystemOptions options_;
  std::unique_ptr<FeatureExtractor> extractor_;
  std::unique_ptr<Tracker> tracker_;
  std::unique_ptr<LocalMapper> mapper_;
  std::unique_ptr<Relocalizer> relocalizer_;
  std::unique_ptr<FrameFeatures> features_;
  std::unique_ptr<TrackedFrame> tracked_;  // processFeatures()'s hand-over
  // Mapping -> tracking: LocalMap snapshots after each inserted keyframe (triple buffer).
  std::unique_ptr<runtime::LatestSnapshot<LocalMap>> snapshots_;
  // Tracking side state.
  bool map_started_ = false;
  bool lost_ = false;
  int lost_streak_ = 0;
  Eigen::Isometry3d T_world_last_good_ = Eigen::Isometry3d::Identity();
  uint64_t keyframe_requests_ = 0;  // handed to mapFrame()
  // Mapping side state.
  std::atomic<uint64_t> keyframe_requests_done_{0};  // after the snapshot is published (release)
  OdometryTrajectory trajectory_;
  OdometryStats stats_;
  FrameOutput output_;
};

}  // namespace plumb
