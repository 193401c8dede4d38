#pragma once
// LocalMapper: owns the Map. For each KeyframeRequest it
//   1. inserts the keyframe (retiring the oldest one when the map is full) and its observations of
//      the landmarks the tracker matched; applies the tracker's visibility counts;
//   2. creates map points from the keyframe's depth for unmatched keypoints (closest first) and
//      map lines (line guidance samples) for unmatched lines with a 3D fit;
//   3. runs local BA on a bounded window (the keyframe and its best covisible neighbours optimised,
//      keyframes outside the window that see the same landmarks fixed), writes poses, landmarks
//      and pose covariances back, drops the observations BA classes as outliers;
//   4. culls landmarks (found/visible ratio, too few observers, line samples failing BA);
//   5. publishes a new LocalMap snapshot for the tracker.
// Keyframes leaving the map are reported (final pose and covariance) through retired().
#include <array>
#include <cstdint>
#include <memory>

#include "sensor/camera.h"
#include "pipeline/odometry/keyframe_request.h"
#include "pipeline/odometry/local_map.h"
#include "pipeline/odometry/map.h"
#include "pipeline/odometry/map_correction.h"
#include "pipeline/odometry/odometry_options.h"
#include "solver/camera_intrinsics.h"
#include "solver/local_ba.h"

namespace plumb {

// A keyframe that left the map: its final state (written to the covariance output).
struct RetiredKeyframe {
  uint32_t id = 0;
  uint64_t frame_sequence = 0;
  double timestamp_s = 0;
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  bool covariance_valid = false;
  KeyframeUncertainty uncertainty;
};

struct MapperStats {
  uint64_t keyframes_inserted = 0;
  uint64_t segments = 0;
  uint64_t points_created = 0;
  uint64_t lines_created = 0;
  uint64_t points_culled = 0;
  uint64_t lines_culled = 0;
  uint64_t ba_runs = 0;
  // Observations solve() flagged above their chi-square threshold (summed over BA runs), and the
  // map observations the mapper removed for them (a line observation counts once, removed when
  // most of its samples were flagged).
  uint64_t ba_outlier_flags = 0;
  uint64_t ba_outlier_observations = 0;
  // BA covariances not published: windows whose reduced system was (numerically) singular, and
  // keyframe covariances not finite, not positive definite or beyond
  // UncertaintyOptions::max_published_*. The keyframes keep the last BA's.
  uint64_t ba_covariances_refused = 0;
  uint64_t stale_associations = 0;  // request named a landmark that is gone meanwhile
  MapCounts peak;                   // largest counts seen (capacity check)
};

struct InsertResult {
  bool inserted = false;
  uint32_t keyframe_id = 0;
  int new_points = 0;
  int new_lines = 0;
  int ba_outliers = 0;
  double ba_initial_cost = 0;
  double ba_final_cost = 0;
};

class LocalMapper {
 public:
  LocalMapper(const PinholeCamera& camera, const OdometryOptions& options);
  ~LocalMapper();
  LocalMapper(const LocalMapper&) = delete;
  LocalMapper& operator=(const LocalMapper&) = delete;

  // Steps 1-5 above in one call: one snapshot, after local BA.
  InsertResult insertKeyframe(const KeyframeRequest& request);
  // The same work in two halves (split map updates, docs/RUNTIME.md "Map updates at a fixed lag"):
  // addKeyframe() does steps 1-2 (the keyframe at its tracked pose, its new landmarks at their
  // measured positions) and step 4 (culling), and writes that "fresh" snapshot into *fresh (a new
  // version; localMap() is not changed yet); refineKeyframe() does steps 3-5 for the keyframe
  // addKeyframe() just inserted (local BA, culling again) and publishes the refined snapshot as
  // localMap(). It returns whether it refined anything: false after a failed insertion (nothing
  // published) and after a new map (no BA there: localMap() is published, with the fresh
  // snapshot's content).
  InsertResult addKeyframe(const KeyframeRequest& request, LocalMap* fresh);
  bool refineKeyframe(InsertResult* result);
  // Loop closing's correction (pipeline/odometry/map_correction.h): ONE rigid motion
  // C = correction.T_world_cam * T_world_keyframe^-1 moves every keyframe and landmark of the map,
  // then a new snapshot is published (the tracker follows through its reference keyframe).
  // Covariances are unchanged (they live in each camera's frame). A keyframe request built against
  // an older snapshot arrives in the old frame: insertKeyframe() moves its pose by the newest C
  // (one correction in flight is assumed; corrections are seconds apart). false (nothing changed)
  // when the keyframe is no longer in the map.
  bool applyCorrection(const MapCorrection& correction);
  // The snapshot published after the last insertion (version 0 before any).
  const LocalMap& localMap() const { return *local_map_; }
  const Map& map() const { return map_; }
  // Keyframe ids from here on start at `id` or later (Map::setNextKeyframeId).
  void setNextKeyframeId(uint32_t id) { map_.setNextKeyframeId(id); }
  const MapperStats& stats() const { return stats_; }
  uint32_t segment() const { return segment_; }

  // Keyframes retired since the last clearRetired(), in retirement order.
  const FixedVector<RetiredKeyframe, kMaxMapKeyframes>& retired() const { return retired_; }
  // The rigid motion the last applied loop correction moved the map by (applyCorrection's C).
  const Eigen::Isometry3d& lastCorrection() const { return last_correction_; }
  void clearRetired() { retired_.clear(); }
  // Retires every keyframe still in the map (end of a run), oldest first.
  void retireAll();

 private:
  // Steps 1-2 of insertKeyframe (no snapshot); remembers the keyframe for the refinement.
  InsertResult addUnrefined(const KeyframeRequest& request);
  void recordPeakCounts();
  void retireKeyframe(int kf_slot);
  void applyVisibility(const KeyframeRequest& request);
  void addTrackedObservations(int kf_slot, const KeyframeRequest& request);
  int createPoints(int kf_slot, const KeyframeRequest& request);
  int createLines(int kf_slot, const KeyframeRequest& request);
  void freePointSlots(std::size_t needed);
  void freeLineSlots(std::size_t needed);
  void cullLandmarks(uint32_t current_keyframe_id);
  // local_mapper_ba.cpp
  void runLocalBa(int kf_slot, InsertResult* result);
  void selectWindow(int kf_slot);
  void excludeSingleViewLandmarks();
  void moveSingleViewLandmarks();
  // Each BA line sample's depth in its first keyframe, when that keyframe is in the BA
  // (LocalMapperOptions::anchor_line_sample_depth). After every other observation.
  void addLineSampleAnchors();
  // local_mapper_covariance.cpp: after a BA's covariance, every window keyframe's relative pose
  // and covariance to its previous keyframe (when that BA held both); the new keyframe's world
  // covariance chained from its previous keyframe's.
  void writeUncertainty(int kf_slot, bool have_covariance, double variance_factor);
  int previousKeyframeSlot(uint32_t id) const;
  // True when a keyframe covariance from this BA may be published (solver/pose_covariance.h
  // publishablePoseCovariance, UncertaintyOptions::max_published_*); counts a refusal.
  bool publishable(const Matrix6d& covariance);
  // local_mapper_snapshot.cpp: publishSnapshot builds localMap(), buildSnapshot any LocalMap.
  void publishSnapshot(int kf_slot) { buildSnapshot(kf_slot, local_map_.get()); }
  void buildSnapshot(int kf_slot, LocalMap* out);
  void rankCovisible(int kf_slot, int count, FixedVector<int, kMaxMapKeyframes>* out) const;

  PinholeCamera camera_;
  CameraIntrinsics intrinsics_;
  OdometryOptions options_;
  LocalBaOptions ba_options_;
  Map map_;
  LocalBundleAdjuster ba_;
  uint32_t segment_ = 0;
  uint64_t snapshot_version_ = 0;
  // The keyframe addUnrefined() inserted and no refinement has run for yet (-1: none), and whether
  // it started a new map (nothing to refine then).
  int unrefined_slot_ = -1;
  bool unrefined_new_map_ = false;
  // The last correction: snapshots older than this version are in the frame before it.
  uint64_t correction_version_ = 0;
  Eigen::Isometry3d last_correction_ = Eigen::Isometry3d::Identity();
  // Loop corrections applied in this map segment and their composition (LocalMap's fields).
  uint64_t loop_corrections_ = 0;
  Eigen::Isometry3d T_loop_corrections_ = Eigen::Isometry3d::Identity();
  MapperStats stats_;
  FixedVector<RetiredKeyframe, kMaxMapKeyframes> retired_;

  // Scratch, allocated once.
  struct Scratch {
    std::array<int32_t, kMaxMapPoints> point_ba_index{};      // -1: not in this BA
    std::array<int32_t, kMaxMapLines> line_ba_first_index{};  // first sample's BA index
    std::array<uint32_t, kMaxMapPoints> point_stamp{};
    std::array<uint32_t, kMaxMapLines> line_stamp{};
    FixedVector<int, kMaxMapKeyframes> window;        // optimised keyframe slots
    FixedVector<int, kMaxMapKeyframes> fixed;         // fixed keyframe slots
    std::array<int, kMaxMapKeyframes> ba_keyframe_index{};  // slot -> BA keyframe index
    FixedVector<uint32_t, kMaxMapPoints> ba_points;   // BA landmark order: point slots ...
    FixedVector<uint32_t, kMaxMapLines> ba_lines;     // ... then line slots (samples consecutive)
    // Landmarks of the window seen by one BA keyframe only: left out of the BA and moved
    // rigidly with that keyframe afterwards (local_mapper_ba.cpp, excludeSingleViewLandmarks).
    FixedVector<uint32_t, kMaxMapPoints> single_view_points;
    FixedVector<uint32_t, kMaxMapLines> single_view_lines;
    std::array<Eigen::Isometry3d, kMaxMapKeyframes> ba_correction;  // T_world_cam new * old^-1
    FixedVector<std::pair<float, uint16_t>, kMaxKeypoints> new_point_order;
    FixedVector<std::pair<float, uint32_t>, kMaxMapPoints> retire_order;
  };
  // One BA observation, for writing outlier decisions back to the map.
  struct BaObservation {
    uint8_t kf_slot = 0;
    bool is_line = false;
    uint32_t slot = 0;
  };
  std::unique_ptr<Scratch> s_;
  std::unique_ptr<LocalMap> local_map_;
  std::vector<BaObservation> ba_observations_;  // reserved once (max BA observations)
  uint32_t stamp_ = 0;
};

}  // namespace plumb
