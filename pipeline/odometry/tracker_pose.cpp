// Tracker: pose-only optimisation over the current associations, and pruning of the outliers.
#include <algorithm>

#include "pipeline/odometry/tracker.h"
#include "solver/noise_model.h"
#include "solver/pose_covariance.h"

namespace plumb {

double Tracker::mapShare(int local_index, bool point) const {
  // A landmark measured by n keyframes like this frame measures it: its error, after local BA
  // averaged them, is about 1/n of one measurement's. A last-frame point, or a landmark the
  // snapshot no longer lists, counts as measured once (the conservative side). 0 while the
  // option that publishes the term is off: the optimiser then skips its accumulation.
  if (!options_.uncertainty.tracked_map_error) return 0.0;
  int n = 1;
  if (local_index >= 0) {
    if (point && local_index < int(local_map_->points.size())) n = local_map_->points[local_index].keyframe_observations;
    if (!point && local_index < int(local_map_->lines.size())) n = local_map_->lines[local_index].keyframe_observations;
  }
  return 1.0 / double(std::max(n, 1));
}

Eigen::Matrix2d Tracker::monoInformation(int octave) const {
  return octave >= 0 && octave < kPyramidLevels ? mono_point_information_[octave]
                                                : monoPointInformation(options_.extractor.noise, octave);
}

double Tracker::lineInformation(int octave) const {
  return octave >= 0 && octave < kPyramidLevels ? line_sample_information_[octave]
                                                : lineSampleInformation(options_.extractor.noise, octave);
}

PoseResult Tracker::optimizeAndPrune(const FrameFeatures& frame, const Eigen::Isometry3d& T_cam_world,
                                     TrackResult* result, bool final_pose) {
  const NoiseModelOptions& noise = options_.extractor.noise;
  auto& points = b_->pose_points;
  auto& point_keypoint = b_->pose_point_keypoint;
  auto& lines = b_->pose_lines;
  auto& line_index = b_->pose_line_index;
  points.clear();
  point_keypoint.clear();
  lines.clear();
  line_index.clear();

  for (std::size_t k = 0; k < frame.keypoints.size(); ++k) {
    if (!b_->points[k].valid) continue;
    const KeypointObservation& kp = frame.keypoints[k];
    PosePointObservation* obs = points.emplace_back();
    obs->P_world = b_->points[k].P_world;
    obs->has_depth = kp.depth_m > 0;  // u_r itself may be negative near the left border
    obs->z = Eigen::Vector3d(kp.px_undist.x(), kp.px_undist.y(), obs->has_depth ? kp.u_right : 0.0);
    if (obs->has_depth) {
      obs->information = kp.info_uvr.cast<double>();
      if (!(obs->information.trace() > 0)) {
        obs->information = stereoPointInformation(noise, intrinsics_, kp.octave, kp.depth_m);
      }
    } else {
      obs->information.setZero();
      obs->information.topLeftCorner<2, 2>() = monoInformation(kp.octave);
    }
    obs->map_share = mapShare(b_->points[k].local_index, true);
    (void)point_keypoint.push_back(uint16_t(k));
  }
  if (options_.tracker.use_lines) {
    for (std::size_t k = 0; k < frame.lines.size(); ++k) {
      const LineAssociation& a = b_->lines[k];
      if (!a.valid) continue;
      const double information = lineInformation(frame.lines[k].octave);
      const double map_share = mapShare(a.local_index, false);
      for (int s = 0; s < a.num_samples; ++s) {
        PoseLineObservation* obs = lines.emplace_back();
        if (obs == nullptr) break;
        obs->P_world = a.samples_world[s];
        obs->line = frame.lines[k].l;
        obs->information = information;
        obs->map_share = map_share;
        (void)line_index.push_back(uint16_t(k));
      }
    }
  }

  PoseOptimizerOptions options = pose_options_;
  options.compute_covariance = final_pose;
  const PoseResult pose =
      optimizePose(intrinsics_, T_cam_world, points.data(), int(points.size()), lines.data(),
                   int(lines.size()), options, b_->point_inlier.data(), b_->line_inlier.data());

  // Outliers lose their association (they are not used again for this frame nor carried on).
  result->point_inliers = 0;
  result->line_inliers = 0;
  result->landmark_inliers = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    PointAssociation& a = b_->points[point_keypoint[i]];
    if (!b_->point_inlier[i]) {
      a = PointAssociation{};
      continue;
    }
    ++result->point_inliers;
    if (a.landmark.id != 0) ++result->landmark_inliers;
  }
  // A line counts as an inlier when most of its samples are.
  std::size_t i = 0;
  while (i < lines.size()) {
    const uint16_t k = line_index[i];
    int total = 0, good = 0;
    for (; i < lines.size() && line_index[i] == k; ++i) {
      ++total;
      good += b_->line_inlier[i] ? 1 : 0;
    }
    LineAssociation& a = b_->lines[k];
    if (2 * good <= total) {
      a = LineAssociation{};
      continue;
    }
    ++result->line_inliers;
    if (a.landmark.id != 0) ++result->landmark_inliers;
  }
  return pose;
}

void Tracker::publishCovariance(const PoseResult& pose, const Vector6d& twist_per_s, TrackResult* result) const {
  result->covariance_local_valid = pose.covariance_valid;
  result->covariance_valid = false;
  if (!pose.covariance_valid) return;
  const double variance_factor = varianceFactor(pose.inlier_chi2, 6.0, pose_options_.chi2);
  const Matrix6d model_terms =
      timingCovariance(options_.uncertainty, camera_.rolling_shutter_readout_s, twist_per_s) +
      rollingShutterCovariance(options_.uncertainty, camera_.rolling_shutter_readout_s,
                               options_.uncertainty.rolling_shutter_frame_share);
  // covariance_local: what two consecutive frames do not share, the velocity's. The map is held
  // exact by pose-only optimisation, and the detection offsets that persist from frame to frame
  // (what tracked_scale inflates for) cancel in the difference too: motion_scale.
  result->covariance_local =
      inflateMotionCovariance(options_.uncertainty, pose.covariance, variance_factor) + model_terms;
  // Relative to the reference keyframe, whose world covariance it chains with, the frame carries
  // the persistent errors (tracked_scale) and the landmarks' own position errors
  // (PoseResult::map_covariance), which consecutive frames share.
  if (!local_map_->reference_world_covariance_valid) return;
  Matrix6d relative_to_reference =
      inflateTrackedCovariance(options_.uncertainty, pose.covariance, variance_factor) + model_terms;
  if (options_.uncertainty.tracked_map_error) {
    relative_to_reference += inflateTrackedCovariance(options_.uncertainty, pose.map_covariance, variance_factor);
  }
  result->covariance = chainPoseCovariance(local_map_->T_world_reference.inverse(), pose.T_cam_world,
                                           local_map_->reference_world_covariance, relative_to_reference);
  result->covariance_valid = true;
}

}  // namespace plumb
