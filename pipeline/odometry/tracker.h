#pragma once
// Tracker: the pose of each frame from the local map (ORB-SLAM2's Tracking, without the map).
//
//   0. rolling-shutter cameras (PinholeCamera::rolling_shutter_readout_s > 0): every feature is
//      moved to the time of the frame's middle row with the constant-velocity motion
//      (pipeline/odometry/tracker_rolling_shutter.h); the tracker, the map and local BA then see a
//      global-shutter frame;
//   1. predict with constant velocity; match the last frame's features by projection (points with
//      depth or a landmark, lines with their 3D samples); too few matches -> retry with a wide
//      window, then with zero motion (fast rotations break the velocity guess);
//   2. pose-only optimisation: points as [u, v, u_r] (or [u, v]) with the noise-model
//      information, line-guidance samples as l^T pi(T P), Pseudo-Huber (solver/pose_optimizer.h);
//   3. track the local map: project the snapshot's landmarks that are not matched yet, match,
//      optimise again; state ok / weak / lost from the inlier count (TrackerOptions);
//   4. decide whether the frame becomes a keyframe and, if so, fill a KeyframeRequest.
//
// The tracker reads only its own copy of a LocalMap snapshot (setLocalMap) and writes only its
// own state and the request: it can run on its own thread with messages in and out.
// All buffers are allocated in the constructor; track() does not allocate.
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Geometry>

#include "sensor/camera.h"
#include "pipeline/frontend/frame_features.h"
#include "pipeline/odometry/keyframe_request.h"
#include "pipeline/odometry/local_map.h"
#include "pipeline/odometry/matcher.h"
#include "pipeline/odometry/odometry_options.h"
#include "pipeline/odometry/tracking_state.h"
#include "solver/camera_intrinsics.h"
#include "solver/pose_optimizer.h"
#include "solver/zero_page_allocator.h"

namespace plumb {

class Tracker {
 public:
  Tracker(const PinholeCamera& camera, const OdometryOptions& options);
  ~Tracker();
  Tracker(const Tracker&) = delete;
  Tracker& operator=(const Tracker&) = delete;

  // Swaps in a new snapshot (copied; visibility counters restart). Like ORB-SLAM2's
  // UpdateLastFrame, the last frame follows what local BA did meanwhile: its pose moves with its
  // reference keyframe (or becomes the keyframe's refined pose when it was made one), its depth
  // points move with it, and its landmark associations take the landmarks' refined positions.
  void setLocalMap(const LocalMap& local_map);
  // The map this tracker asked for (KeyframeRequest::start_new_map) at its last frame, built by
  // the mapping side: installed like setLocalMap, and the last frame, which is that map's first
  // keyframe, takes it as its reference (as resetAt would have, had the map been there already).
  void adoptNewMap(const LocalMap& local_map);
  const LocalMap& localMap() const { return *local_map_; }

  // Tracks one frame. When the result asks for a keyframe, `request` has been filled.
  TrackResult track(const FrameFeatures& frame, uint64_t sequence, double timestamp_s,
                    KeyframeRequest* request);

  // (Re)starts from a frame whose pose is known (new map, relocalization): it becomes the last
  // frame, velocity is reset, state becomes ok.
  void resetAt(const FrameFeatures& frame, const Eigen::Isometry3d& T_world_cam);
  // Fills a request that starts a new map from `frame` at T_world_cam.
  void fillNewMapRequest(const FrameFeatures& frame, uint64_t sequence, double timestamp_s,
                         const Eigen::Isometry3d& T_world_cam, KeyframeRequest* request) const;
  // Forget everything (no map): the next frame must start a map.
  void reset();

  TrackingState state() const { return state_; }
  const Eigen::Isometry3d& lastPose() const { return T_world_last_; }
  bool hasPose() const { return has_last_frame_; }

 private:
  // A 3D point a current-frame feature was matched to: a landmark of the snapshot, or a point of
  // the last frame back-projected with its depth (ORB-SLAM2's temporary "visual odometry" points).
  struct PointAssociation {
    bool valid = false;
    Eigen::Vector3d P_world = Eigen::Vector3d::Zero();
    LandmarkRef landmark;  // id 0: a last-frame depth point
    int local_index = -1;  // into the snapshot's points, -1 when unknown
  };
  struct LineAssociation {
    bool valid = false;
    uint8_t num_samples = 0;
    std::array<Eigen::Vector3d, kMaxLineSamples> samples_world{};
    LandmarkRef landmark;
    int local_index = -1;
  };

  // tracker_matching.cpp
  int matchLastFrame(const FrameFeatures& frame, const Eigen::Isometry3d& T_cam_world_pred,
                     ProjectionMatcher& matcher);
  int matchLocalMap(const FrameFeatures& frame, const Eigen::Isometry3d& T_cam_world);
  void clearAssociations(const FrameFeatures& frame);
  // tracker_pose.cpp: optimise from T_cam_world, drop outlier associations, count inliers.
  // final_pose = false (the first optimisation, on the last frame's matches): no covariance (one
  // linearisation fewer). (A looser step tolerance there, 1e-4, moved head250's ATE by +14 %.)
  PoseResult optimizeAndPrune(const FrameFeatures& frame, const Eigen::Isometry3d& T_cam_world,
                              TrackResult* result, bool final_pose = true);
  // 1 / (keyframes that measured the landmark at local_index of the snapshot; 1 when unknown).
  double mapShare(int local_index, bool point) const;
  // The tracked pose's published covariances (TrackResult) from the final optimisation.
  // twist_per_s: the frame's velocity (timing model error, UncertaintyOptions).
  void publishCovariance(const PoseResult& pose, const Vector6d& twist_per_s, TrackResult* result) const;
  // tracker.cpp
  void rememberLastFrame(const FrameFeatures& frame, const Eigen::Isometry3d& T_world_cam);
  // tracker_last_frame.cpp: the setLocalMap update of the last frame described above.
  void followMapCorrections();
  // A loop correction moved the whole map by `correction`: every 3D point the last frame holds
  // (landmarks outside the new snapshot too) moves with it.
  void followLoopCorrection(const Eigen::Isometry3d& correction);
  void fillKeyframeRequest(const FrameFeatures& frame, uint64_t sequence, double timestamp_s,
                           const Eigen::Isometry3d& T_world_cam, KeyframeRequest* request);
  bool keyframeNeeded(const FrameFeatures& frame, const TrackResult& result) const;

  PinholeCamera camera_;
  CameraIntrinsics intrinsics_;
  OdometryOptions options_;
  PoseOptimizerOptions pose_options_;
  // The noise model's information of a 2D point and of a line sample per pyramid octave, made
  // once (solver/noise_model.h computes a power per call); other octaves call it directly.
  std::array<Eigen::Matrix2d, kPyramidLevels> mono_point_information_;
  std::array<double, kPyramidLevels> line_sample_information_{};
  Eigen::Matrix2d monoInformation(int octave) const;
  double lineInformation(int octave) const;
  ProjectionMatcher matcher_;        // constant-velocity window
  ProjectionMatcher wide_matcher_;   // retries
  ProjectionMatcher local_matcher_;  // local-map window

  TrackingState state_ = TrackingState::kNotInitialized;
  bool has_last_frame_ = false;
  Eigen::Isometry3d T_world_last_ = Eigen::Isometry3d::Identity();
  // The last frame's sequence and its reference keyframe as the snapshot it was tracked with gave
  // it: the next snapshot's pose of that keyframe tells how far local BA moved the frame.
  static constexpr uint64_t kUnknownSequence = ~uint64_t(0);
  uint64_t last_sequence_ = kUnknownSequence;
  uint32_t last_reference_id_ = 0;
  Eigen::Isometry3d T_world_last_reference_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d velocity_cur_last_ = Eigen::Isometry3d::Identity();  // T_cam(k) <- T_cam(k-1)
  bool has_velocity_ = false;
  // Rolling shutter: the velocity's time span (NaN when unknown) and the last frame's timestamp.
  double velocity_dt_s_ = 0;
  double last_timestamp_s_ = 0;
  int frames_since_keyframe_ = 0;
  uint64_t frame_stamp_ = 0;  // increments per track(): marks landmark slots matched this frame

  // Everything big lives in one block allocated at construction.
  // The input moved to its middle row's time (rolling-shutter cameras only): assigned whole before
  // it is read, so it lives in zero pages and costs no resident memory on a global-shutter camera.
  std::vector<FrameFeatures, ZeroPageAllocator<FrameFeatures>> compensated_frame_;
  struct Buffers {
    LocalMap local_map;
    FrameFeatures last_frame;
    std::array<PointAssociation, kMaxKeypoints> last_points;  // per last-frame keypoint
    std::array<LineAssociation, kMaxLines> last_lines;
    std::array<PointAssociation, kMaxKeypoints> points;       // per current keypoint
    std::array<LineAssociation, kMaxLines> lines;
    std::array<uint64_t, kMaxMapPoints> point_slot_stamp{};   // == frame_stamp_: already matched
    std::array<uint16_t, kMaxMapPoints> point_slot_keypoint{};
    std::array<uint64_t, kMaxMapLines> line_slot_stamp{};
    std::array<uint16_t, kMaxMapLines> line_slot_line{};
    std::array<uint16_t, kMaxLocalMapPoints> point_visible{};  // since the last snapshot
    std::array<uint16_t, kMaxLocalMapPoints> point_found{};
    std::array<uint16_t, kMaxLocalMapLines> line_visible{};
    std::array<uint16_t, kMaxLocalMapLines> line_found{};
    // Pose problem (observation -> feature index).
    FixedVector<PosePointObservation, kMaxKeypoints> pose_points;
    FixedVector<uint16_t, kMaxKeypoints> pose_point_keypoint;
    FixedVector<PoseLineObservation, kMaxLines * kMaxLineSamples> pose_lines;
    FixedVector<uint16_t, kMaxLines * kMaxLineSamples> pose_line_index;
    std::array<bool, kMaxKeypoints> point_inlier{};
    std::array<bool, kMaxLines * kMaxLineSamples> line_inlier{};
    // Matching scratch.
    FixedVector<PointCandidate, kMaxLocalMapPoints> point_candidates;
    FixedVector<uint16_t, kMaxLocalMapPoints> point_candidate_local;
    FixedVector<LineCandidate, kMaxLocalMapLines> line_candidates;
    FixedVector<uint16_t, kMaxLocalMapLines> line_candidate_local;
    PointMatches point_matches;
    LineMatches line_matches;
  };
  std::unique_ptr<Buffers> b_;
  LocalMap* local_map_ = nullptr;
};

}  // namespace plumb
